"""The Surface's work told from its parameters alone (core.work): the raster's CL points at the spacing its mode
can ask for at closest (the cusp rule at the slope limit; the section rule's smallest step is half of it), or the
3D offset's passes; the verification's dense raster or the cusp check's measurement added when they run.

The passes and the cutting length are what the user is told (a time): over the region's area, not its box, and
with a coarse sample of the model's heights (core.query.height_sample, when the caller has the model) at the
spacing the mode will take there (the cusp rule at the region's worst slope across the passes, or at each
place's own for the adaptive raster and the 3D offset) and the length the passes climb."""
from __future__ import annotations

import functools
import math
from dataclasses import replace
from typing import Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError, WorkLimitError
from tmm_workbench.core.footprint import offset_field, region
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.raster import pass_count
from tmm_workbench.core.query.height_sample import HeightSample
from tmm_workbench.core.strategies import raster_offset3d
from tmm_workbench.core.strategies.surface import cusp_check, variable_step
from tmm_workbench.core.strategies.surface.params import (ADAPTIVE, CUSP, OFFSET3D, PENCIL, STEPOVER, SurfaceParams,
                                                           shape_of)
from tmm_workbench.core.strategies.surface.pattern import count_points
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Box, Work

REFERENCE_TOOL_MM = 6.0   # the paces are a 6 mm tool's; a larger one covers more triangles per drop
_CLIMB_BIN, _CLIMB_BINS = 0.25, 16   # the climbs told in slope bins of this tan
_LEAST_BEND = 0.25                    # a convex section widens the step at most 2x
_WORST_PERCENT = 3.0                  # the cusp mode's worst crossing: this percentile of the places' steps


def tool_fit(params: SurfaceParams, cutter: Cutter) -> str:
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


def estimate_work(params: SurfaceParams, cutter: Cutter, bounds: Box, sample: Optional[HeightSample] = None) -> Work:
    """The Surface's work over `params.boundary` and its region (`bounds`: the model's box, unused: the boundary is
    the params'); `sample`: the model's heights over the boundary, for the passes and length told. A step-over
    wider than the tool is refused (TmmError); a cusp spacing with a flat end mill is told in the work's note."""
    params.validate()
    flat_cusp = tool_fit(params, cutter) if params.pattern != PENCIL else ""
    work = _with_loops(_estimate(params, cutter, sample), params, cutter)
    return replace(work, note=f"{work.note} WARNING: {flat_cusp}".strip()) if flat_cusp else work


def _with_loops(work: Work, params: SurfaceParams, cutter: Cutter) -> Work:
    """A rest's `work` with the waterline loops over its slopes (core.strategies.rest_steep.estimate), when its
    rest is known (the op's after it has found it)."""
    if getattr(params, "rest", None) is None or params.pattern == PENCIL:
        return work
    from tmm_workbench.core.strategies import rest_steep

    loops = rest_steep.estimate(params, cutter)
    if loops is None:
        return work
    count, length, levels = loops
    note = f"{work.note} (with the waterline loops over the rest's slopes: {levels} levels, at most)".strip()
    return replace(work.plus(count, "waterline", note), cut_length=float(work.cut_length or 0.0) + length)


def _estimate(params: SurfaceParams, cutter: Cutter, sample: Optional[HeightSample]) -> Work:
    if params.pattern == PENCIL:  # the creases' grid of drops and the curves' points (count_points' bound)
        count = count_points(params)
        x0, y0, x1, y1 = params.boundary
        return Work(count, "CL points", params.pencil_passes, 2 * ((x1 - x0) + (y1 - y0)) * params.pencil_passes,
                    paces=((_pace(params, cutter), count),))
    if params.stepover_mode == OFFSET3D:
        return _told(_checked(_offset3d(params, cutter), params, cutter), params, cutter, sample)
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
    return _told(_checked(work, params, cutter), params, cutter, sample)


def _told(work: Work, params: SurfaceParams, cutter: Cutter, sample: Optional[HeightSample]) -> Work:
    """`work` with the passes and cutting length the op will likely make: over the region's area (the count, an
    upper bound for the limits, stays), and with `sample` at the mode's spacing over the model's slopes."""
    shape = shape_of(params)
    area = polygons.area(shape)
    x0, y0, x1, y1 = params.boundary
    if sample is None:  # the boundary box's length, for the region's share of it
        return replace(work, cut_length=work.cut_length * min(area / max((x1 - x0) * (y1 - y0), 1e-12), 1.0))
    inside = sample.inside(shape)
    if not inside.any():
        return work
    along, across = sample.slopes(params.angle_deg)
    climb = np.sqrt(1.0 + along[inside] ** 2)   # a pass's length over its XY length
    steps = _spacing(params, cutter, sample, inside, along, across)
    length = area / inside.sum() * climb / steps   # each node stands for an equal share of the area
    bins = np.minimum((along[inside] / _CLIMB_BIN).astype(int), _CLIMB_BINS - 1)
    climbs = tuple((float((k + 1) * _CLIMB_BIN), float(v)) for k, v in enumerate(np.bincount(bins, length,
                                                                                              _CLIMB_BINS)) if v > 0)
    a = math.radians(params.angle_deg)
    x0, y0, x1, y1 = polygons.bounds(shape)
    span = (x1 - x0) * abs(math.sin(a)) + (y1 - y0) * abs(math.cos(a))
    return replace(work, cut_length=float(length.sum()), passes=pass_count(span, float(np.median(steps))),
                   climbs=climbs)


