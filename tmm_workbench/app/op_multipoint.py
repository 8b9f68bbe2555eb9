"""'TMM 5-axis Multipoint': a Path operation that finishes one Bézier or B-spline face with a toroidal
(bull-nose) or ball cutter by multipoint positioning (seed 001, core.multipoint).

Input: `Base` (FreeCAD's base-geometry property, as the stock face ops): exactly one face of one object,
usually of the Job's model clone. The face's `Surface` must be a Part.BezierSurface or Part.BSplineSurface;
it is taken in document (global) coordinates: FreeCAD's `Face.Surface` already carries the object's
Placement, and a surface that does not (checked by evaluating it against the face) is transformed by the
shape's Placement first. The whole (untrimmed) surface is machined.

Tool: the op's tool controller. bullnose ToolBit -> Ro = radius - corner radius, Ri = corner radius;
ballend -> Ro = 0, Ri = radius (the core's ball); endmill -> Ri = 0, which the core refuses with its own
message; other shapes are refused.

Path (docs/path5.md): X Y Z = tool tip, U V W = unit tool axis, on every motion command. Linking (TMM's
choice, as a machinist expects): each cut segment (consecutive good positions of one pass)
  * is entered from above: rapid at the transit height to the point `AxisRetract` above the first
    position *along its tool axis*, with the tool already in that orientation, then a G1 plunge at the
    vertical feed along the axis to the first position;
  * is left the same way: G0 back along the tool axis by `AxisRetract` (away from the part), then G0
    straight up in Z to the transit height.
  The transit height is SafeHeight for the lowest point of the (tilted) tool, i.e. the tip is at
  SafeHeight + Ri (1 - cos t) + Ro sin t for a tilt t. The op starts at ClearanceHeight with a vertical
  axis, turns the tool above its first entry point, and ends at ClearanceHeight turned back to vertical
  (so ObjectOp's final `G0 Z<ClearanceHeight>` and any op after this one stay untilted).
Errors (TmmError, cancel, anything unexpected) never leave a partial path: the Path is emptied, the message
goes to the report view and the op is marked invalid with that message (as op_surface).
"""
from __future__ import annotations

import math
from typing import Any, Optional

import FreeCAD
import Path

from tmm_workbench.app import hooks, op_base, progress
from tmm_workbench.app.compat import PathOp, PathSetupSheet
from tmm_workbench.app.tools import _mm, bull_corner_radius, shape_name
from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.multipoint import (STATUS_FAILED, BezierFace, MultipointParams,
                                           MultipointResults, compute_multipoint_toolpath)
from tmm_workbench.core.toolpath import MoveKind, Toolpath, Z_AXIS

OP_NAME = "TMM_Multipoint"
METHODS = {"VCRF": "vcrf", "DRD": "drd"}
TOOL_SHAPES = {"RoundInsert": "round_insert", "BullNose": "bull_nose"}
ANCHORS = {"Axis": "axis", "Tip": "tip"}
PASS_SPACINGS = {"Even": "even", "Fixed": "fixed"}
SUPPORTED_SHAPES = ("bullnose", "ballend", "endmill")  # endmill only to get the core's clear refusal
_DEFAULT = MultipointParams()

