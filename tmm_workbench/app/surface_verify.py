"""The 3-axis Surface op's verification pass (core.strategies.surface.variable_step): `VerifyCusp` cuts
the pass set in the stock simulation and adds partial passes where its cusp exceeds CuspHeight. Off by default,
and off in documents saved before it (a Bool property added on restore is False): their path is unchanged.

`CheckCusp` (Auto by default: a large region on coarser cells; core.strategies.surface.cusp_check): a cusp mode's
pass set measured as the verification measures it, no passes added. What it finds goes to the read-only `CuspReport` (cells above CuspHeight, the
largest, where) and, when cells exceed it, a warning suggesting VerifyCusp. It never changes the path.

Each pass set's report goes to the report view: a message with the cusp before and after, the passes added and
the cells out of the tool's reach; a warning when cells stay above the tolerance after the round limit.
"""
from __future__ import annotations

from typing import Any

import FreeCAD

from tmm_workbench.core.stage import Field, Stage

STAGE = Stage("verification", (
    Field("VerifyCusp", "bool", "Surface",
          "Cut the passes in the stock simulation and add partial passes where the simulated cusp exceeds "
          "CuspHeight (any StepOverMode; ZigZag or OneWay over the Box region); cells out of the tool's reach are "
          "reported, not chased", "verify_cusp", "verify_cusp", widget="verifyCusp"),
    Field("CheckCusp", "choice", "Surface",
          "Cusp modes (Cusp, Adaptive, Offset3D): measure the passes in the stock simulation as VerifyCusp does, "
          "without adding passes, and report in CuspReport how many cells stay above CuspHeight and where (Auto: a "
          "few seconds, a large region on coarser cells, saying how far a crest may read low; On: always on the "
          "verification's cells, about as long again as the passes)", "cusp_check",
          choices={"Auto": "auto", "On": "on", "Off": "off"}),
))
REPORT = "CuspReport"


def notes_for(params: Any) -> list:
    """The list the strategy appends its reports to (empty when neither VerifyCusp, CheckCusp nor the pencil's
    clean-up runs; the clean-up's report goes with the rest's: app.rest_source.report)."""
    from tmm_workbench.core.strategies.surface import cusp_check
    from tmm_workbench.core.strategies.surface.params import PENCIL, PENCIL_CLEANUP

    notes: list = []
    cleanup = params.pattern == PENCIL and params.pencil_source == PENCIL_CLEANUP
    if params.verify_cusp or cusp_check.applies(params) or cleanup or params.rest is not None:
        params.verify_notes = notes
    return notes


def _report_property(obj: Any, text: str) -> None:
    if not hasattr(obj, REPORT):
        obj.addProperty("App::PropertyString", REPORT, "Surface",
                        "What the cusp check measured on the last computed path (cells above CuspHeight, where)")
    obj.setEditorMode(REPORT, 1)
    setattr(obj, REPORT, text)


def report(obj: Any, notes: list) -> None:
    from tmm_workbench.core.footprint.cleanup import CleanupReport
    from tmm_workbench.core.strategies.rest_steep import SteepReport
    from tmm_workbench.core.strategies.surface.cusp_check import CuspCheck

    _report_property(obj, "")
    for note in notes:
        if isinstance(note, (CleanupReport, SteepReport)):   # reported with the rest (app.rest_source.report)
            continue
        if isinstance(note, CuspCheck):
            _report_property(obj, note.summary())
            if note.within or note.verified:   # (VerifyCusp warns itself)
                FreeCAD.Console.PrintMessage(f"{obj.Label}: {note.summary()}\n")
            else:
                FreeCAD.Console.PrintWarning(f"{obj.Label}: {note.summary()}\n")
            continue
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {note.summary()}\n")
        if not note.within:
            FreeCAD.Console.PrintWarning(
                f"{obj.Label}: {note.exceeding_after} cells keep a cusp above CuspHeight "
                f"{note.tolerance:g} mm (up to {note.max_cusp_after:.4f} mm) after {note.rounds} rounds\n")
