"""'TMM Roughing': a Path operation that rough-machines the Job's stock down to the model plus stock to
leave in z-levels (core.strategies.zlevel_rough: per layer the region the tool centre may reach, cleared by
offset or zig-zag passes at a step-over in % of the diameter, entered by helix, ramp or plunge).

What is machined: as the Surface op (op_surface: `StlFile`, then `Model`, then the Job's model; STL files,
Mesh and Part objects). What is cut: the Job's stock solid. Its bounding box is the strategy's `stock_box`;
a stock that is not a box (a cylinder, a solid of any shape) also gives its top as heights on a grid
(`stock_heights`, from app.simulation's stock-as-heights helper), so no air above it is cut. After earlier ops
in the Job, the stock is what they left (app.simulation.rest_stock: the stock solid cut by their Paths), so a
second roughing cuts only the material the first could not reach and enters just above it.

Heights: FreeCAD's SafeHeight and ClearanceHeight (their SetupSheet defaults put them above the stock top).
The step-down is refused when it is deeper than the ToolBit's CuttingEdgeHeight (the core's plain cutters
have no length: that check is here). Feeds from the tool controller as the Surface op's (op_surface.commands).
Errors never leave a partial path (op_base.guarded/fail).
"""
from __future__ import annotations

import math
from typing import Any, Optional

from tmm_workbench.app import geometry, op_base, op_mesh, progress, simulation, stages, tool_assembly, work_estimate
from tmm_workbench.app.compat import PathSetupSheet, PathUtils
from tmm_workbench.app.op_base import Prop
from tmm_workbench.app.tools import label_of
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.strategies import zlevel_rough
from tmm_workbench.core.strategies.zlevel_rough import RoughingParams

OP_NAME = "TMM_Roughing"
LAYER_MODES = {"Fixed": "fixed", "Tolerance": "tolerance"}
PATTERNS = {"Offset": "offset", "ZigZag": "zigzag"}
DIRECTIONS = {"Climb": "climb", "Conventional": "conventional"}
ENTRIES = {"Helix": "helix", "Ramp": "ramp", "Plunge": "plunge"}
STEEP_DESCENT_DEG = 45.0   # cutting moves down more steeply than this run at the vertical feed
STOCK_CELL_MM = 0.5        # grid of a stock that is not a box (its top as heights)

PROPERTIES: list[Prop] = op_mesh.MODEL_PROPERTIES + [
    Prop("App::PropertyDistance", "StepDown", "Layers", "Depth of each z-level (at most the tool's cutting edge "
         "height)", "step_down"),
    Prop("App::PropertyEnumeration", "LayerMode", "Layers",
         "Fixed: layers StepDown apart; Tolerance: as deep as the remaining material allows (seed 000, eq. 3.11)",
         "layer_mode"),
    Prop("App::PropertyDistance", "RemainingHeight", "Layers",
         "Tolerance mode: the largest step of material left on a slope between layers", "remaining_height"),
    Prop("App::PropertyBool", "FlatLayers", "Layers",
         "Extra layers at the model's flat areas, so no plateau keeps more than the stock to leave", "flat_layers"),
    Prop("App::PropertyBool", "UseFinalZ", "Layers", "Stop at FinalZ instead of the model's lowest point"),
    Prop("App::PropertyDistance", "FinalZ", "Layers", "Lowest layer when UseFinalZ is set"),
    Prop("App::PropertyFloat", "StepOver", "Clearing", "Distance between clearing passes, % of the tool diameter",
         "stepover_percent"),
    Prop("App::PropertyEnumeration", "Pattern", "Clearing",
         "Offset: contour-parallel passes; ZigZag: parallel passes inside each region", "pattern"),
    Prop("App::PropertyEnumeration", "Direction", "Clearing", "Climb or conventional milling", "direction"),
    Prop("App::PropertyDistance", "StockToLeave", "Clearing", "Material left on the model's sides (radial)",
         "stock_to_leave"),
    Prop("App::PropertyDistance", "AxialStockToLeave", "Clearing",
         "Material left on top of the model's flat areas (axial); by default the expression 'StockToLeave'",
         "stock_to_leave_axial"),
    Prop("App::PropertyDistance", "ChordTolerance", "Clearing", "Largest deviation of the passes' chords",
         "chord_tol"),
    Prop("App::PropertyBool", "KeepToolDown", "Linking",
         "Links inside a region with the tool down where the straight link stays in the region", "keep_tool_down"),
    Prop("App::PropertyEnumeration", "Entry", "Linking",
         "Helix or ramp into the material; Plunge only for a tool that can cut straight down", "entry"),
    Prop("App::PropertyAngle", "RampAngle", "Linking", "Descent angle of helix and ramp entries", "ramp_angle_deg"),
    Prop("App::PropertyFloat", "HelixDiameter", "Linking", "Diameter of the helix entry, % of the tool diameter",
         "helix_diameter_percent"),
]
CHOICES = {"LayerMode": LAYER_MODES, "Pattern": PATTERNS, "Direction": DIRECTIONS, "Entry": ENTRIES}
DEFAULTS: dict[str, Any] = {**op_mesh.MODEL_DEFAULTS, "UseFinalZ": False, "FinalZ": 0.0}
# the whole tool: holder, stick-out, clearances (app.tool_assembly), declared once for every mesh op
TOOL_STAGES = (tool_assembly.STAGE,)
PROPERTIES += stages.properties(TOOL_STAGES)
CHOICES.update(stages.choices(TOOL_STAGES))
DEFAULTS.update(stages.defaults(TOOL_STAGES))
AXIAL_EXPRESSION = "StockToLeave"  # the axial stock to leave follows the radial one unless given


