"""The one ToolBit map: FreeCAD tools (ToolBits of 0.20 and later, 0.20's legacy Path.Tool; duck-typed)
<-> the core's one tool model (core.tools.Cutter). Nothing else in TMM reads or makes a ToolBit.

ToolBit shapes: endmill -> flat, ballend -> ball, bullnose -> bull-nose, chamfer and v-bit -> a cone
(the generalized APT cutter with a taper): `CuttingEdgeAngle` is the included tip angle (180: flat, as in
FreeCAD's PathSurfaceSupport), from a flat tip of `TipDiameter` up to `Diameter`; the cone height follows
from these three (the shipped bits' `CuttingEdgeHeight` does not always agree with them). FreeCAD 0.20's bullnose
shape has no corner radius parameter: it stores `FlatRadius`, the radius of the flat bottom, so the
corner radius is Diameter/2 - FlatRadius (FreeCAD issue #19050; later versions migrate to
`CornerRadius`, PR #18724 / #25438). A bit that carries `CornerRadius` (or the old torus shape's
`TorusRadius`) is taken at its word. The shape is the bit's shape file name (`BitShape`, 0.20 and 1.0),
its `ShapeID` / `ShapeName` (1.1), or a legacy tool's `ToolType` (EndMill: bull-nose when CornerRadius
> 0, BallEndMill). Which cutters a strategy takes is the strategy's data (`SUPPORTED_TOOLS`, Cutter kinds).

The generalized APT cutter itself comes from TMM's own ToolBit shape `tmm_apt` (resources/tools/Shape/
tmm_apt.fcstd, made by scripts/make_tool_shape.py; every version takes a custom shape file): Diameter (2R
at the cutting-edge height), CornerRadius r, BottomAngle beta1, TaperAngle beta2, CuttingEdgeHeight L_C.
"""
from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Optional

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools.cutter import Cutter

TOOLBIT_SHAPES = ("endmill", "ballend", "bullnose", "chamfer", "v-bit", "tmm_apt")  # shapes TMM maps to a cutter
APT_SHAPE = "tmm_apt"  # TMM's shape for the generalized APT cutter, shipped beside the add-on
APT_SHAPE_FILE = Path(__file__).resolve().parents[2] / "resources" / "tools" / "Shape" / f"{APT_SHAPE}.fcstd"
_LEGACY_TYPES = {"EndMill": "endmill", "BallEndMill": "ballend"}  # 0.20's deprecated Path.Tool
# ToolBit shapes shipped with FreeCAD (Mod/Path/Tools/Shape/<name>.fcstd) that TMM creates bits of
BIT_SHAPES = ("endmill", "ballend", "bullnose")
# API names of the shapes TMM creates (lower case) -> ToolBit shape
SHAPE_ALIASES = {"ballend": "ballend", "ball": "ballend", "endmill": "endmill", "flat": "endmill",
                 "bullnose": "bullnose", "bull": "bullnose"}


def shape_name(tool: Any) -> str:
    """'endmill', 'ballend', ... for a ToolBit (from its shape) or a legacy tool (ToolType)."""
    bit_shape = getattr(tool, "BitShape", "")
    if bit_shape:
        return os.path.splitext(os.path.basename(str(bit_shape)))[0]
    for prop in ("ShapeID", "ShapeName"):
        shape = getattr(tool, prop, "")
        if shape:
            return os.path.splitext(os.path.basename(str(shape)))[0]
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


def label_of(tool: Any) -> str:
    return str(getattr(tool, "Label", "") or getattr(tool, "Name", "") or "tool")


def diameter_of(tool: Any) -> float:
    """The tool's diameter in mm; TmmError unless finite and > 0."""
    d = _mm(getattr(tool, "Diameter", float("nan")))
    if not (math.isfinite(d) and d > 0):
        raise TmmError(f"tool '{label_of(tool)}': diameter must be a length > 0 mm, got {d:g} mm")
    return d


