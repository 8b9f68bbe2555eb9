"""FreeCAD tools (ToolBits, and 0.20's legacy Path.Tool) -> core cutters.

ToolBit shapes: endmill -> flat, ballend -> ball, bullnose -> bull-nose, chamfer and v-bit -> a cone
(the generalized APT cutter with a taper): `CuttingEdgeAngle` is the included tip angle (180: flat, as in
FreeCAD's PathSurfaceSupport), from a flat tip of `TipDiameter` up to `Diameter`; the cone height follows
from these three (the shipped bits' `CuttingEdgeHeight` does not always agree with them). FreeCAD 0.20's bullnose
shape has no corner radius parameter: it stores `FlatRadius`, the radius of the flat bottom, so the
corner radius is Diameter/2 - FlatRadius (FreeCAD issue #19050; later versions migrate to
`CornerRadius`, PR #18724 / #25438). A bit that carries `CornerRadius` (or the old torus shape's
`TorusRadius`) is taken at its word. Legacy tools: EndMill (bull-nose when CornerRadius > 0), BallEndMill.
"""
from __future__ import annotations

import os
from typing import Any

from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.errors import TmmError

SUPPORTED_SHAPES = ("endmill", "ballend", "bullnose", "chamfer", "v-bit")
_LEGACY_TYPES = {"EndMill": "endmill", "BallEndMill": "ballend"}  # 0.20's deprecated Path.Tool


def shape_name(tool: Any) -> str:
    """'endmill', 'ballend', ... for a ToolBit (from its shape file) or a legacy tool (ToolType)."""
    bit_shape = getattr(tool, "BitShape", "")
    if bit_shape:
        return os.path.splitext(os.path.basename(bit_shape))[0]
    shape = getattr(tool, "ShapeName", "")
    if shape:
        return shape
    legacy = getattr(tool, "ToolType", "")
    return _LEGACY_TYPES.get(legacy, legacy or "unknown")


def _mm(value: Any) -> float:
    """A FreeCAD Quantity, a number or a unit string like '6 mm' in mm."""
    if hasattr(value, "Value"):
        return float(value.Value)
    if isinstance(value, str):
        import FreeCAD  # only for unit strings
        return float(FreeCAD.Units.Quantity(value).Value)
    return float(value)


def cutter_from_tool(tool: Any) -> Cutter:
    """The core cutter for `tool`; TmmError naming the shape for shapes TMM cannot drop."""
    if tool is None:
        raise TmmError("the operation has no tool")
    name = shape_name(tool)
    label = getattr(tool, "Label", getattr(tool, "Name", "tool"))
    if name not in SUPPORTED_SHAPES:
        raise TmmError(f"tool '{label}' has the shape '{name}', which TMM 3-axis Surface does not support; "
                       f"use one of: {', '.join(SUPPORTED_SHAPES)}")
    d = _mm(tool.Diameter)
    if name == "endmill":
        corner = _mm(getattr(tool, "CornerRadius", 0.0))  # legacy tools: an end mill with a corner radius
        return Cutter.bull(d, corner) if corner > 0 else Cutter.flat(d)
    if name == "ballend":
        return Cutter.ball(d)
    if name in ("chamfer", "v-bit"):
        angle = float(getattr(tool, "CuttingEdgeAngle", 0.0))
        tip = _mm(getattr(tool, "TipDiameter", 0.0))
        if not 0 < angle < 180:
            raise TmmError(f"tool '{label}': cutting edge angle {angle:g} deg must be between 0 and 180")
        return Cutter.vbit(d, angle, tip)
    return Cutter.bull(d, bull_corner_radius(tool, d))


def bull_corner_radius(tool: Any, diameter: float) -> float:
    label = getattr(tool, "Label", "tool")
    for prop in ("CornerRadius", "TorusRadius"):
        if hasattr(tool, prop):
            return _mm(getattr(tool, prop))
    if hasattr(tool, "FlatRadius"):
        flat = _mm(tool.FlatRadius)
        corner = diameter / 2 - flat
        if flat < 0:
            raise TmmError(f"bull-nose tool '{label}': corner radius {corner:g} mm is larger than the tool "
                           f"radius {diameter / 2:g} mm (FlatRadius {flat:g} mm)")
        if corner < 0:
            raise TmmError(f"bull-nose tool '{label}': FlatRadius {flat:g} mm is larger than the tool radius "
                           f"{diameter / 2:g} mm")
        return corner
    raise TmmError(f"bull-nose tool '{label}' has neither CornerRadius nor FlatRadius")