def stock_of(job: Any, stock: Any) -> dict[str, Any]:
    """The strategy's stock fields for the Job's stock solid: `stock_box`, and `stock_heights` (grid,
    heights) when the solid is not a box."""
    if stock is None or stock.Shape.isNull() or not stock.Shape.Solids:
        raise TmmError("the Job has no stock solid to rough from")
    out: dict[str, Any] = {"stock_box": geometry.stock_box_of(stock)}
    if not geometry.is_box(stock.Shape):
        from tmm_workbench.core.sim.grid import Grid

        bb = stock.Shape.BoundBox
        grid = Grid.covering(bb.XMin, bb.YMin, bb.XMax, bb.YMax, STOCK_CELL_MM)
        out["stock_heights"] = (grid, simulation.stock_heights(job, grid))
    return out


def check_step_down(tool: Any, step_down: float) -> None:
    """The step-down against the ToolBit's cutting edge height (the core's cutter has no length)."""
    edge = getattr(tool, "CuttingEdgeHeight", None)
    if edge is None:
        return
    edge = float(getattr(edge, "Value", edge))
    if math.isfinite(edge) and edge > 0 and step_down > edge:
        raise TmmError(f"step-down {step_down:g} mm is larger than the cutting edge height {edge:g} mm of tool "
                       f"'{label_of(tool)}' (allowed: up to {edge:g} mm)")


class ObjectTmmRoughing(op_mesh.MeshOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath`, `mesh`, `params`
    (the strategy's, as computed)."""

    ESTIMATE = staticmethod(work_estimate.roughing)  # its strategy's inputs from the properties
    STRATEGY = zlevel_rough  # its estimate_work (core.work)

    VIEW_KIND = "roughing_op"
    PARAMS = RoughingParams
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    SPECS = stages.specs(TOOL_STAGES)
    RESTORED_DEFAULTS = stages.restored(TOOL_STAGES)
    params: Optional[RoughingParams] = None

    def opSetDefaultValues(self, obj: Any, job: Any) -> None:
        obj.setExpression("AxialStockToLeave", AXIAL_EXPRESSION)  # a given value replaces it
        super().opSetDefaultValues(obj, job)

    # --- computation -------------------------------------------------------------------------
    def clear_results(self) -> None:
        self.mesh = self.toolpath = self.params = None

    def compute(self, obj: Any) -> None:
        mesh = self.model_mesh(obj)
        cutter = self.cutter()
        check_step_down(self.tool, obj.StepDown.Value)
        job = PathUtils.findParentJob(obj)
        final_z = obj.FinalZ.Value if obj.UseFinalZ else None
        stock = stock_of(job, self.stock)
        rest = simulation.rest_stock(obj, cutter)   # earlier ops in the Job: cut only what they left
        if rest is not None:
            stock["stock_heights"] = rest
        params = self.params_from(obj, final_z=final_z, **stock)
        tool_assembly.prepare(obj, params)  # the shank and holder kept clear (no holder: the cutter alone)
        policy = LinkPolicy(obj.SafeHeight.Value, obj.ClearanceHeight.Value)
        with self.reporting(obj) as cb:
            toolpath = zlevel_rough.compute_roughing_toolpath(mesh, cutter, params, policy,
                                                              progress.phase(cb, 0.0, progress.KERNEL_SHARE))
            if not len(toolpath):
                left = "what the Job's earlier ops left" if rest is not None else "the stock"
                raise TmmError(f"no material to remove: {left} lies within the model plus stock to leave")
            self.mesh, self.toolpath, self.params = mesh, toolpath, params
            tool_assembly.report(obj, params)
            self.add_moves(toolpath, STEEP_DESCENT_DEG, obj.ClearanceHeight.Value,
                           progress.phase(cb, progress.KERNEL_SHARE, 1.0))


def SetupProperties() -> list[str]:
    """Properties the Job's SetupSheet may hold defaults for."""
    return op_base.setup_properties(ObjectTmmRoughing, exclude=("StlFile", "Model"))


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`."""
    return op_base.create(ObjectTmmRoughing, "roughing_op", name, obj, parentJob, values)


PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)
