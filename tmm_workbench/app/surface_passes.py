"""The 3-axis Surface op's properties for what FreeCAD's 3D Surface users expect: the
step-over in % of the tool diameter, a Depths group (final depth, finishing passes over a semi-finish stock
to leave, their step-down) and a start point; the core is core.strategies.finish_passes.

Their defaults (mm step-over, no final depth, one pass, no start point) give the op's tool path from before
they existed, so documents saved before them restore and compute unchanged (op_base.ensure_properties).
"""
from __future__ import annotations

from typing import Any

import FreeCAD

from tmm_workbench.app.op_base import Prop
from tmm_workbench.core.strategies.finish_passes import STEPOVER_PERCENT, FinishParams, stepover_of_percent
from tmm_workbench.core.strategies.raster_drop import ADAPTIVE, CUSP, OFFSET3D, STEPOVER
from tmm_workbench.core.tools.cutter import Cutter

# the Surface's step-over modes, op property value -> core name; 3D offset: closed loops from the region's edge
# inward, CuspHeight apart across the surface (a document saved before it gets the choice on restore, op_base)
SPACINGS = {"StepOver": STEPOVER, "Cusp": CUSP, "Adaptive": ADAPTIVE, "Offset3D": OFFSET3D}

MM, PERCENT = "mm", "%"

PROPERTIES: list[Prop] = [
    Prop("App::PropertyEnumeration", "StepOverUnit", "Surface",
         "mm: passes StepOver apart; %: StepOverPercent of the tool diameter apart (StepOver spacing)"),
    Prop("App::PropertyFloat", "StepOverPercent", "Surface",
         "Distance between raster passes in % of the tool diameter, when StepOverUnit is %"),
    Prop("App::PropertyBool", "UseFinalDepth", "Depths", "No tool tip below FinalDepth (off: the model's lowest point)"),
    Prop("App::PropertyDistance", "FinalDepth", "Depths", "Lowest tool tip height, when UseFinalDepth is set"),
    Prop("App::PropertyInteger", "FinishPasses", "Depths",
         "Passes over the surface: the first ones leave StockToLeave + k x StepDown (semi-finish), the last "
         "StockToLeave"),
    Prop("App::PropertyDistance", "StepDown", "Depths",
         "Stock each finishing pass removes over the next one (FinishPasses > 1)"),
    Prop("App::PropertyBool", "UseStartPoint", "Start Point",
         "Each pass set begins at the end of the raster nearest StartPoint (X, Y)"),
    Prop("App::PropertyVectorDistance", "StartPoint", "Start Point", "Where the cutting starts (X and Y are used)"),
]
CHOICES: dict[str, dict[str, Any]] = {"StepOverUnit": {MM: MM, PERCENT: PERCENT}}
DEFAULTS: dict[str, Any] = {"StepOverUnit": MM, "StepOverPercent": 10.0, "UseFinalDepth": False, "FinalDepth": 0.0,
                            "FinishPasses": 1, "StepDown": 0.5, "UseStartPoint": False,
                            "StartPoint": FreeCAD.Vector(0, 0, 0)}


def params_extra(obj: Any, cutter: Cutter) -> dict[str, Any]:
    """Params fields these properties set: the step-over in mm from its % of the tool diameter."""
    if obj.StepOverUnit == PERCENT and obj.StepOverMode == _spacing_name(STEPOVER):
        return {"stepover": stepover_of_percent(float(obj.StepOverPercent), cutter)}
    return {}


def api_values(stepover_percent: Any, final_depth: Any, finish_passes: Any, finish_step_down: Any,
               start_point: Any) -> dict[str, Any]:
    """The op's property values for run_surface's arguments (None: the op's default), each checked by its
    argument's name as the core checks the field: a % step-over (in (0, 100]: the mm step-over is then
    ignored), a final depth, the finishing passes and their step-down, a start point (x, y)."""
    from dataclasses import replace

    from tmm_workbench.core.errors import TmmError
    from tmm_workbench.core.params import check, check_finite, spec_of

    values: dict[str, Any] = {}
    if stepover_percent is not None:
        check(replace(STEPOVER_PERCENT, label="stepover_percent"), stepover_percent)
        values.update(StepOverUnit=PERCENT, StepOverPercent=float(stepover_percent))
    for name, field, value in (("final_depth", "final_depth", final_depth),
                               ("finish_passes", "passes", finish_passes),
                               ("finish_step_down", "step_down", finish_step_down)):
        if value is not None:
            check(replace(spec_of(FinishParams, field), label=name), value)
    if final_depth is not None:
        values.update(UseFinalDepth=True, FinalDepth=float(final_depth))
    if finish_passes is not None:
        values["FinishPasses"] = int(finish_passes)
    if finish_step_down is not None:
        values["StepDown"] = float(finish_step_down)
    if start_point is not None:
        try:
            x, y = (float(c) for c in start_point)
        except (TypeError, ValueError):
            raise TmmError(f"start_point must be two numbers (x, y) in mm, got {start_point!r}") from None
        check_finite("start_point (x, y)", (x, y))
        values.update(UseStartPoint=True, StartPoint=FreeCAD.Vector(x, y, 0.0))
    return values


def finish_params(obj: Any) -> FinishParams:
    start = obj.StartPoint
    return FinishParams(passes=int(obj.FinishPasses), step_down=float(obj.StepDown.Value),
                        final_depth=float(obj.FinalDepth.Value) if obj.UseFinalDepth else None,
                        start_xy=(float(start.x), float(start.y)) if obj.UseStartPoint else None)


def _spacing_name(core: str) -> str:
    return {c: p for p, c in SPACINGS.items()}[core]
