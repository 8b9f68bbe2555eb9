"""'TMM 3-axis Surface': a Path operation that finishes a mesh (or a tessellated Part) with a
drop-cutter raster computed by the TMM kernel.

What is machined, first match wins:
  1. `StlFile`: an STL file read by the core;
  2. `Model`: a Mesh::Feature (its triangles) or a Part object (tessellated within `LinearDeflection`);
  3. the Job's Model: Part solids are tessellated; TMM's stand-in boxes for meshes
     (`model_proxy.ModelBounds`, 0.20 Jobs cannot hold meshes) are replaced by the mesh they stand for.

The tool comes from the op's tool controller (`tools.cutter_from_tool`, the one ToolBit map), feeds from ObjectOp.execute
(mm/s in properties: `self.horizFeed` on cutting moves, `self.vertFeed` on plunges; rapids carry no F).
Errors (TmmError, cancel, anything unexpected) never leave a partial path: the Path is emptied, the
message goes to the report view and the op is marked invalid with that message (its status string).
"""
from __future__ import annotations

from typing import Any, Optional

import FreeCAD

from tmm_workbench.app import op_base, op_mesh, progress, region_source, simulation, work_estimate
from tmm_workbench.app import surface_passes
from tmm_workbench.app import surface_verify
from tmm_workbench.app import offset_start
from tmm_workbench.app.compat import PathSetupSheet, PathUtils
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.strategies import finish_passes
from tmm_workbench.core.strategies.raster_drop import (INWARD, OFF_MODEL_FLOOR, OFF_MODEL_SKIP, OFFSET3D, ONEWAY,
                                                       OUTWARD, SAMPLED, SPIRAL, STEPOVER, TOLERANCE, ZIGZAG,
                                                       SurfaceParams)

OP_NAME = "TMM_Surface"
PATTERNS = {"ZigZag": ZIGZAG, "OneWay": ONEWAY, "Spiral": SPIRAL}
OFF_MODEL = {"Floor": OFF_MODEL_FLOOR, "Skip": OFF_MODEL_SKIP}
BOUNDARIES = ("Stock", "Model")

PROPERTIES: list[Prop] = op_mesh.MODEL_PROPERTIES + [
    Prop("App::PropertyEnumeration", "BoundaryShape", "Boundary",
         "Area covered by the tool tip: the Stock's or the Model's XY bounding box"),
    Prop("App::PropertyDistance", "BoundaryMargin", "Boundary",
         "Grows (positive) or shrinks (negative) the boundary on every side"),
    Prop("App::PropertyDistance", "StepOver", "Surface", "Distance between raster passes", "stepover"),
    Prop("App::PropertyEnumeration", "StepOverMode", "Surface",
         "StepOver: passes StepOver apart; Cusp: the step-over that keeps CuspHeight on the worst crossing of "
         "the boundary, slope and curvature (up to CuspSlopeLimit); Adaptive: each pass placed from the previous one's tool positions "
         "so that the cusp between them is CuspHeight", "stepover_mode"),
    Prop("App::PropertyDistance", "CuspHeight", "Surface",
         "Largest scallop left between passes (Cusp and Adaptive spacing), along the surface normal", "cusp"),
    Prop("App::PropertyAngle", "CuspSlopeLimit", "Surface",
         "Steeper places are not held to CuspHeight (walls are waterline's)", "max_slope_deg"),
    Prop("App::PropertyDistance", "SampleStep", "Surface", "Sampling step along a pass", "sample_step"),
    Prop("App::PropertyAngle", "RasterAngle", "Surface", "Direction of the passes, from +X", "angle_deg"),
    Prop("App::PropertyEnumeration", "Pattern", "Surface",
         "ZigZag: cut both ways, linked over the surface; OneWay: cut one way, retract between passes; "
         "Spiral: from the region's centre (SpiralDirection)", "pattern"),
    Prop("App::PropertyDistance", "StockToLeave", "Surface", "Material left on the surface", "stock_to_leave"),
    Prop("App::PropertyDistance", "ChordTolerance", "Surface",
         "The tolerance of the moves: with ForwardStep Tolerance, how far above or below the exact tool path a "
         "move may pass; with SampleStep, how far above the CL points a longer straight move may pass where it "
         "replaces them (never below one; 0: keep every point off a straight line)", "chord_tol"),
    # lean passes: the forward step by ChordTolerance, arcs in the pass's plane
    Prop("App::PropertyEnumeration", "ForwardStep", "Surface",
         "Tolerance: the fewest moves within ChordTolerance of the exact tool path, above or below it (points "
         "added where a move would leave it, removed where a longer move stays in it); SampleStep: a point "
         "every SampleStep, moves above them only"),
    Prop("App::PropertyBool", "ArcFitting", "Surface",
         "With ForwardStep Tolerance, passes at 0 or 90 deg get arcs (G2/G3 in G18 XZ / G19 YZ) where they fit "
         "within ChordTolerance; lines where the Job's post drops K (linuxcnc, mach3_mach4, ...)", "arcs"),
    Prop("App::PropertyAngle", "PlungeAngle", "Feeds",
         "Cutting moves going down more steeply than this (below the horizontal) run at the vertical feed"),
    Prop("App::PropertyEnumeration", "OffModel", "Surface",
         "Where no part of the model is under the tool (beside an open surface, in a hole): Floor cuts along the "
         "floor (the model's lowest point); Skip lifts over it and cuts only over the model", "off_model"),
    # --- machining region, spiral, slope range (app.region_source) ---
    Prop("App::PropertyEnumeration", "Region", "Region",
         "Where the tool centre may go: Box (BoundaryShape with BoundaryMargin), Faces (RegionFaces seen from "
         "above), Sketch (the closed loops of RegionSketch seen from above, inner loops are holes)"),
    Prop("App::PropertyLinkSubListGlobal", "RegionFaces", "Region", "Faces of the model bounding the region"),
    Prop("App::PropertyLink", "RegionSketch", "Region", "Sketch (or closed edges) bounding the region"),
    Prop("App::PropertyDistance", "RegionTolerance", "Region",
         "How far the region's polygon may depart from the faces' or the sketch's exact outline"),
    Prop("App::PropertyEnumeration", "SpiralDirection", "Surface",
         "Spiral pattern: from the region's centre Outward, or Inward to it", "spiral_direction"),
    Prop("App::PropertyAngle", "SlopeMin", "Surface",
         "Cut only where the surface slope is at least this (shallower areas left to another op)", "slope_min_deg"),
    Prop("App::PropertyAngle", "SlopeMax", "Surface",
         "Cut only where the surface slope is at most this (steeper walls left to waterline)", "slope_max_deg"),
]
FORWARD_STEPS = {"Tolerance": TOLERANCE, "SampleStep": SAMPLED}
CHOICES = {"BoundaryShape": {b: b for b in BOUNDARIES}, "Pattern": PATTERNS, "OffModel": OFF_MODEL,
           "StepOverMode": surface_passes.SPACINGS, "ForwardStep": FORWARD_STEPS}
