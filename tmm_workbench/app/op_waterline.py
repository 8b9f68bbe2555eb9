"""'TMM Waterline': a Path operation that finishes the steep walls of a model with closed loops at constant
heights (core.strategies.waterline: per level the loops where the cutter touches the model, linked by the
one linker with vertical retracts).

What is machined: as the Surface op (op_surface: `StlFile`, then `Model`, then the Job's model; STL files,
Mesh and Part objects). Boundary (the tool tip's XY box): the model's box grown by the tool radius (so the
tool reaches round the model's outside walls) and `BoundaryMargin`, or the Job stock's box and the margin.
Levels: a step-down below the model's top, then `StepDown` apart down to its lowest point (the last level exactly
there), or the same from TopZ down to BottomZ (UseZRange), within the Job's stock: a bottom below the stock's
bottom is refused. Heights: FreeCAD's SafeHeight and ClearanceHeight (their SetupSheet defaults put them above
the stock top); each loop is entered by a rapid down to 1 mm above what the earlier ops and the loops above left
standing off the design (`app.simulation.material_left`, core.linking.know_design), then fed; between loops the
tool hops 1 mm over the material along the way where that is below the safe height. The step-down is refused when it is deeper than the ToolBit's CuttingEdgeHeight.
Feeds from the tool controller as the Surface op's (op_surface.commands). Errors never leave a partial path.
"""
from __future__ import annotations

from typing import Any, Optional

from tmm_workbench.app import op_base, op_mesh, progress, rest_source, simulation, stages, tool_assembly, work_estimate
from tmm_workbench.app.compat import PathSetupSheet
from tmm_workbench.app.op_base import Prop
from tmm_workbench.app.op_roughing import STEEP_DESCENT_DEG, check_step_down
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import VERTICAL, LinkPolicy, know_op_design, link
from tmm_workbench.core.strategies import rest_joins, waterline
from tmm_workbench.core.strategies.waterline import WaterlineParams

OP_NAME = "TMM_Waterline"
DIRECTIONS = {"Climb": "climb", "Conventional": "conventional"}
BOUNDARIES = ("Model", "Stock")

PROPERTIES: list[Prop] = op_mesh.MODEL_PROPERTIES + [
    Prop("App::PropertyEnumeration", "BoundaryShape", "Boundary",
         "Area the tool tip may reach: the Model's XY box grown by the tool radius, or the Stock's XY box"),
    Prop("App::PropertyDistance", "BoundaryMargin", "Boundary",
         "Grows (positive) or shrinks (negative) the boundary on every side"),
    Prop("App::PropertyDistance", "StepDown", "Waterline", "Height between levels (at most the tool's cutting "
         "edge height)", "step_down"),
    Prop("App::PropertyDistance", "StockToLeave", "Waterline", "Material left on the model", "stock_to_leave"),
    Prop("App::PropertyDistance", "SampleStep", "Waterline",
         "Spacing of the points the loops are found from (0: automatic, from the tool and the chord tolerance)"),
    Prop("App::PropertyDistance", "ChordTolerance", "Waterline", "Largest deviation of the loops' chords",
         "chord_tol"),
    Prop("App::PropertyEnumeration", "Direction", "Waterline", "Climb or conventional milling", "direction"),
    Prop("App::PropertyBool", "UseZRange", "Levels", "Levels between TopZ and BottomZ instead of the model's "
         "top and lowest point"),
    Prop("App::PropertyDistance", "TopZ", "Levels", "Top of the levels when UseZRange is set: the first level is a "
         "step-down below it"),
    Prop("App::PropertyDistance", "BottomZ", "Levels", "Lowest level when UseZRange is set"),
]
CHOICES = {"BoundaryShape": {b: b for b in BOUNDARIES}, "Direction": DIRECTIONS}
DEFAULTS: dict[str, Any] = {**op_mesh.MODEL_DEFAULTS, "BoundaryShape": "Model",
                            "BoundaryMargin": 0.0, "SampleStep": 0.0, "UseZRange": False, "TopZ": 0.0,
                            "BottomZ": 0.0}
