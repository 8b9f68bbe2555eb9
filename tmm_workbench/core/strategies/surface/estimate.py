"""The Surface's work told from its parameters alone (core.work): the raster's CL points at the spacing its mode
can ask for at closest (the cusp rule at the slope limit; the section rule's smallest step is half of it), or the
3D offset's passes; the verification's dense raster or the cusp check's measurement added when they run."""
from __future__ import annotations

import math
from dataclasses import replace

from tmm_workbench.core.errors import WorkLimitError
from tmm_workbench.core.footprint import offset_field, region
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.raster import pass_count
from tmm_workbench.core.strategies import raster_offset3d
from tmm_workbench.core.strategies.surface import cusp_check, variable_step
from tmm_workbench.core.strategies.surface.params import ADAPTIVE, CUSP, OFFSET3D, PENCIL, STEPOVER, SurfaceParams
from tmm_workbench.core.strategies.surface.pattern import count_points
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Box, Work

REFERENCE_TOOL_MM = 6.0   # the paces are a 6 mm tool's; a larger one covers more triangles per drop


def estimate_work(params: SurfaceParams, cutter: Cutter, bounds: Box) -> Work:
    """The Surface's work over `params.boundary` (`bounds`: the model's box, unused: the boundary is the
    params')."""
    params.validate()
    if params.pattern == PENCIL:  # the creases' grid of drops and the curves' points (count_points' bound)
        count = count_points(params)
        x0, y0, x1, y1 = params.boundary
        return Work(count, "CL points", params.pencil_passes, 2 * ((x1 - x0) + (y1 - y0)) * params.pencil_passes,
                    paces=((_pace(params, cutter), count),))
    if params.stepover_mode == OFFSET3D:
        return _checked(_offset3d(params, cutter), params, cutter)
    stepover = params.stepover
    if params.stepover_mode != STEPOVER:  # the closest spacing the cusp can ask for
        stepover = stepover_for_cusp(cutter, params.cusp, params.max_slope_deg)
        if params.stepover_mode == CUSP:  # the section rule's smallest step (core.footprint.cusp_section)
            stepover *= 0.5
    count = count_points(replace(params, stepover=stepover))
    x0, y0, x1, y1 = params.boundary
    w, h = x1 - x0, y1 - y0
    scale = max(1.0, (cutter.diameter / REFERENCE_TOOL_MM) ** 2)
    # passes cover the boundary at the step-over: their length is its area over the spacing
    work = Work(count, "CL points", pass_count(math.hypot(w, h), stepover), w * h / stepover,
                paces=((_pace(params, cutter), count * scale),))
    return _checked(work, params, cutter)


def _pace(params: SurfaceParams, cutter: Cutter) -> str:
    """A flat or bull-nose cutter's cusp spacing costs more per point than a ball's."""
    if params.stepover_mode == ADAPTIVE:
        return "adaptive"
    ball = cutter.corner_radius >= cutter.radius
    return "surface" if ball or params.stepover_mode == STEPOVER else "surface_flat_cusp"


def _checked(work: Work, params: SurfaceParams, cutter: Cutter) -> Work:
    """With VerifyCusp: the verification's dense raster added (known before it runs; its partial passes are not);
    with the cusp check: its measurement, at most."""
    if not params.verify_cusp:
        if not cusp_check.applies(params):
            return work
        try:
            dense = cusp_check.cost_points(params.boundary, cutter, params.cusp, cusp_check.check_cell(params, cutter))
        except WorkLimitError:
            return replace(work, note="(the cusp check is skipped: its measurement is above the work limit)")
        return work.plus(dense, "verify", "(with the cusp check's dense raster, at most)")
    dense = variable_step.estimate_params(cutter, params)
    return work.plus(dense, "verify", f"(with the verification's dense raster; + up to {variable_step.ROUNDS} rounds "
                                      "of partial passes where the simulated cusp is over, not counted)")


def _offset3d(params: SurfaceParams, cutter: Cutter) -> Work:
    """The 3D offset's passes over the boundary box: their points and length on a plane (the region's area over
    the flat step and its boundary: raster_offset3d.loop_length), the loops from the box's edge to its middle."""
    shape = region.box_region(params.boundary)
    count = raster_offset3d.estimate_work(shape, cutter, params)
    length = raster_offset3d.loop_length(shape, cutter, params)
    x0, y0, x1, y1 = params.boundary
    flat = offset_field.step_rule(cutter, params.cusp, params.max_slope_deg).flat
    return Work(count, "CL points", math.ceil(0.5 * min(x1 - x0, y1 - y0) / flat) + 1, length,
                paces=(("offset3d", count),))
