"""The 3-axis Surface op's properties for what FreeCAD's 3D Surface users expect: the
step-over in % of the tool diameter, a Depths group (final depth, finishing passes over a semi-finish stock
to leave, their step-down) and a start point; the core is core.strategies.finish_passes.

Their defaults (mm step-over, no final depth, one pass, no start point) give the op's tool path from before
they existed, so documents saved before them restore and compute unchanged (op_base.ensure_properties).
"""
from __future__ import annotations

from typing import Any

import FreeCAD

from dataclasses import replace

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, check, check_finite, spec_of
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.strategies.finish_passes import STEPOVER_PERCENT, FinishParams, stepover_of_percent
from tmm_workbench.core.strategies.surface.params import STEPOVER
from tmm_workbench.core.strategies.surface.pattern import SPACINGS
from tmm_workbench.core.tools.cutter import Cutter

MM, PERCENT = "mm", "%"

_FIELDS = (
    Field("StepOverUnit", "choice", "Surface",
          "mm: passes StepOver apart; %: StepOverPercent of the tool diameter apart (StepOver spacing)",
          choices={MM: MM, PERCENT: PERCENT}, default=MM, widget="stepOverUnit"),
    Field("StepOverPercent", "percent", "Surface",
          "Distance between raster passes in % of the tool diameter, when StepOverUnit is %", default=10.0,
          spec=STEPOVER_PERCENT),
    Field("UseFinalDepth", "bool", "Depths", "No tool tip below FinalDepth (off: the model's lowest point)",
          default=False, widget="useFinalDepth"),
    Field("FinalDepth", "length", "Depths", "Lowest tool tip height, when UseFinalDepth is set", default=0.0,
          spec=Spec("final depth", "mm", low=-10_000.0, high=10_000.0), widget="finalDepth"),
    Field("FinishPasses", "int", "Depths",
          "Passes over the surface: the first ones leave StockToLeave + k x StepDown (semi-finish), the last "
          "StockToLeave", default=1),
    Field("StepDown", "length", "Depths", "Stock each finishing pass removes over the next one (FinishPasses > 1)",
          default=0.5, spec=Spec("finishing step-down", "mm", low=0.0, high=1000.0, low_open=True),
          widget="stepDown"),
    Field("UseStartPoint", "bool", "Start Point", "Each pass set begins at the end of the raster nearest StartPoint "
          "(X, Y)", default=False, widget="useStartPoint"),
    Field("StartPoint", "vector", "Start Point", "Where the cutting starts (X and Y are used)",
          default=FreeCAD.Vector(0, 0, 0)),
)


def params_extra(obj: Any, cutter: Cutter) -> dict[str, Any]:
    """Params fields these properties set: the step-over in mm from its % of the tool diameter."""
    if obj.StepOverUnit == PERCENT and obj.StepOverMode == _spacing_name(STEPOVER):
        return {"stepover": stepover_of_percent(float(obj.StepOverPercent), cutter)}
    return {}


def api_values(args: Args, model: Any = None) -> dict[str, Any]:
    """The op's property values for run_surface's arguments (None: the op's default), each checked by its
    argument's name as the core checks the field: a % step-over (in (0, 100]: the mm step-over is then
    ignored), a final depth, the finishing passes and their step-down, a start point (x, y)."""
    stepover_percent, final_depth, finish_passes, finish_step_down, start_point = (
        args.get(name) for name in COMPOSITE)
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


COMPOSITE = ("stepover_percent", "final_depth", "finish_passes", "finish_step_down", "start_point")
STAGE = Stage("depths", _FIELDS, composite=COMPOSITE, composite_values=api_values)


def finish_params(obj: Any) -> FinishParams:
    start = obj.StartPoint
    return FinishParams(passes=int(obj.FinishPasses), step_down=float(obj.StepDown.Value),
                        final_depth=float(obj.FinalDepth.Value) if obj.UseFinalDepth else None,
                        start_xy=(float(start.x), float(start.y)) if obj.UseStartPoint else None)


def _spacing_name(core: str) -> str:
    return {c: p for p, c in SPACINGS.items()}[core]