# the whole tool: holder, stick-out, clearances (app.tool_assembly), declared once for every mesh op
TOOL_STAGES = (tool_assembly.STAGE, rest_source.WATERLINE_STAGE)   # and the rest (its steep walls)
PROPERTIES += stages.properties(TOOL_STAGES)
CHOICES.update(stages.choices(TOOL_STAGES))
DEFAULTS.update(stages.defaults(TOOL_STAGES))


class ObjectTmmWaterline(op_mesh.MeshOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath`, `mesh`, `params`
    (the strategy's, as computed), `diagnostics` (the strategy's: levels, loops, points, top)."""

    ESTIMATE = staticmethod(work_estimate.waterline)  # its strategy's inputs from the properties
    STRATEGY = waterline  # its estimate_work (core.work)

    VIEW_KIND = "waterline_op"
    PARAMS = WaterlineParams
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    SPECS = stages.specs(TOOL_STAGES)
    RESTORED_DEFAULTS = stages.restored(TOOL_STAGES)
    params: Optional[WaterlineParams] = None
    diagnostics: Optional[dict] = None

    # --- computation -------------------------------------------------------------------------
    def clear_results(self) -> None:
        self.mesh = self.toolpath = self.params = self.diagnostics = None

    def compute(self, obj: Any) -> None:
        mesh = self.model_mesh(obj)
        cutter = self.cutter()
        check_step_down(self.tool, obj.StepDown.Value)
        sample = obj.SampleStep.Value
        extra: dict[str, Any] = {"boundary": self.boundary(obj, mesh, cutter.radius),
                                 "sample_step": None if sample == 0 else sample}
        if obj.UseZRange:
            extra.update(top_z=obj.TopZ.Value, bottom_z=obj.BottomZ.Value)
        if self.stock is not None and not self.stock.Shape.isNull():  # the levels stay within the stock
            bb = self.stock.Shape.BoundBox
            extra["stock_z"] = (bb.ZMin, bb.ZMax)
        params = self.params_from(obj, **extra)
        tool_assembly.prepare(obj, params)  # the shank and holder kept clear (no holder: the cutter alone)
        policy = LinkPolicy(obj.SafeHeight.Value, obj.ClearanceHeight.Value, retract=VERTICAL)
        policy.validate()
        policy.material_top = rest_source.material_left(obj, cutter)
        rest = rest_source.rest_of_op(obj, simulation.job_of(obj), mesh, cutter, policy.material_top,
                                      extra["boundary"])
        params.rest = None if rest is None else rest.stock
        # between loops the tool hops just above the material along the way, not up to the safe height; each loop
        # is entered by a rapid to just above what stands off the design (the loops above cut the wall down to it)
        policy.low_links = policy.material_top is not None
        rest_source.know_stock(obj, params, policy.material_top, mesh)   # clear of what is left too
        if policy.low_links and params.assembly is not None:   # and the shank and holder clear of walls beside them
            policy.hop_clear = rest_joins.bodies_clear(mesh, params.assembly, stock=params.stock)
        know_op_design(policy, mesh, params)
        with self.reporting(obj) as cb:
            result = waterline.compute(mesh, cutter, params, progress.phase(cb, 0.0, progress.KERNEL_SHARE))
            top = result.diagnostics.get("top")
            if top is not None and policy.safe_height <= top:
                raise TmmError(f"safe height {policy.safe_height:g} mm is not above the highest tool position "
                               f"{top:.4g} mm")
            # each loop is entered from above onto one of its points: a loop point is free (the tool's drop
            # height there is its level), so the plunge down to it cuts nothing of the model
            toolpath = link(result.segments, policy)  # the strategy refuses a result without loops
            self.mesh, self.toolpath, self.params = mesh, toolpath, params
            self.diagnostics = dict(result.diagnostics)
            tool_assembly.report(obj, params)
            rest_source.report(obj, rest)
            self.add_moves(toolpath, STEEP_DESCENT_DEG, obj.ClearanceHeight.Value,
                           progress.phase(cb, progress.KERNEL_SHARE, 1.0))


def SetupProperties() -> list[str]:
    """Properties the Job's SetupSheet may hold defaults for."""
    return op_base.setup_properties(ObjectTmmWaterline, exclude=("StlFile", "Model"))


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`."""
    return op_base.create(ObjectTmmWaterline, "waterline_op", name, obj, parentJob, values)


PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)