def cutter_from_tool(tool: Any) -> Cutter:
    """The core cutter for `tool`; TmmError naming the shape for shapes TMM cannot map."""
    if tool is None:
        raise TmmError("the operation has no tool")
    name = shape_name(tool)
    label = label_of(tool)
    if name not in TOOLBIT_SHAPES:
        raise TmmError(f"tool '{label}' has the shape '{name}', which TMM does not support; "
                       f"use one of: {', '.join(TOOLBIT_SHAPES)}")
    d = diameter_of(tool)
    if name == "endmill":
        corner = _mm(getattr(tool, "CornerRadius", 0.0))  # legacy tools: an end mill with a corner radius
        return Cutter.bull(d, corner) if corner > 0 else Cutter.flat(d)
    if name == "ballend":
        return Cutter.ball(d)
    if name == APT_SHAPE:
        return _apt_cutter(tool, d)
    if name in ("chamfer", "v-bit"):
        angle = float(getattr(tool, "CuttingEdgeAngle", 0.0))
        tip = _mm(getattr(tool, "TipDiameter", 0.0))
        if not 0 < angle < 180:
            raise TmmError(f"tool '{label}': cutting edge angle {angle:g} deg must be between 0 and 180")
        return Cutter.vbit(d, angle, tip)
    return Cutter.bull(d, bull_corner_radius(tool, d))


def _degrees(value: Any) -> float:
    """A FreeCAD angle Quantity (its Value is in degrees), a number of degrees or a unit string in degrees."""
    if isinstance(value, str):
        import FreeCAD  # only for unit strings
        return float(FreeCAD.Units.Quantity(value).getValueAs("deg"))
    return float(getattr(value, "Value", value))


def _apt_cutter(tool: Any, diameter: float) -> Cutter:
    """The generalized APT cutter of a `tmm_apt` bit; TmmError naming the tool and what is impossible."""
    label = label_of(tool)
    values = {}
    for prop in ("CornerRadius", "BottomAngle", "TaperAngle", "CuttingEdgeHeight"):
        if not hasattr(tool, prop):
            raise TmmError(f"tool '{label}' of the {APT_SHAPE} shape has no {prop}")
        values[prop] = getattr(tool, prop)
    try:
        return Cutter(diameter, _mm(values["CornerRadius"]), _degrees(values["BottomAngle"]),
                      _degrees(values["TaperAngle"]), _mm(values["CuttingEdgeHeight"]))
    except TmmError as exc:
        raise TmmError(f"tool '{label}': {exc}") from exc


def bull_corner_radius(tool: Any, diameter: float) -> float:
    label = label_of(tool)
    for prop in ("CornerRadius", "TorusRadius"):
        if hasattr(tool, prop):
            corner = _mm(getattr(tool, prop))
            if corner > diameter / 2:
                raise TmmError(f"bull-nose tool '{label}': corner radius {corner:g} mm is larger than the tool "
                               f"radius {diameter / 2:g} mm")
            return corner
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


def corner_radius_of(tool: Any) -> Optional[float]:
    """The corner radius for reports (the post's tool list): from the same map, None where unknown."""
    try:
        cutter = cutter_from_tool(tool)
    except (TmmError, TypeError, ValueError):
        return None
    return cutter.corner_radius


FLUTE_DIAMETERS = 3.0     # flute length of the bits TMM makes, in diameters
LENGTH_PAST_FLUTES = 4.0  # their length beyond the flutes, in diameters (at least MIN_LENGTH_MM overall)
MIN_LENGTH_MM = 50.0


