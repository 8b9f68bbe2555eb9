"""3-axis finishing by the "3D offset" (constant scallop) step-over mode: what raster_drop
does when SurfaceParams.stepover_mode is OFFSET3D.

The passes (core.footprint.offset_field: the level sets of one arrival-time field) follow the machining region
(its polygons, or the boundary box) from its edge inward, or a chosen curve (offset_from) to both sides, spaced by
the cusp height across the local slope; they are put in chains outside in
(offset3d.loop_chains) and handed back as region_order runs, so raster_drop drops, refines (no gouge between
CL points, links included) and cuts them exactly as it does a region's raster: within a chain the tool stays
down over short links inside the region, between chains it lifts. Pattern OneWay: no links (a lift before
every loop); Spiral is another footprint and is refused.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import offset3d, offset_field, region_order
from tmm_workbench.core.footprint.cusp import check_cusp
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.strategies.surface.params import _BYTES_PER_POINT, ONEWAY, SPIRAL
from tmm_workbench.core.tools.cutter import Cutter



def check(params: Any, cutter: Cutter) -> None:
    """The inputs the mode adds, by name, before any work."""
    if params.pattern == SPIRAL:
        raise TmmError("the 3D offset step-over mode makes its own loops from the region's boundary; with it use "
                       "the ZigZag (loops linked) or OneWay (a lift before each loop) pattern, not Spiral")
    check_cusp(cutter, params.cusp)
    for k, curve in enumerate(params.offset_from or [], 1):
        c = np.asarray(curve, dtype=float)
        if c.ndim != 2 or c.shape[1] != 2 or len(c) < 2 or not np.isfinite(c).all():
            raise TmmError(f"3D offset start curve {k}: needs at least two finite XY points, got {c.shape} points")
        if float(np.hypot(*np.diff(c, axis=0).T).sum()) <= 1e-9:
            raise TmmError(f"3D offset start curve {k}: it has no length (seen from above)")


_POINTS_OVER_PLANE = 1.15   # CL points over the plane's length / sample step: on a surface the passes are longer
                            # (1.15-1.5x, loop_length) and keep their contours' vertices (within 0.5 % of the step)


def _perimeter(shape: list) -> float:
    return sum(float(np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T).sum()) for p in shape)


def loop_length(shape: list, cutter: Cutter, params: Any) -> float:
    """The passes' length (mm) on a plane: the region's area over the flat step, and its boundary (pass 0). On a
    surface the steps are smaller where it slopes: measured 1.15x (sphere_on_plate) to 1.5x (mount_rush) this."""
    flat = offset_field.step_rule(cutter, params.cusp, params.max_slope_deg).flat
    return abs(polygons.area(shape)) / flat + _perimeter(shape)


def estimate_work(shape: list, cutter: Cutter, params: Any) -> float:
    """The CL points of the passes (loop_length over the sample step), after refusing above the limits, before
    any height is dropped: the field's grid nodes (each dropped) and the passes at the smallest step (every
    place at the slope limit: an upper bound)."""
    rule = offset_field.step_rule(cutter, params.cusp, params.max_slope_deg)
    least, flat = float(rule.step(np.array([params.max_slope_deg]))[0]), rule.flat
    start = None if params.offset_from is None else [np.asarray(c, dtype=float) for c in params.offset_from]
    nodes = offset_field.node_count(shape, flat, start)
    most = nodes + (abs(polygons.area(shape)) / least + _perimeter(shape)) / params.sample_step
    check_work("CL points", most, _BYTES_PER_POINT,
               f"3D offset: cusp height {params.cusp:g} mm (smallest step {least:.3g} mm at the {params.max_slope_deg:g}"
               f" deg slope limit, {nodes:.3g} field nodes) and sample step {params.sample_step:g} mm over a "
               f"{polygons.area(shape):.6g} mm^2 region")
    return _POINTS_OVER_PLANE * loop_length(shape, cutter, params) / params.sample_step


def chains(mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: Any, floor_z: float, diagnostics: dict,
           progress: Optional[Progress] = None) -> tuple[list[list[region_order.Run]], offset_field.Field]:
    """The runs of each chain of loops, and the arrival field whose level sets they are (the verification pass
    places its extra passes between them by it). diagnostics: "passes" (loops), "jumps", "levels", "stepover" (the flat
    step, mm), "least_step" (mm), "region_area" (mm^2)."""
    from tmm_workbench.core.footprint import region as region_mod
    from tmm_workbench.core.strategies.raster_region import max_link

    check(params, cutter)
    shape = params.region if params.region is not None else region_mod.box_region(params.boundary)
    estimate_work(shape, cutter, params)
    s = params.stock_to_leave
    tool = cutter.offset(s)

    def heights(xy: np.ndarray) -> np.ndarray:
        return np.maximum(surface.drop(tool, xy, floor_z - s) + s, floor_z)

    start = None if params.offset_from is None else [np.asarray(c, dtype=float) for c in params.offset_from]
    loops = offset_field.field_loops(shape, heights, cutter, params.cusp, params.sample_step, params.max_slope_deg,
                                     start, progress)
    ordered = offset3d.loop_chains(loops, shape, max_link(loops.flat_step, cutter), params.pattern != ONEWAY)
    diagnostics.update(passes=len(loops.loops), jumps=len(ordered) - 1, levels=loops.levels,
                       stepover=loops.flat_step, least_step=loops.least_step, region_area=polygons.area(shape))
    return region_order.chain_runs(ordered, params.sample_step), loops.field
