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

from tmm_workbench.app import offset_start, op_base, op_mesh, pencil_source, progress, region_source
from tmm_workbench.app import stages
from tmm_workbench.app import rest_source, surface_passes, surface_verify, tool_assembly, work_estimate
from tmm_workbench.app.compat import PathSetupSheet, PathUtils
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.stage import Field, Stage
from tmm_workbench.core.strategies import finish_passes, raster_drop, rest_joins
from tmm_workbench.core.strategies.surface import forward_step, pattern, positioning
from tmm_workbench.core.strategies.surface.estimate import tool_fit
from tmm_workbench.core.strategies.surface.params import OFFSET3D, SAMPLED, SurfaceParams

OP_NAME = "TMM_Surface"
BOUNDARIES = ("Stock", "Model")
# FreeCAD posts whose parameter list has no K: an arc in XZ or YZ would lose its centre's Z (0.20-1.1)
POSTS_WITHOUT_K = ("linuxcnc", "tmm_linuxcnc", "mach3_mach4", "fanuc", "KineticNCBeamicon2", "comparams", "dxf",
                   "fablin", "jtech", "nccad", "opensbp", "rml", "estlcam", "fangling", "generic", "wedm")

BOUNDARY_STAGE = Stage("boundary", (
    Field("BoundaryShape", "choice", "Boundary",
          "Area covered by the tool tip: the Stock's or the Model's XY bounding box", api="boundary",
          choices={b: b for b in BOUNDARIES}, default="Stock", widget="boundaryShape"),
    Field("BoundaryMargin", "length", "Boundary", "Grows (positive) or shrinks (negative) the boundary on every side",
          api="margin", default=0.0, widget="boundaryMargin"),
))
LINKING_STAGE = Stage("linking", (
    Field("PlungeAngle", "angle", "Feeds",
          "Cutting moves going down more steeply than this (below the horizontal) run at the vertical feed",
          default=45.0),
))
# the op's stages in the order of their properties (documents keep that order); the Surface's pipeline runs
# pattern -> positioning -> forward step -> verification -> linking (core.strategies.raster_drop)
STAGES = (op_mesh.MODEL_STAGE, BOUNDARY_STAGE, pattern.STAGE, positioning.STAGE, forward_step.STAGE,
          LINKING_STAGE, region_source.STAGE, surface_passes.STAGE, surface_verify.STAGE, offset_start.STAGE,
          tool_assembly.STAGE, rest_source.STAGE, pencil_source.STAGE)
PROPERTIES: list[Prop] = stages.properties(STAGES)
CHOICES = stages.choices(STAGES)
DEFAULTS: dict[str, Any] = stages.defaults(STAGES)
SPECS = stages.specs(STAGES)


class ObjectTmmSurface(op_mesh.MeshOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath`, `mesh`, `rest`
    (app.rest_source.Rest of a rest op)."""

    ESTIMATE = staticmethod(work_estimate.surface)  # its strategy's inputs from the properties
    STRATEGY = raster_drop  # its estimate_work (core.work)

    PARAMS = SurfaceParams
    STAGES = STAGES
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    SPECS = SPECS
    # documents from before them kept every point, on the samples
    RESTORED_DEFAULTS = {"ChordTolerance": 0.0, "ForwardStep": "SampleStep", **stages.restored(STAGES)}

    # --- computation -------------------------------------------------------------------------
    def clear_results(self) -> None:
        self.mesh = self.toolpath = self.rest = None

    def compute(self, obj: Any) -> None:
        mesh = self.model_mesh(obj)
        cutter = self.cutter()
        job = PathUtils.findParentJob(obj)
        left = rest_source.material_left(obj, cutter)   # what the Job's earlier ops left (None: not known)
        rest = None
        if getattr(obj, "Region", "") == region_source.REST:   # only where they (or a larger tool) left material
            rest = rest_source.rest_of(obj, job, mesh, cutter, left, self.boundary(obj, mesh))
            region = rest.region
        else:
            region = region_source.region_of(obj, job)  # None: the box
        boundary = self.boundary(obj, mesh) if region is None else polygons.bounds(region)
        params = self.params_from(obj, boundary=boundary, region=region,
                                  forward_step=forward_step.FORWARD_STEPS.get(getattr(obj, "ForwardStep", ""),
                                                                              SAMPLED),
                                  **surface_passes.params_extra(obj, cutter))
        params.offset_from = offset_start.curves_of(obj, params.stepover_mode == OFFSET3D)
        params.rest = None if rest is None else rest.stock
        params.pencil_curves = pencil_source.curves_of(obj)   # an outline's or a footprint file's (pattern Pencil)
        params.cleanup_reference = pencil_source.finishing_cutter(obj, cutter)   # the clean-up's finishing tool
        if rest is not None:   # its slopes' loops are told only now: refused above the limits before any is made
            lo, hi = mesh.bounds
            self.STRATEGY.estimate_work(params, cutter, (*map(float, lo), *map(float, hi)))
        flat_cusp = tool_fit(params, cutter)
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
        # and between pieces hop just over the material along the way, not up to the safe height
        policy = LinkPolicy(obj.SafeHeight.Value, obj.ClearanceHeight.Value, material_top=left,
                            low_links=left is not None)
        notes = surface_verify.notes_for(params)  # VerifyCusp's reports
        tool_assembly.prepare(obj, params)  # the shank and holder kept clear (no holder: the cutter alone)
        rest_source.know_stock(obj, params, left, mesh)   # and of what the earlier ops left above the model
        if policy.low_links and params.assembly is not None:   # its hops too, of walls beside them
            policy.hop_clear = rest_joins.bodies_clear(mesh, params.assembly, stock=params.stock)
        with self.reporting(obj) as cb:
            toolpath = finish_passes.compute_finish_toolpath(mesh, cutter, params, finish, policy,
                                                             progress.phase(cb, 0.0, progress.KERNEL_SHARE))
            surface_verify.report(obj, notes)
            tool_assembly.report(obj, params)
            rest_source.report(obj, rest, notes)
            self.mesh, self.toolpath, self.rest = mesh, toolpath, rest
            self.add_moves(toolpath, obj.PlungeAngle.Value, obj.ClearanceHeight.Value,
                           progress.phase(cb, progress.KERNEL_SHARE, 1.0))

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