def make_tool_bit(doc: Any, shape: str, diameter: float, corner_radius: float = 0.0, label: str = "") -> Any:
    """A ToolBit of FreeCAD's endmill/ballend/bullnose shape in `doc`, with a shank of its diameter, flutes of 3
    diameters and a length of 7 diameters, at least 50 mm. For a bull-nose, the 0.20 and 1.0 shape stores
    FlatRadius = diameter/2 - corner radius (see the module doc), 1.1's CornerRadius."""
    from tmm_workbench.app import compat

    if shape not in BIT_SHAPES:
        raise TmmError(f"tool shape '{shape}' is not one of {', '.join(BIT_SHAPES)}")
    for name, v in (("diameter", diameter), ("corner radius", corner_radius)):
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise TmmError(f"tool {name} must be a finite number of mm, got {v!r}")
    if not diameter > 0:
        raise TmmError(f"tool diameter must be a length > 0 mm, got {diameter:g}")
    if shape == "bullnose" and not 0 <= corner_radius <= diameter / 2:
        raise TmmError(f"bull-nose tool: corner radius {corner_radius:g} mm is larger than the tool radius "
                       f"{diameter / 2:g} mm" if corner_radius > 0 else
                       f"bull-nose tool: corner radius must be >= 0 mm, got {corner_radius:g}")
    # a solid carbide end mill's proportions (the shape files' defaults are one 3 mm shank, 30-40 mm flutes and
    # 50 mm length for every diameter): the shank of the cutting diameter, flutes of FLUTE_DIAMETERS diameters
    flutes = FLUTE_DIAMETERS * diameter
    params = {"Diameter": f"{diameter} mm", "ShankDiameter": f"{diameter} mm", "CuttingEdgeHeight": f"{flutes} mm",
              "Length": f"{max(MIN_LENGTH_MM, flutes + LENGTH_PAST_FLUTES * diameter)} mm"}
    if shape == "bullnose" and compat.toolbits_are_assets():
        params["CornerRadius"] = f"{corner_radius} mm"
    elif shape == "bullnose":
        params["FlatRadius"] = f"{diameter / 2 - corner_radius} mm"
    label = label or f"{diameter:g} mm {shape}" + (f" r{corner_radius:g}" if shape == "bullnose" else "")
    return compat.make_toolbit(doc, shape, params, label)


def make_apt_bit(doc: Any, cutter: Cutter, label: str = "", length: Optional[float] = None,
                 shank_diameter: Optional[float] = None) -> Any:
    """A ToolBit of TMM's `tmm_apt` shape in `doc` standing for `cutter` (any APT cutter; it needs a finite
    cutting-edge height). The drawn shank is `shank_diameter` (default: the diameter) up to `length`
    (default: the cutting-edge height plus 2 diameters)."""
    from tmm_workbench.app import compat

    if not math.isfinite(cutter.cutting_length):
        raise TmmError(f"the {cutter.describe()} cutter needs a finite cutting-edge height for a ToolBit")
    length = cutter.cutting_length + 2 * cutter.diameter if length is None else length
    shank = cutter.diameter if shank_diameter is None else shank_diameter
    if not (math.isfinite(length) and length > cutter.cutting_length):
        raise TmmError(f"tool length {length!r} mm must be longer than the cutting-edge height "
                       f"{cutter.cutting_length:g} mm")
    if not (math.isfinite(shank) and shank > 0):
        raise TmmError(f"tool shank diameter must be a length > 0 mm, got {shank!r}")
    params = {"Diameter": f"{cutter.diameter} mm", "CornerRadius": f"{cutter.corner_radius} mm",
              "BottomAngle": f"{cutter.bottom_angle_deg} deg", "TaperAngle": f"{cutter.taper_angle_deg} deg",
              "CuttingEdgeHeight": f"{cutter.cutting_length} mm", "Length": f"{length} mm",
              "ShankDiameter": f"{shank} mm"}
    return compat.make_toolbit(doc, str(APT_SHAPE_FILE), params, label or cutter.describe())


def bit_for_cutter(doc: Any, cutter: Cutter, label: str = "") -> Any:
    """The ToolBit standing for a core cutter: FreeCAD's ballend, endmill or bullnose, TMM's tmm_apt for the
    others (cones, tapers)."""
    shape = {"ball": "ballend", "flat": "endmill", "bull": "bullnose"}.get(cutter.kind)
    if shape is None:
        return make_apt_bit(doc, cutter, label)
    return make_tool_bit(doc, shape, cutter.diameter, cutter.corner_radius, label)


# --- the tool assembly: shank, neck and holder above the cutter (core.tools.assembly) ---

GRIP_SHANK_DIAMETERS = 3.0  # default grip: 3 shank diameters in the holder (about 2/3 of an ER collet's bore)


