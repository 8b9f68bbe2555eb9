"""A post's `objectslist` (FreeCAD tool controllers, ops, fixtures, compounds) -> a core `Program`.

Duck-typed, no FreeCAD import: a tool controller has `ToolNumber` and `Tool`; anything else with a `Path` is
an operation (inactive ones skipped, compounds with `Group` expanded). Quantities are read through `.Value`.
What a ToolBit means (shape, corner radius) comes from the one ToolBit map, app.tools.
"""
from __future__ import annotations

from typing import Any, Iterable

from tmm_workbench.app.tools import corner_radius_of, shape_name
from tmm_workbench.core.post import Operation, Program, ToolInfo


def _value(v: Any, default: Any = None) -> Any:
    if v is None:
        return default
    if hasattr(v, "Value"):
        return float(v.Value)
    try:
        return float(v)
    except (TypeError, ValueError):
        return default


def is_tool_controller(obj: Any) -> bool:
    return hasattr(obj, "ToolNumber") and hasattr(obj, "Tool")


def tool_info(tc: Any) -> ToolInfo:
    tool = getattr(tc, "Tool", None)
    shape = shape_name(tool) if tool is not None else ""
    shape = "" if shape == "unknown" else shape
    d = _value(getattr(tool, "Diameter", None))
    corner = corner_radius_of(tool) if tool is not None else None
    direction = str(getattr(tc, "SpindleDir", "Forward"))
    spindle_power = getattr(tool, "SpindlePower", True) if tool is not None else True
    return ToolInfo(
        number=int(getattr(tc, "ToolNumber", 0)),
        label=str(getattr(tool, "Label", "") or getattr(tc, "Label", "")),
        shape=shape, diameter=d, corner_radius=corner,
        cutting_height=_value(getattr(tool, "CuttingEdgeHeight", None)),
        spindle_rpm=_value(getattr(tc, "SpindleSpeed", 0.0), 0.0),
        spindle_dir="OFF" if direction == "None" or not spindle_power else ("CCW" if direction == "Reverse" else "CW"),
    )


def program_from_objects(objectslist: Iterable[Any]) -> Program:
    """Tool changes and operations, in order; objects without a Path and inactive ops are skipped."""
    out: Program = []
    for obj in objectslist:
        if is_tool_controller(obj):
            out.append(tool_info(obj))
            continue
        if hasattr(obj, "Group") and not hasattr(obj, "Path"):
            out.extend(program_from_objects(obj.Group))
            continue
        if not hasattr(obj, "Path"):
            continue
        if not getattr(obj, "Active", True):
            continue
        base = getattr(obj, "Base", None)
        if base is not None and hasattr(base, "Active") and not base.Active:
            continue
        coolant = str(getattr(obj, "CoolantMode", None) or getattr(base, "CoolantMode", None) or "None")
        commands = [(c.Name, dict(c.Parameters)) for c in obj.Path.Commands]
        out.append(Operation(str(getattr(obj, "Label", getattr(obj, "Name", "operation"))), commands, coolant))
    return out