DEFAULTS: dict[str, Any] = {**op_mesh.MODEL_DEFAULTS, "BoundaryShape": "Stock",
                            "BoundaryMargin": 0.0, "PlungeAngle": 45.0, "ForwardStep": "SampleStep"}
CHOICES.update({"Region": {r: r for r in region_source.REGIONS},
                "SpiralDirection": {"Outward": OUTWARD, "Inward": INWARD}})
DEFAULTS.update({"Region": region_source.BOX, "RegionTolerance": 0.01})
# lean passes by default for new ops since the fit is in the kernel; documents saved without the property
# restore with SampleStep (RESTORED_DEFAULTS)
DEFAULTS["ForwardStep"] = "Tolerance"
# FreeCAD posts whose parameter list has no K: an arc in XZ or YZ would lose its centre's Z (0.20-1.1)
POSTS_WITHOUT_K = ("linuxcnc", "tmm_linuxcnc", "mach3_mach4", "fanuc", "KineticNCBeamicon2", "comparams", "dxf",
                   "fablin", "jtech", "nccad", "opensbp", "rml", "estlcam", "fangling", "generic", "wedm")
# % step-over, Depths (final depth, finishing passes) and start point: app.surface_passes
PROPERTIES += surface_passes.PROPERTIES
CHOICES.update(surface_passes.CHOICES)
DEFAULTS.update(surface_passes.DEFAULTS)
# the verification pass: partial passes where the simulated cusp exceeds CuspHeight
PROPERTIES += surface_verify.PROPERTIES
CHOICES.update(surface_verify.CHOICES)
# the 3D offset's start: the region's boundary or a chosen curve (app.offset_start)
PROPERTIES += offset_start.PROPERTIES
CHOICES.update(offset_start.CHOICES)
DEFAULTS.update(offset_start.DEFAULTS)