# (type, name, group, tooltip)
PROPERTIES: list[tuple[str, str, str, str]] = [
    ("App::PropertyEnumeration", "Method", "Multipoint",
     "VCRF: vertical cutter, rotate to find the second contact (seed 001); DRD: directional ray distances"),
    ("App::PropertyEnumeration", "ToolShape", "Multipoint",
     "RoundInsert: the seed's torus (round-insert cutter, hollow centre); BullNose: the torus plus its flat "
     "bottom disc (a solid bull-nose end mill; on convex faces its bottom keeps most positions at one contact)"),
    ("App::PropertyDistance", "SideStep", "Footprint", "Distance between passes (see PassSpacing)"),
    ("App::PropertyEnumeration", "PassSpacing", "Footprint",
     "Even: passes spread evenly over the boundary, at most SideStep apart; Fixed: passes exactly SideStep "
     "apart from the start edge and a last one on the far edge (seed 001's footprint: x = 0, 18, ..., 144, 150)"),
    ("App::PropertyDistance", "ForwardStep", "Footprint", "Distance between tool positions along a pass (at most)"),
    ("App::PropertyAngle", "FeedAngle", "Footprint", "Direction of the passes in XY, from +X"),
    ("App::PropertyDistance", "BoundaryMargin", "Footprint",
     "Grows (positive) or shrinks (negative) the face's XY extent covered by the footprint"),
    ("App::PropertyBool", "ZigZag", "Footprint", "Alternate the direction of the passes"),
    ("App::PropertyAngle", "TiltLimit", "Multipoint", "Largest tilt of the tool axis from the vertical"),
    ("App::PropertyDistance", "Tolerance", "Multipoint", "Contact and gouge tolerance"),
    ("App::PropertyDistance", "SurfaceExtension", "Multipoint",
     "Position the tool against the face continued past its edges by this distance (0: off), so a pass over "
     "an edge rests on the continued surface instead of on the edge; every position is still checked "
     "against the real face. The tool radius (Ro + Ri) covers a pass centred on the edge"),
    ("App::PropertyEnumeration", "FootprintAnchor", "Footprint",
     "Axis: the tool axis before tilting passes through the footprint point (seed 001; the tilt moves the tip "
     "sideways); Tip: the tilted tool's tip lies on the footprint point (passes exactly one side step apart)"),
    ("App::PropertyDistance", "AxisRetract", "Linking",
     "Entry and exit distance along the tool axis (then straight up/down to the safe height)"),
    ("App::PropertyString", "ContactSummary", "Multipoint",
     "Result of the last computation: footprint points with two contacts, one contact, failed"),
]
DEFAULTS: dict[str, Any] = {
    "Method": "VCRF", "ToolShape": "RoundInsert", "SideStep": _DEFAULT.side_step,
    "ForwardStep": _DEFAULT.forward_step, "FeedAngle": _DEFAULT.feed_angle_deg, "BoundaryMargin": _DEFAULT.margin,
    "ZigZag": _DEFAULT.zigzag, "TiltLimit": _DEFAULT.beta_max_deg, "Tolerance": _DEFAULT.tol, "AxisRetract": 5.0,
    "SurfaceExtension": _DEFAULT.extend, "FootprintAnchor": "Axis", "PassSpacing": "Even",
}
ENUMERATIONS = {"Method": list(METHODS), "ToolShape": list(TOOL_SHAPES), "FootprintAnchor": list(ANCHORS),
                "PassSpacing": list(PASS_SPACINGS)}


def torus_radii(tool: Any) -> tuple[float, float]:
    """(Ro, Ri) of a ToolBit: bullnose (radius - corner, corner), ballend (0, radius), endmill (radius, 0:
    refused later by the core's own check)."""
    if tool is None:
        raise TmmError("the operation has no tool")
    name = shape_name(tool)
    label = getattr(tool, "Label", "tool")
    if name not in SUPPORTED_SHAPES:
        raise TmmError(f"tool '{label}' has the shape '{name}', which TMM 5-axis Multipoint does not support; "
                       "use a bullnose (toroidal) or ballend tool")
    d = _mm(tool.Diameter)
    if name == "ballend":
        return 0.0, d / 2
    if name == "endmill":
        corner = _mm(getattr(tool, "CornerRadius", 0.0))
        return d / 2 - corner, corner
    corner = bull_corner_radius(tool, d)
    return d / 2 - corner, corner


def face_surface(obj: Any, sub: str) -> Any:
    """The Part.BezierSurface / BSplineSurface of `obj`'s face `sub`, in document coordinates."""
    label = getattr(obj, "Label", "?")
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull():
        raise TmmError(f"'{label}' has no shape")
    try:
        face = shape.getElement(sub)
    except Exception as exc:  # Part.OCCError, ValueError
        raise TmmError(f"'{label}' has no element '{sub}' ({exc})") from None
    if face.ShapeType != "Face":
        raise TmmError(f"'{label}.{sub}' is a {face.ShapeType}, not a face")
    surf = face.Surface
    kind = type(surf).__name__
    if kind not in ("BezierSurface", "BSplineSurface"):
        raise TmmError(f"face '{label}.{sub}' is a {kind}: TMM 5-axis Multipoint needs a Bézier or B-spline "
                       "face (convert it, e.g. with Part's 'Convert to NURBS')")
    u0, u1, v0, v1 = face.ParameterRange
    u, v = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    if (surf.value(u, v) - face.valueAt(u, v)).Length > 1e-7:  # a surface in the shape's local frame
        surf = surf.copy()
        surf.transform(face.Placement.toMatrix())
        if (surf.value(u, v) - face.valueAt(u, v)).Length > 1e-6:
            raise TmmError(f"face '{label}.{sub}': cannot place its surface in document coordinates")
    return surf


