"""'TMM 5-axis Multipoint': a Path operation that finishes one Bézier or B-spline face with a toroidal
(bull-nose) or ball cutter by multipoint positioning (seed 001, core.multipoint).

Input: `Base` (FreeCAD's base-geometry property, as the stock face ops): exactly one face of one object,
usually of the Job's model clone. The face's `Surface` must be a Part.BezierSurface or Part.BSplineSurface;
it is taken in document (global) coordinates: FreeCAD's `Face.Surface` already carries the object's
Placement, and a surface that does not (checked by evaluating it against the face) is transformed by the
shape's Placement first. The whole (untrimmed) surface is machined.

Tool: the op's tool controller through the one ToolBit map (app.tools) to the core's cutter, whose toroidal
view gives the torus: bullnose -> Ro = radius - corner radius, Ri = corner radius; ballend -> Ro = 0, Ri =
radius; the strategy refuses other cutters (a flat end mill has no corner to tilt about) with its reason.

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

from dataclasses import replace
from typing import Any, Optional

import numpy as np

import FreeCAD
import Path

from tmm_workbench.app import geometry, hooks, op_base, progress, stages, tool_assembly, work_estimate
from tmm_workbench.app.compat import PathOp, PathSetupSheet
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.linking import link
from tmm_workbench.core.machine import TarusMachine
from tmm_workbench.core.report_text import within
from tmm_workbench.core.strategies import multipoint
from tmm_workbench.core.strategies.multipoint import (STATUS_FAILED, MultipointParams, MultipointResults,
                                                      face_top)
from tmm_workbench.core.toolpath import Toolpath

OP_NAME = "TMM_Multipoint"
METHODS = {"VCRF": "vcrf", "DRD": "drd"}
TOOL_SHAPES = {"RoundInsert": "round_insert", "BullNose": "bull_nose", "FromToolBit": "from_tool_bit"}
ANCHORS = {"Axis": "axis", "Tip": "tip"}
PASS_SPACINGS = {"Even": "even", "Fixed": "fixed", "Scallop": "scallop"}  # Scallop last: old enum indices stay
# what new ops get (the core's own defaults stay as they were for scripts): the side step from the scallop,
# the tool's solid from its ToolBit
NEW_OP_DEFAULTS: dict[str, Any] = {"PassSpacing": "Scallop", "ToolShape": "FromToolBit"}
MAX_AREAS_LISTED = 10  # areas where the scallop is not held, one warning line each (the rest counted)

PROPERTIES: list[Prop] = [
    Prop("App::PropertyEnumeration", "Method", "Multipoint",
         "How the tool is put on the face touching it at two points (seed 001): VCRF, vertical and circular ray "
         "firing (rays shot down and round the tool find the first contact and the tilt to the second; the "
         "faster); DRD, drop-rotate-drop (drop the tool, tilt it about the first contact until it touches again)",
         "method"),
    Prop("App::PropertyEnumeration", "ToolShape", "Multipoint",
         "RoundInsert: the seed's torus (round-insert cutter, hollow centre); BullNose: the torus plus its flat "
         "bottom disc (a solid bull-nose end mill; on convex faces its bottom keeps most positions at one "
         "contact); FromToolBit: from the tool controller's ToolBit (FreeCAD's bullnose, ballend and endmill bits "
         "are solid end mills: BullNose)", "shape"),
    Prop("App::PropertyDistance", "SideStep", "Footprint",
         "Distance between passes (see PassSpacing; with Scallop the first guess of the search)", "side_step"),
    Prop("App::PropertyEnumeration", "PassSpacing", "Footprint",
         "Scallop: each pass at the largest side step whose simulated scallop with the pass before is at most "
         "Scallop; Even: passes spread evenly over the boundary, at most SideStep apart; Fixed: passes exactly "
         "SideStep apart from the start edge and a last one on the far edge (seed 001's footprint: x = 0, 18, "
         "..., 144, 150)", "pass_spacing"),
    Prop("App::PropertyDistance", "Scallop", "Footprint",
         "Scallop height left between passes (PassSpacing Scallop), measured on the simulated tool positions",
         "scallop"),
    Prop("App::PropertyDistance", "ForwardStep", "Footprint",
         "Distance between tool positions along a pass (at most)", "forward_step"),
    Prop("App::PropertyAngle", "FeedAngle", "Footprint",
         "Direction of the passes seen from above, from +X (the footprint: the grid of XY points the tool is put "
         "on, pass by pass)", "feed_angle_deg"),
    Prop("App::PropertyDistance", "BoundaryMargin", "Footprint",
         "Grows (positive) or shrinks (negative) the face's XY extent covered by the footprint", "margin"),
    Prop("App::PropertyBool", "ZigZag", "Footprint", "Alternate the direction of the passes", "zigzag"),
    Prop("App::PropertyAngle", "TiltLimit", "Multipoint", "Largest tilt of the tool axis from the vertical",
         "beta_max_deg"),
    Prop("App::PropertyDistance", "Tolerance", "Multipoint", "Contact and gouge tolerance", "tol"),
    Prop("App::PropertyDistance", "SurfaceExtension", "Multipoint",
         "Position the tool against the face continued past its edges by this distance (0: off), so a pass over "
         "an edge rests on the continued surface instead of on the edge; every position is still checked "
         "against the real face. The tool radius (Ro + Ri) covers a pass centred on the edge", "extend"),
    Prop("App::PropertyEnumeration", "FootprintAnchor", "Footprint",
         "Axis: the tool axis before tilting passes through the footprint point (seed 001; the tilt moves the "
         "tip sideways); Tip: the tilted tool's tip lies on the footprint point (passes exactly one side step "
         "apart)", "anchor"),
    Prop("App::PropertyDistance", "GougeTolerance", "Multipoint",
         "Tolerance on the way from one position to the next (the tool moved in a straight line, its axis turning "
         "evenly): the deepest cut into the face, and the most material left beyond what the positions leave; "
         "where a move is out of it, positions are inserted halfway (0: not checked)", "between_tol"),
    Prop("App::PropertyDistance", "AxisRetract", "Linking",
         "Entry and exit distance along the tool axis (then straight up/down to the safe height)"),
    Prop("App::PropertyString", "ContactSummary", "Multipoint",
         "Result of the last computation: footprint points with two contacts, one contact, failed"),
]
CHOICES = {"Method": METHODS, "ToolShape": TOOL_SHAPES, "FootprintAnchor": ANCHORS, "PassSpacing": PASS_SPACINGS}
DEFAULTS: dict[str, Any] = {"AxisRetract": 5.0}

# the whole tool (app.tool_assembly) as the mesh ops have it, where a 5-axis tool can tilt away instead of rising
HOLDER_COLLISIONS = {"Tilt": "tilt", "LeaveOut": "leave_out"}
_COLLISION_TIP = ("Where the shank or holder would come closer to the face: Tilt the tool away from it (within "
                  "TiltLimit and the Tarus's C limits; what no tilt clears is left out, reported in HolderReport), "
                  "or LeaveOut those positions (the pass split there)")
TOOL_STAGE = replace(tool_assembly.STAGE, fields=tuple(
    replace(f, choices=HOLDER_COLLISIONS, api_names={"tilt": "Tilt", "leave_out": "LeaveOut"}, tip=_COLLISION_TIP)
    if f.prop == "HolderCollision" else f for f in tool_assembly.STAGE.fields))
TOOL_STAGES = (TOOL_STAGE,)
PROPERTIES += stages.properties(TOOL_STAGES)
CHOICES.update(stages.choices(TOOL_STAGES))
DEFAULTS.update(stages.defaults(TOOL_STAGES))


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


def tool_shape(prop_value: str, tool: Any) -> str:
    """The core's tool solid for the ToolShape property: FromToolBit -> bull_nose for the ToolBits TMM maps
    (FreeCAD's bullnose, ballend, endmill: solid end mills; none models a round insert)."""
    shape = TOOL_SHAPES[prop_value]
    return "bull_nose" if shape == "from_tool_bit" else shape


def uncut_strip_warning(pass_spacing: str, side_step: float, cutter: Any) -> str:
    """The warning for a fixed side step at least the tool's cutting width 2 (Ro + Ri) on a plane (strips
    between the passes the tool never touches), "" otherwise (and for the scallop rule)."""
    Ro, Ri = cutter.torus_radii
    if pass_spacing == "scallop" or side_step < 2.0 * (Ro + Ri):
        return ""
    return (f"side step {side_step:g} mm leaves uncut strips for this tool (cutting width {2.0 * (Ro + Ri):g} "
            "mm); use PassSpacing Scallop or a side step below it")


def spacing_warnings(params: MultipointParams, cutter: Any, placement: Any) -> list[str]:
    """What the user should know about the side step: a fixed step leaving strips the tool never touches
    (wider than its cutting width 2 (Ro + Ri) on a plane), strips the scallop rule could not keep within the
    tolerance."""
    out = []
    strips = uncut_strip_warning(params.pass_spacing, params.side_step, cutter)
    if strips:
        out.append(strips)
    if placement is not None:
        out.append(f"{len(placement.offsets)} passes, largest scallop {placement.max_scallop:.4g} mm "
                   f"(tolerance {params.scallop:g} mm)")
        areas = placement.unreached
        if areas:
            out.append(f"the scallop {params.scallop:g} mm is not held on {len(areas)} areas "
                       f"({within(np.vstack([a.outline for a in areas]))}), up to {max(a.height for a in areas):.4g} "
                       "mm above the face: machined as reached (the report view lists them)")
    return out


def area_lines(placement: Any) -> list[str]:
    """One line per area where the scallop rule could not hold the tolerance (at most MAX_AREAS_LISTED)."""
    areas = placement.unreached if placement is not None else []
    out = [a.describe() for a in areas[:MAX_AREAS_LISTED]]
    if len(areas) > MAX_AREAS_LISTED:
        out.append(f"... and {len(areas) - MAX_AREAS_LISTED} more areas")
    return out


def unreached_warning(res: MultipointResults) -> str:
    """Where no tool position was found (not machined), "" when every footprint point has one."""
    failed = res.xy[res.status == STATUS_FAILED]
    if not len(failed):
        return ""
    return f"{len(failed)} footprint points have no tool position and are not machined ({within(failed)})"


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
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath` (the op's tool
    path, linked once by core.linking), `segments` (the strategy's cut segments), `results` (per footprint
    point), `face`, `radii` (Ro, Ri), `placement` (the scallop rule's report, None for other spacings)."""

    ESTIMATE = staticmethod(work_estimate.multipoint)  # its strategy's inputs from the properties
    STRATEGY = multipoint  # its estimate_work (core.work)

    PARAMS = MultipointParams
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    SPECS = stages.specs(TOOL_STAGES)
    RESTORED_DEFAULTS = stages.restored(TOOL_STAGES)   # documents from before the holder: none
    READ_ONLY = ("ContactSummary",)
    toolpath: Optional[Toolpath] = None
    segments: Optional[list] = None
    results: Optional[MultipointResults] = None
    face: Optional[BezierFace] = None
    radii: Optional[tuple[float, float]] = None
    placement: Any = None  # the scallop rule's report (its `unreached`: areas where the scallop is not held)

    def opFeatures(self, obj: Any) -> int:
        return PathOp.FeatureTool | PathOp.FeatureHeights | PathOp.FeatureCoolant | PathOp.FeatureBaseFaces

    NEW_OP_DEFAULTS = NEW_OP_DEFAULTS  # declared exceptions to "defaults from the params dataclass"

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        return {**super().defaults(), **cls.NEW_OP_DEFAULTS}

    def opOnDocumentRestored(self, obj: Any) -> None:
        # enumerations saved before a choice was added get it, keeping their value (an old document keeps
        # its Even/Fixed side step and its tool shape: the path it was computed with)
        for name in ("PassSpacing", "ToolShape"):
            if hasattr(obj, name) and list(obj.getEnumerationsOfProperty(name)) != list(CHOICES[name]):
                value = getattr(obj, name)
                setattr(obj, name, list(CHOICES[name]))
                setattr(obj, name, value)
        self.ensure_properties(obj, restoring=True)
        hooks.attach_view("multipoint_op", obj)

    def opRejectAddBase(self, obj: Any, base: Any, sub: str) -> bool:
        return not str(sub).startswith("Face")

    # --- computation -------------------------------------------------------------------------
    def clear_results(self) -> None:
        self.toolpath = self.segments = self.results = self.face = self.radii = self.placement = None

    def params_from(self, obj: Any, **extra: Any) -> Any:
        """As every op's, with the tool solid the op computes with (FromToolBit read as the ToolBit's solid): the
        simulation and the panel's checks read the same."""
        extra.setdefault("shape", tool_shape(obj.ToolShape, None))
        return super().params_from(obj, **extra)

    def compute(self, obj: Any) -> None:
        base, sub = self.base_face(obj)
        surf = face_surface(base, sub)
        face = geometry.bezier_face(surf, name=f"{base.Label}.{sub}")
        cutter = self.cutter()
        params = self.params_from(obj)
        safe, clearance = obj.SafeHeight.Value, obj.ClearanceHeight.Value
        top = face_top(face)
        if safe <= top:
            raise TmmError(f"safe height {safe:g} mm must be above the face's top {top:g} mm")
        if clearance < safe:
            raise TmmError(f"clearance height {clearance:g} mm is below the safe height {safe:g} mm")
        tool_assembly.prepare(obj, params)  # the shank and holder kept off the face (no holder: the cutter alone)
        if params.assembly is not None:
            params.machine = TarusMachine()  # the post's machine: its C limits bound a tilt away
        with progress.reporter(obj.Label, self.progress_enabled) as cb:
            result = multipoint.compute(face, cutter, params, cb)
        res = result.diagnostics["results"]
        toolpath = link(result.segments, multipoint.link_policy(cutter, safe, clearance, obj.AxisRetract.Value))
        if not len(toolpath):
            raise TmmError(f"no tool position found on the face ({summary(res)})")
        self.face, self.radii, self.results = face, cutter.torus_radii, res
        self.segments, self.toolpath = result.segments, toolpath
        self.placement = result.diagnostics.get("scallop")
        text = summary(res)
        warnings = spacing_warnings(params, cutter, result.diagnostics.get("scallop"))
        unreached = unreached_warning(res)
        if unreached:
            warnings.append(unreached)
        for w in warnings + area_lines(result.diagnostics.get("scallop")):
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {w}\n")
        text = "; ".join([text] + warnings)
        if obj.ContactSummary != text:
            obj.ContactSummary = text
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {text}\n")
        between = result.diagnostics.get("between") or {}
        if between.get("remaining"):
            FreeCAD.Console.PrintWarning(
                f"{obj.Label}: {between['remaining']} moves between positions are still out of the tolerance "
                f"{params.between_tol:g} mm after {params.between_rounds} rounds of inserted positions (cutting "
                f"up to {between['deepest']:.4f} mm in, leaving up to {between['widest_gap']:.4f} mm); use a "
                "smaller ForwardStep\n")
        tool_assembly.report(obj, params)
        self.commandlist.extend(Path.Command(n, p) for n, p in
                                path5.encode_toolpath(toolpath, self.horizFeed, self.vertFeed))

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


def SetupProperties() -> list[str]:
    return op_base.setup_properties(ObjectTmmMultipoint, exclude=("ContactSummary",))


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`
    (e.g. {"Base": [(clone, ("Face1",))], "SideStep": 18.0})."""
    return op_base.create(ObjectTmmMultipoint, "multipoint_op", name, obj, parentJob, values)


PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)
