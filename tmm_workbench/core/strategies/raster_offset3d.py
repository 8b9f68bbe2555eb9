"""3-axis finishing by the "3D offset" (constant scallop) step-over mode (issue 14 item 1): what raster_drop
does when SurfaceParams.stepover_mode is OFFSET3D.

The loops (core.footprint.offset3d) follow the machining region (its polygons, or the boundary box) from its
edge inward, spaced by the cusp height across the local slope; they are put in chains outside in
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
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.tools.cutter import Cutter

_DROPS_PER_POINT = 4  # a loop point is dropped once, and three times for the slope across it


def check(params: Any, cutter: Cutter) -> None:
    """The inputs the mode adds, by name, before any work."""
    from tmm_workbench.core.strategies.raster_drop import SPIRAL

    if params.pattern == SPIRAL:
        raise TmmError("the 3D offset step-over mode makes its own loops from the region's boundary; with it use "
                       "the ZigZag (loops linked) or OneWay (a lift before each loop) pattern, not Spiral")
    if not 0 < params.cusp <= cutter.radius:
        raise TmmError(f"cusp height must be in (0, {cutter.radius:g}] mm (the tool radius), got {params.cusp:g}")


def estimate_work(shape: list, cutter: Cutter, params: Any) -> float:
    """CL points dropped (loops at the smallest step, their slope probes), refused above the limits before any
    loop is made: the loops' total length is about the region's area over the step, plus its boundary."""
    from tmm_workbench.core.strategies.raster_drop import _BYTES_PER_POINT

    least = offset3d.least_step(cutter, params.cusp, params.max_slope_deg)
    perimeter = sum(float(np.hypot(*np.diff(np.vstack([p, p[:1]]), axis=0).T).sum()) for p in shape)
    length = abs(polygons.area(shape)) / least + 2 * perimeter
    count = _DROPS_PER_POINT * (length / params.sample_step + 1)
    check_work("CL points", count, _BYTES_PER_POINT,
               f"3D offset: cusp height {params.cusp:g} mm (smallest step {least:.3g} mm at the {params.max_slope_deg:g}"
               f" deg slope limit) and sample step {params.sample_step:g} mm over a {polygons.area(shape):.6g} mm^2 "
               f"region")
    return count


def chains(mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: Any, floor_z: float, diagnostics: dict,
           progress: Optional[Progress] = None) -> list[list[region_order.Run]]:
    """The runs of each chain of loops. diagnostics: "passes" (loops), "jumps", "levels", "stepover" (the flat
    step, mm), "least_step" (mm), "region_area" (mm^2)."""
    from tmm_workbench.core.footprint import region as region_mod
    from tmm_workbench.core.strategies.raster_drop import ONEWAY
    from tmm_workbench.core.strategies.raster_region import max_link

    check(params, cutter)
    shape = params.region if params.region is not None else region_mod.box_region(params.boundary)
    estimate_work(shape, cutter, params)
    s = params.stock_to_leave
    tool = cutter.offset(s)

    def heights(xy: np.ndarray) -> np.ndarray:
        return np.maximum(surface.drop(tool, xy, floor_z - s) + s, floor_z)

    loops = offset_field.field_loops(shape, heights, cutter, params.cusp, params.sample_step, params.max_slope_deg,
                                     params.offset_from, progress)
    ordered = offset3d.loop_chains(loops, shape, max_link(loops.flat_step, cutter), params.pattern != ONEWAY)
    diagnostics.update(passes=len(loops.loops), jumps=len(ordered) - 1, levels=loops.levels,
                       stepover=loops.flat_step, least_step=loops.least_step, region_area=polygons.area(shape))
    return region_order.chain_runs(ordered, params.sample_step)