def _spacing(params: SurfaceParams, cutter: Cutter, sample: HeightSample, inside: np.ndarray, along: np.ndarray,
             across: np.ndarray) -> np.ndarray:
    """The passes' spacing the mode will take at each node inside the region (the slopes: tan, along and across
    the passes)."""
    if params.stepover_mode == STEPOVER:
        return np.full(int(inside.sum()), params.stepover)
    limit = math.tan(math.radians(params.max_slope_deg))
    # the 3D offset's loops cross the slope at every angle: half-way between along and across, on average
    steep = np.hypot(along, across) / math.sqrt(2.0) if params.stepover_mode == OFFSET3D else across
    table = _step_table(cutter, params.cusp, limit)
    at = np.minimum(np.minimum(steep, limit) / limit * (len(table) - 1), len(table) - 1)
    # a section of the tip surface bent by k across the passes (1 / k its radius, k > 0 concave) changes the
    # cusp by about 1 + R k (the cusp section rule's rho / (rho - R) on a concave section of radius rho, rho /
    # (rho + R) on a convex one): the step by its root
    bend = np.clip(1.0 + cutter.radius * sample.curvature(params.angle_deg), _LEAST_BEND, None)
    every = table[at.round().astype(int)] / np.sqrt(bend)
    if params.stepover_mode == CUSP:  # one spacing, the worst crossing's over the box, down to the rule's floor
        # (the worst but a few nodes: the rule leaves out creases narrower than the tool, which a coarse sample
        # reads as sharp concave sections, and walls; measured: benchmarks/estimate_cycle.py)
        worst = float(np.percentile(every, _WORST_PERCENT))
        return np.full(int(inside.sum()), max(worst, 0.5 * float(table[-1])))
    if params.stepover_mode == ADAPTIVE:  # between each place's step and its pass's worst (measured:
        # benchmarks/estimate_cycle.py; the raster's passes follow the previous ones' tool positions)
        return np.sqrt(_per_pass(sample, inside, params.angle_deg, every[inside]) * every[inside])
    return every[inside]


def _per_pass(sample: HeightSample, inside: np.ndarray, angle_deg: float, steps: np.ndarray) -> np.ndarray:
    """Each place's step replaced by the least along its pass (the sample's nodes binned across the passes)."""
    a = math.radians(angle_deg)
    gx, gy = np.meshgrid(sample.xs, sample.ys)
    across = (-gx * math.sin(a) + gy * math.cos(a))[inside]
    rows = np.floor((across - across.min()) / max(sample.step, 1e-9)).astype(int)
    least = np.full(rows.max() + 1, np.inf)
    np.minimum.at(least, rows, steps)
    return least[rows]


def _cusp_step(cutter: Cutter, cusp: float, slope_tan: float) -> float:
    return stepover_for_cusp(cutter, cusp, math.degrees(math.atan(slope_tan)))


def _step_table(cutter: Cutter, cusp: float, limit_tan: float) -> np.ndarray:
    """The cusp's planar step-over at slopes 0 .. the limit (tan), evenly spaced rows: a ball's in closed form
    (the chord 2 sqrt(2 R h - h^2) along the slope), another cutter's by the planar rule (core.footprint.cusp:
    a third of a second a row, so fewer rows, kept for the panel's next value)."""
    if cutter.corner_radius >= cutter.radius:
        r = cutter.radius
        chord = 2.0 * math.sqrt(max(2.0 * r * cusp - cusp * cusp, 0.0))
        return chord * np.cos(np.arctan(np.linspace(0.0, limit_tan, 64)))
    return np.array(_rule_rows(cutter, cusp, limit_tan))


@functools.lru_cache(maxsize=8)
def _rule_rows(cutter: Cutter, cusp: float, limit_tan: float) -> tuple:   # a Cutter is equal by its values
    return tuple(_cusp_step(cutter, cusp, t) for t in np.linspace(0.0, limit_tan, 8))


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
