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
import numpy as np

from tmm_workbench.app import tools
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.tools import holders

NONE = "None"
FROM_TC = "FromToolController"   # the holder the op's tool controller carries (TC_HOLDER): the default
TC_HOLDER, TC_STICK_OUT = "TmmHolder", "TmmStickOut"
LIFT, LEAVE_OUT = "lift", "leave_out"
COLLISIONS = {"Lift": LIFT, "LeaveOut": LEAVE_OUT}
CLEARANCE = Spec("clearance", "mm", low=0.0, high=100.0)
STICK_OUT = Spec("stick-out", "mm", low=0.0, high=1000.0)   # 0: from the ToolBit's Length (tools.assembly_from_tool)


def _library_names() -> list[str]:
    """The library's holder names (shipped and the user's). A library that cannot be read (a broken user file)
    gives none here: documents still open, and an op with a holder says what is wrong with the file when it
    computes."""
    try:
        return holders.names(tools.user_holders_file())
    except (TmmError, OSError) as exc:
        FreeCAD.Console.PrintWarning(f"TMM holder library: {exc}\n")
        return []


def holder_choices() -> dict[str, Optional[str]]:
    """Property value -> holder: None, the library's holders, and the tool controller's (its TmmHolder)."""
    return {NONE: None, **{name: name for name in _library_names()}, FROM_TC: FROM_TC}


def ignored(args: Args) -> Optional[str]:
    """Stick-out, clearances and the collision choice mean nothing without a holder: refused by name."""
    if args.get("holder") is not None and str(args["holder"]) != NONE:
        return None
    for name in ("stick_out", "shank_clearance", "holder_clearance", "holder_collision"):
        if args.get(name) is not None:
            return f"{name} is used with a holder only: give holder= (a name from the holder library) as well"
    return None


HOLDERS = holder_choices()   # the library read once, at import (the panel and the API offer these)
STAGE = Stage("tool assembly", (
    Field("Holder", "choice", "Tool",
          "The tool holder (TMM's library, docs/holders.md): its shank and the holder are kept their clearance "
          "away from the model; FromToolController: the one set on the tool controller (its TmmHolder); None: "
          "the cutter alone", api="holder", choices=HOLDERS,
          api_names={**{str(n).lower(): n for n in HOLDERS if n != FROM_TC}, "tool_controller": FROM_TC},
          default=FROM_TC, restored=NONE, widget="holder"),
    Field("StickOut", "length", "Tool",
          "Gauge length from the holder's face to the tool tip, mm; 0: the tool controller's (TmmStickOut), or "
          "the ToolBit's Length minus a grip of 3 shank diameters", api="stick_out", default=0.0, spec=STICK_OUT, widget="stickOut"),
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


def ensure_tool_controller(tc: Any) -> None:
    """The tool controller's holder properties (TmmHolder: None or a library holder; TmmStickOut: 0 for the
    ToolBit's), added when missing, the library's names offered (a value no longer in it kept as None)."""
    names = [NONE] + _library_names()
    if not hasattr(tc, TC_HOLDER):
        tc.addProperty("App::PropertyEnumeration", TC_HOLDER, "TMM",
                       "The holder this tool is clamped in (TMM's library, docs/holders.md): TMM ops whose Holder is "
                       "FromToolController keep its shank and holder clear of the model")
        tc.addProperty("App::PropertyLength", TC_STICK_OUT, "TMM",
                       "Gauge length from the holder's face to the tool tip, mm; 0: the ToolBit's Length minus a "
                       "grip of 3 shank diameters")
    if list(tc.getEnumerationsOfProperty(TC_HOLDER) or []) != names:
        value = str(getattr(tc, TC_HOLDER) or NONE)
        setattr(tc, TC_HOLDER, names)
        setattr(tc, TC_HOLDER, value if value in names else NONE)


def set_tool_controller_holder(tc: Any, holder: Optional[str], stick_out: float = 0.0) -> None:
    """Clamps the tool controller's tool in `holder` (a library name; None: no holder) at `stick_out` mm (0: the
    ToolBit's Length minus 3 shank diameters). TmmError naming an unknown holder or a stick-out out of range."""
    from tmm_workbench.app.api_args import numbers

    ensure_tool_controller(tc)
    name = NONE if holder is None else str(holder)
    known = list(tc.getEnumerationsOfProperty(TC_HOLDER))
    if name not in known:
        raise TmmError(f"holder must be one of {', '.join(known)}, got {holder!r}")
    numbers(stick_out=(stick_out, STICK_OUT))
    setattr(tc, TC_HOLDER, name)
    setattr(tc, TC_STICK_OUT, float(stick_out))


def holder_of(obj: Any) -> tuple[str, float]:
    """(holder name or NONE, stick-out mm or 0) the op computes with: its own, or its tool controller's."""
    name = str(getattr(obj, "Holder", NONE) or NONE)
    stick_out = float(obj.StickOut.Value) if hasattr(obj, "StickOut") else 0.0
    if name != FROM_TC:
        return name, stick_out
    tc = getattr(obj, "ToolController", None)
    name = str(getattr(tc, TC_HOLDER, NONE) or NONE)
    if stick_out <= 0 and hasattr(tc, TC_STICK_OUT):
        stick_out = float(getattr(tc, TC_STICK_OUT).Value)
    return name, stick_out


def assembly_of(obj: Any) -> Any:
    """The op's core ToolAssembly (its tool controller's ToolBit with the holder and stick-out of holder_of and
    the op's clearances), or None without a holder."""
    name, stick_out = holder_of(obj)
    if name == NONE:
        return None
    tc = getattr(obj, "ToolController", None)
    if tc is None:
        raise TmmError(f"Holder '{name}' needs a tool controller with a ToolBit (its shank and length)")
    return tools.assembly_from_tool(tc.Tool, name, stick_out if stick_out > 0 else None,
                                    shank_clearance=float(obj.ShankClearance.Value),
                                    holder_clearance=float(obj.HolderClearance.Value))


REPORT, REGIONS = "HolderReport", "HolderRegions"


def prepare(obj: Any, params: Any) -> None:
    """A strategy's params (core.strategies.holder_guard.WholeToolParams) given the op's assembly and, with one,
    the list its guard reports to."""
    params.assembly = assembly_of(obj)
    params.holder_notes = [] if params.assembly is not None else None


def report(obj: Any, params: Any) -> None:
    """What the holder guard changed (core.strategies.holder_guard): in the read-only HolderReport, the places it
    left material in HolderRegions (the view draws them), and a warning when it left any (with the stick-out
    that would cut it)."""
    notes = params.holder_notes or []
    if not hasattr(obj, REPORT):
        obj.addProperty("App::PropertyString", REPORT, "Tool",
                        "What the shank and holder left uncut on the last computed path, and the stick-out that "
                        "would cut it")
    if not hasattr(obj, REGIONS):
        obj.addProperty("App::PropertyVectorList", REGIONS, "Tool",
                        "Where the shank or holder kept the tool off the model on the last computed path (material "
                        "is left there): drawn on the 3D view")
    for name in (REPORT, REGIONS):
        obj.setEditorMode(name, 1)
    text = "; ".join(note.summary() for note in notes)
    setattr(obj, REPORT, text)
    spots = [note.spots for note in notes if note.spots is not None and len(note.spots)]
    setattr(obj, REGIONS, [FreeCAD.Vector(*map(float, p)) for p in np.vstack(spots)] if spots else [])
    if any(note.affected for note in notes):
        FreeCAD.Console.PrintWarning(f"{obj.Label}: {text}\n")
    elif notes:
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {text}\n")