def face_top(face: BezierFace, samples: int = 64) -> float:
    """Highest point of the face (sampled densely; FreeCAD's BoundBox depends on whether the shape was
    tessellated, and the control net's box is loose)."""
    import numpy as np

    u0, u1, v0, v1 = face.domain
    U, V = np.meshgrid(np.linspace(u0, u1, samples + 1), np.linspace(v0, v1, samples + 1), indexing="ij")
    return float(face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"][:, 2].max())


def lowest_drop(axis: tuple[float, float, float], Ro: float, Ri: float) -> float:
    """How far the lowest point of the tool is below its tip for a tool axis `axis` (>= 0)."""
    c = max(-1.0, min(1.0, axis[2]))
    return Ri * (1.0 - c) + Ro * math.sqrt(max(0.0, 1.0 - c * c))


def link_toolpath(res: MultipointResults, Ro: float, Ri: float, safe: float, clearance: float,
                  retract: float) -> Toolpath:
    """The op's tool path from the per-point results: cut segments as the core's (passes left and re-entered
    around failed points), linked as described in the module doc."""
    tip, axis, status, passes = res["tip"], res["axis"], res["status"], res.passes
    segments: list[list[int]] = []
    current: list[int] = []
    for i in range(len(res)):
        if current and (passes[i] != passes[current[-1]] or status[i] == STATUS_FAILED):
            segments.append(current)
            current = []
        if status[i] != STATUS_FAILED:
            current.append(i)
    if current:
        segments.append(current)
    tp = Toolpath()
    if not segments:
        return tp

    def above(i: int, height: float) -> tuple[float, float, float, tuple[float, float, float]]:
        a = tuple(float(c) for c in axis[i])
        r = tip[i] + retract * axis[i]
        return float(r[0]), float(r[1]), max(float(r[2]), height + lowest_drop(a, Ro, Ri)), a

    first = segments[0][0]
    x, y, z, a = above(first, safe)
    tp.add(MoveKind.RAPID, x, y, max(clearance, z), Z_AXIS)
    tp.add(MoveKind.RAPID, x, y, max(clearance, z), a)
    for seg in segments:
        i0, i1 = seg[0], seg[-1]
        x, y, z, a = above(i0, safe)
        tp.add(MoveKind.RAPID, x, y, z, a)                       # transit (turns the tool above the entry)
        r = tip[i0] + retract * axis[i0]
        tp.add(MoveKind.RAPID, *r, a)                            # down to the entry point on the axis
        tp.add(MoveKind.PLUNGE, *tip[i0], a)                     # along the axis onto the face
        for i in seg[1:]:
            tp.add(MoveKind.FEED, *tip[i], tuple(axis[i]))
        a1 = tuple(float(c) for c in axis[i1])
        r = tip[i1] + retract * axis[i1]
        tp.add(MoveKind.RAPID, *r, a1)                           # back along the axis
        x, y, z, _ = above(i1, safe)
        tp.add(MoveKind.RAPID, x, y, z, a1)                      # straight up
    last = tp.moves[-1]
    top = max(clearance, last.z)
    tp.add(MoveKind.RAPID, last.x, last.y, top, last.axis)
    tp.add(MoveKind.RAPID, last.x, last.y, top, Z_AXIS)          # upright again at the clearance height
    return tp


def summary(res: MultipointResults) -> str:
    counts = res.counts()
    text = (f"{len(res)} footprint points: {counts['two']} two-contact, {counts['one']} one-contact, "
            f"{counts['failed']} failed")
    failed = [r for r, s in zip(res.reason_texts(), res.status) if s == STATUS_FAILED]
    if failed:
        by_reason: dict[str, int] = {}
        for r in failed:
            by_reason[r] = by_reason.get(r, 0) + 1
        text += " (" + ", ".join(f"{n} {r}" for r, n in sorted(by_reason.items(), key=lambda t: -t[1])) + ")"
    return text


class ObjectTmmMultipoint(op_base.TmmOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath` (the op's linked
    tool path), `core_toolpath` (the core's), `results` (per footprint point), `face`, `radii` (Ro, Ri)."""

    PROPERTIES = PROPERTIES
    ENUMERATIONS = ENUMERATIONS
    DEFAULTS = DEFAULTS
    READ_ONLY = ("ContactSummary",)
    SUPPORTED_SHAPES = SUPPORTED_SHAPES
    toolpath: Optional[Toolpath] = None
    core_toolpath: Optional[Toolpath] = None
    results: Optional[MultipointResults] = None
    face: Optional[BezierFace] = None
    radii: Optional[tuple[float, float]] = None

    def opFeatures(self, obj: Any) -> int:
        return PathOp.FeatureTool | PathOp.FeatureHeights | PathOp.FeatureCoolant | PathOp.FeatureBaseFaces

    def opOnDocumentRestored(self, obj: Any) -> None:
        self.ensure_properties(obj, restoring=True)
        hooks.attach_view("multipoint_op", obj)

    def opRejectAddBase(self, obj: Any, base: Any, sub: str) -> bool:
        return not str(sub).startswith("Face")

    # --- computation -------------------------------------------------------------------------
    def opExecute(self, obj: Any) -> None:
        self.toolpath = self.core_toolpath = self.results = self.face = self.radii = None

        def compute() -> None:
            base, sub = self.base_face(obj)
            surf = face_surface(base, sub)
            face = BezierFace.from_freecad_surface(surf, name=f"{base.Label}.{sub}")
            Ro, Ri = torus_radii(self.tool)
            params = self.params(obj)
            safe, clearance = obj.SafeHeight.Value, obj.ClearanceHeight.Value
            top = face_top(face)
            if safe <= top:
                raise TmmError(f"safe height {safe:g} mm must be above the face's top {top:g} mm")
            if clearance < safe:
                raise TmmError(f"clearance height {clearance:g} mm is below the safe height {safe:g} mm")
            with progress.reporter(obj.Label, self.progress_enabled) as cb:
                core_tp, res = compute_multipoint_toolpath(face, Ro, Ri, params, METHODS[obj.Method], cb)
            toolpath = link_toolpath(res, Ro, Ri, safe, clearance, obj.AxisRetract.Value)
            if not len(toolpath):
                raise TmmError(f"no tool position found on the face ({summary(res)})")
            self.face, self.radii, self.results = face, (Ro, Ri), res
            self.core_toolpath, self.toolpath = core_tp, toolpath
            text = summary(res)
            if obj.ContactSummary != text:
                obj.ContactSummary = text
            FreeCAD.Console.PrintMessage(f"{obj.Label}: {text}\n")
            self.commandlist.extend(Path.Command(n, p) for n, p in
                                    path5.encode_toolpath(toolpath, self.horizFeed, self.vertFeed))

        self.guarded(obj, compute)

    def on_fail(self, obj: Any) -> None:
        if obj.ContactSummary:
            obj.ContactSummary = ""

    def base_face(self, obj: Any) -> tuple[Any, str]:
        pairs = [(o, s) for o, subs in (obj.Base or []) for s in (subs or ())]
        if not pairs:
            raise TmmError("no face selected: set Base to one Bézier or B-spline face")
        faces = [(o, s) for o, s in pairs if str(s).startswith("Face")]
        if len(faces) != 1 or len(pairs) != 1:
            names = ", ".join(f"{o.Label}.{s}" for o, s in pairs)
            raise TmmError(f"select exactly one face (Base holds {names})")
        return faces[0]

    def params(self, obj: Any) -> MultipointParams:
        return MultipointParams(
            side_step=obj.SideStep.Value, pass_spacing=PASS_SPACINGS[obj.PassSpacing],
            forward_step=obj.ForwardStep.Value,
            feed_angle_deg=obj.FeedAngle.Value, margin=obj.BoundaryMargin.Value, zigzag=bool(obj.ZigZag),
            shape=TOOL_SHAPES[obj.ToolShape], beta_max_deg=obj.TiltLimit.Value, tol=obj.Tolerance.Value,
            extend=obj.SurfaceExtension.Value, anchor=ANCHORS[obj.FootprintAnchor])


def SetupProperties() -> list[str]:
    return [name for _, name, _, _ in PROPERTIES if name != "ContactSummary"]


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`
    (e.g. {"Base": [(clone, ("Face1",))], "SideStep": 18.0})."""
    return op_base.create(ObjectTmmMultipoint, "multipoint_op", name, obj, parentJob, values)


PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)
