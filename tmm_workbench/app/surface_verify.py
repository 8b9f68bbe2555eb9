"""The 3-axis Surface op's verification pass (issue 14 item 4; core.footprint.variable_step): `VerifyCusp` cuts
the pass set in the stock simulation and adds partial passes where its cusp exceeds CuspHeight. Off by default,
and off in documents saved before it (a Bool property added on restore is False): their path is unchanged.

Each pass set's report goes to the report view: a message with the cusp before and after, the passes added and
the cells out of the tool's reach; a warning when cells stay above the tolerance after the round limit.
"""
from __future__ import annotations

from typing import Any

import FreeCAD

from tmm_workbench.app.op_base import Prop

PROPERTIES: list[Prop] = [
    Prop("App::PropertyBool", "VerifyCusp", "Surface",
         "Cut the passes in the stock simulation and add partial passes where the simulated cusp exceeds "
         "CuspHeight (any StepOverMode; ZigZag or OneWay over the Box region); cells out of the tool's reach are "
         "reported, not chased", "verify_cusp"),
]


def notes_for(params: Any) -> list:
    """The list the strategy appends its reports to (empty when VerifyCusp is off)."""
    notes: list = []
    if params.verify_cusp:
        params.verify_notes = notes
    return notes


def report(obj: Any, notes: list) -> None:
    for note in notes:
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {note.summary()}\n")
        if not note.within:
            FreeCAD.Console.PrintWarning(
                f"{obj.Label}: {note.exceeding_after} cells keep a cusp above CuspHeight "
                f"{note.tolerance:g} mm (up to {note.max_cusp_after:.4f} mm) after {note.rounds} rounds\n")