def user_holders_file() -> Optional[Path]:
    """The user's holder file extending TMM's library: holders.json in TMM's folder of the FreeCAD user data
    folder (docs/holders.md); None outside FreeCAD."""
    try:
        import FreeCAD
    except ImportError:
        return None
    from tmm_workbench.core.tools import holders

    return holders.user_file_in(FreeCAD.getUserAppDataDir())


def _optional_mm(tool: Any, *props: str) -> Optional[float]:
    """The first of `props` the tool carries, in mm; None when it has none of them."""
    for prop in props:
        if hasattr(tool, prop):
            return _mm(getattr(tool, prop))
    return None


def _default_stick_out(probe: Any, length: float, label: str) -> float:
    """The bit's Length minus a grip of GRIP_SHANK_DIAMETERS shank diameters, shortened so the flutes, neck
    and cone stay out of the holder; refused when less than one shank diameter would be held."""
    shank = probe.shank_diameter
    stick_out = max(length - GRIP_SHANK_DIAMETERS * shank, probe.minimum_stick_out)
    if length - stick_out < shank - 1e-9:
        raise TmmError(f"tool '{label}': its length {length:g} mm leaves {length - stick_out:g} mm to clamp "
                       f"once the {probe.minimum_stick_out:g} mm of flutes, neck and cone stand out, less than "
                       f"the shank diameter {shank:g} mm: give the stick-out")
    return stick_out


def assembly_from_tool(tool: Any, holder: Any = None, stick_out: Optional[float] = None, *,
                       cutter_clearance: float = 0.0, shank_clearance: float = 1.0, holder_clearance: float = 1.0,
                       shank_cone_deg: float = 90.0, holders_file: Any = "user") -> Any:
    """The core ToolAssembly of a ToolBit (0.20, 1.0, 1.1 alike): its cutter (cutter_from_tool), ShankDiameter
    (the cutter diameter when the bit has none: 0.20's legacy tools), CuttingEdgeHeight as the flute length
    (at least a cone's height), Length as the overall length, NeckDiameter with NeckLength or NeckHeight when
    the shape has a neck. `holder`: a core Holder, a name in the library (shipped + `holders_file`, by default
    user_holders_file()) or None. `stick_out`: the gauge length from the holder face to the tip; None takes
    Length minus 3 shank diameters (_default_stick_out). TmmError naming the tool and the value."""
    from tmm_workbench.core.tools import holders
    from tmm_workbench.core.tools.assembly import ToolAssembly

    cutter = cutter_from_tool(tool)
    label = label_of(tool)
    shank = _optional_mm(tool, "ShankDiameter")
    edge = _optional_mm(tool, "CuttingEdgeHeight")
    if edge is None and not math.isfinite(cutter.cutting_length):
        raise TmmError(f"tool '{label}' has no CuttingEdgeHeight: its flute length is unknown")
    flute = max(v for v in (edge, cutter.cutting_length) if v is not None and math.isfinite(v))
    length = _optional_mm(tool, "Length")
    neck_d = _optional_mm(tool, "NeckDiameter")
    neck_l = _optional_mm(tool, "NeckLength", "NeckHeight") if neck_d is not None else None
    if isinstance(holder, str):
        path = user_holders_file() if holders_file == "user" else holders_file
        holder = holders.holder(holder, path)
    try:
        def assemble(out: float, held: Any) -> Any:
            return ToolAssembly(cutter, cutter.diameter if shank is None else shank, out, flute_length=flute,
                                holder=held, neck_diameter=neck_d, neck_length=neck_l or 0.0,
                                shank_cone_deg=shank_cone_deg, overall_length=length,
                                cutter_clearance=cutter_clearance, shank_clearance=shank_clearance,
                                holder_clearance=holder_clearance)
        if stick_out is None:
            if length is None:
                raise TmmError("it has no Length: give the stick-out")
            stick_out = _default_stick_out(assemble(length, None), length, label)
        return assemble(stick_out, holder)
    except TmmError as exc:
        raise TmmError(str(exc) if str(exc).startswith(f"tool '{label}'") else f"tool '{label}': {exc}") from exc
