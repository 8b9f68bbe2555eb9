"""The op's whole tool (core.tools.assembly): the holder from TMM's library (docs/holders.md, the user's file
extending it), the stick-out, the clearances the shank and the holder keep from the model, and what the op does
where they would come closer (Lift: the tool rises there and the surface below keeps material, reported as
regions; LeaveOut: those places are not cut, for a longer tool or 5-axis). Holder None: the cutter alone, as
every op computed before the holder existed (documents saved before it restore with None).

A stage of every mesh op (core.stage): declared once here, derived into the op's properties and the API's
`holder=`, `stick_out=`, `shank_clearance=`, `holder_clearance=`, `holder_collision=`.
"""
from __future__ import annotations

from typing import Any, Optional

import FreeCAD

from tmm_workbench.app import tools
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.tools import holders

NONE = "None"
LIFT, LEAVE_OUT = "lift", "leave_out"
COLLISIONS = {"Lift": LIFT, "LeaveOut": LEAVE_OUT}
CLEARANCE = Spec("clearance", "mm", low=0.0, high=100.0)
STICK_OUT = Spec("stick-out", "mm", low=0.0, high=1000.0)   # 0: from the ToolBit's Length (tools.assembly_from_tool)


def holder_choices() -> dict[str, Optional[str]]:
    """None and the library's holders (shipped and the user's), property value -> holder name. A library that
    cannot be read (a broken user file) leaves None only here: documents still open, and an op with a holder
    says what is wrong with the file when it computes."""
    try:
        names = holders.names(tools.user_holders_file())
    except (TmmError, OSError) as exc:
        FreeCAD.Console.PrintWarning(f"TMM holder library: {exc}\n")
        names = []
    return {NONE: None, **{name: name for name in names}}


def ignored(args: Args) -> Optional[str]:
    """Stick-out, clearances and the collision choice mean nothing without a holder: refused by name."""
    if args.get("holder") is not None and str(args["holder"]) != NONE:
        return None
    for name in ("stick_out", "shank_clearance", "holder_clearance", "holder_collision"):
        if args.get(name) is not None:
            return f"{name} is used with a holder only: give holder= (a name from the holder library) as well"
    return None


STAGE = Stage("tool assembly", (
    Field("Holder", "choice", "Tool",
          "The tool holder (TMM's library, docs/holders.md): its shank and the holder are kept their clearance "
          "away from the model; None: the cutter alone", api="holder", choices=holder_choices(), default=NONE, widget="holder"),
    Field("StickOut", "length", "Tool",
          "Gauge length from the holder's face to the tool tip, mm; 0: the ToolBit's Length minus a grip of 3 "
          "shank diameters", api="stick_out", default=0.0, spec=STICK_OUT, widget="stickOut"),
    Field("ShankClearance", "length", "Tool", "Least distance the shank and neck keep from the model, mm",
          api="shank_clearance", default=1.0, spec=CLEARANCE, widget="shankClearance"),
    Field("HolderClearance", "length", "Tool", "Least distance the holder keeps from the model, mm",
          api="holder_clearance", default=1.0, spec=CLEARANCE, widget="holderClearance"),
    Field("HolderCollision", "choice", "Tool",
          "Where the shank or holder would come closer: Lift the tool there (the surface below keeps material, "
          "reported as regions), or LeaveOut those places (for a longer tool or 5-axis)", "holder_collision",
          "holder_collision", choices=COLLISIONS, api_names={"lift": "Lift", "leave_out": "LeaveOut"},
          widget="holderCollision"),
), ignored=ignored)


def assembly_of(obj: Any) -> Any:
    """The op's core ToolAssembly (its tool controller's ToolBit with the op's holder, stick-out and clearances),
    or None without a holder."""
    name = str(getattr(obj, "Holder", NONE) or NONE)
    if name == NONE:
        return None
    tc = getattr(obj, "ToolController", None)
    if tc is None:
        raise TmmError(f"Holder '{name}' needs a tool controller with a ToolBit (its shank and length)")
    stick_out = float(obj.StickOut.Value)
    return tools.assembly_from_tool(tc.Tool, name, stick_out if stick_out > 0 else None,
                                    shank_clearance=float(obj.ShankClearance.Value),
                                    holder_clearance=float(obj.HolderClearance.Value))


REPORT = "HolderReport"


def prepare(obj: Any, params: Any) -> None:
    """A strategy's params (core.strategies.holder_guard.WholeToolParams) given the op's assembly and, with one,
    the list its guard reports to."""
    params.assembly = assembly_of(obj)
    params.holder_notes = [] if params.assembly is not None else None


def report(obj: Any, params: Any) -> None:
    """What the holder guard changed (core.strategies.holder_guard): in the read-only HolderReport, and a warning
    when it left material (with the stick-out that would cut it)."""
    notes = params.holder_notes or []
    if not hasattr(obj, REPORT):
        obj.addProperty("App::PropertyString", REPORT, "Tool",
                        "What the shank and holder left uncut on the last computed path, and the stick-out that "
                        "would cut it")
    obj.setEditorMode(REPORT, 1)
    text = "; ".join(note.summary() for note in notes)
    setattr(obj, REPORT, text)
    if any(note.affected for note in notes):
        FreeCAD.Console.PrintWarning(f"{obj.Label}: {text}\n")
    elif notes:
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {text}\n")