class ObjectTmmSurface(op_mesh.MeshOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath`, `mesh`."""

    ESTIMATE = staticmethod(work_estimate.surface)  # the work from the properties (app.work_estimate)

    PARAMS = SurfaceParams
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    # documents from before them kept every point, on the samples
    RESTORED_DEFAULTS = {"ChordTolerance": 0.0, "ForwardStep": "SampleStep"}

    # --- computation -------------------------------------------------------------------------
    def clear_results(self) -> None:
        self.mesh = self.toolpath = None

    def compute(self, obj: Any) -> None:
        mesh = self.model_mesh(obj)
        cutter = self.cutter()
        region = region_source.region_of(obj, PathUtils.findParentJob(obj))  # None: the box
        boundary = self.boundary(obj, mesh) if region is None else polygons.bounds(region)
        params = self.params_from(obj, boundary=boundary, region=region,
                                  forward_step=FORWARD_STEPS.get(getattr(obj, "ForwardStep", ""), SAMPLED),
                                  **surface_passes.params_extra(obj, cutter))
        params.offset_from = offset_start.curves_of(obj, params.stepover_mode == OFFSET3D)
        flat_cusp = check_tool_fit(params, cutter)
        if flat_cusp:
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {flat_cusp}\n")
        if params.arcs and self.post_without_k(obj):
            params.arcs = False
            FreeCAD.Console.PrintWarning(
                f"{obj.Label}: ArcFitting off: the Job's post '{self.post_without_k(obj)}' writes no K, so arcs in "
                "XZ/YZ would be wrong; lines within ChordTolerance instead\n")
        finish = surface_passes.finish_params(obj)
        check_final_depth(obj, finish.final_depth)
        # entries rapid to just above what the Job's earlier ops left and feed from there
        policy = LinkPolicy(obj.SafeHeight.Value, obj.ClearanceHeight.Value,
                            material_top=simulation.material_left(obj, cutter))
        notes = surface_verify.notes_for(params)  # VerifyCusp's reports
        with progress.reporter(obj.Label, self.progress_enabled) as cb:
            toolpath = finish_passes.compute_finish_toolpath(mesh, cutter, params, finish, policy, cb)
        surface_verify.report(obj, notes)
        self.mesh, self.toolpath = mesh, toolpath
        self.commandlist.extend(self.commands(toolpath, obj.PlungeAngle.Value, obj.ClearanceHeight.Value))

    def post_without_k(self, obj: Any) -> str:
        """The Job's post processor when it drops the K word of arcs, else ''."""
        job = PathUtils.findParentJob(obj)
        name = str(getattr(job, "PostProcessor", "") or "")
        return name if name in POSTS_WITHOUT_K else ""



def SetupProperties() -> list[str]:
    """Properties the Job's SetupSheet may hold defaults for."""
    return op_base.setup_properties(ObjectTmmSurface, exclude=("StlFile", "Model", "RegionFaces", "RegionSketch",
                                                                     "OffsetCurve"))


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`."""
    return op_base.create(ObjectTmmSurface, "op", name, obj, parentJob, values)


# Lets the Job's SetupSheet hold defaults for this op, headless too (the GUI's SetupOperation repeats it).
PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)


def check_tool_fit(params: SurfaceParams, cutter: Any) -> str:
    """A step-over wider than the tool leaves strips no pass touches: refused by name. A cusp spacing with a flat
    end mill (its cusps come from the bottom's edge on every slope, so the passes crowd): the warning to show."""
    if params.stepover_mode == STEPOVER and params.stepover > cutter.diameter:
        raise TmmError(f"StepOver {params.stepover:g} mm is wider than the tool (diameter {cutter.diameter:g} mm): "
                       f"strips between the passes would stay uncut; set it to at most {cutter.diameter:g} mm")
    if params.stepover_mode != STEPOVER and cutter.corner_radius <= 0:
        return (f"{params.stepover_mode} spacing with a flat end mill: its cusps come from the edge of its flat "
                "bottom on every slope, so the passes fall very close together (many more than with a rounded "
                f"tool); a ball or bull-nose end mill of the same diameter holds CuspHeight {params.cusp:g} mm "
                "with far fewer passes")
    return ""


def check_final_depth(obj: Any, final_depth: Optional[float]) -> None:
    """A final depth below the Job's stock would let the passes follow the model where no stock is: refused by
    name, as roughing and waterline refuse levels below it."""
    job = PathUtils.findParentJob(obj)
    stock = getattr(job, "Stock", None) if job is not None else None
    if final_depth is None or stock is None or stock.Shape.isNull():
        return
    bottom = float(stock.Shape.BoundBox.ZMin)
    if final_depth < bottom - 1e-6:
        raise TmmError(f"FinalDepth {final_depth:g} mm is below the stock's bottom {bottom:g} mm: set it within the "
                       f"stock ({bottom:g} to {float(stock.Shape.BoundBox.ZMax):g} mm) or turn UseFinalDepth off")
