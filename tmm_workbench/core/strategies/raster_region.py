"""3-axis finishing in a machining region, the spiral pattern and the slope range: what
raster_drop does when SurfaceParams has a `region`, the pattern SPIRAL or a slope range.

The region bounds the tool centre (core.footprint.region). The raster's passes (at any angle, spaced by
the step-over mode as in the box) are clipped to it exactly; the spiral (core.footprint.spiral) is clipped
the same way. The pieces are put in chains (core.footprint.region_order): within a chain the tool stays
down over straight links inside the region, dropped on the surface like every CL point; between chains
it jumps (the linker lifts to the safe height). Each chain is cut like today's zig-zag (core.strategies.surface.
segments), so the box with neither region nor spiral gives exactly the path it always gave. The region's and the
slope range's checks are SurfaceParams's (core.strategies.surface.params.validate_region).
"""
from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import region as region_mod
from tmm_workbench.core.footprint import region_order, spiral
from tmm_workbench.core.strategies import slope_filter
from tmm_workbench.core.strategies.surface.params import (  # noqa: F401 - shape_of, spiral_radius: the region's
    INWARD, ONEWAY, SPIRAL, ZIGZAG, shape_of, spiral_radius)
from tmm_workbench.core.tools.cutter import Cutter

Run = region_order.Run
_BARRIER: Run = (True, np.zeros((0, 2)))  # between chains: raster_refine does not check across it


def max_link(stepover: float, cutter: Cutter) -> float:
    """The longest straight link cut with the tool down between two pieces (inside the region): three
    step-overs or the tool's diameter; longer gaps are jumps."""
    return max(3.0 * stepover, 2.0 * cutter.radius)


def chains(lines: list[np.ndarray], cutter: Cutter, params: Any, diagnostics: dict) -> list[list[Run]]:
    """The runs of each chain (see the module doc). diagnostics: "passes" (pieces), "jumps" (lifts between
    chains), "region_area" (mm^2)."""
    shape = shape_of(params)
    stepover = float(diagnostics["stepover"])
    longest = max_link(stepover, cutter)
    if params.pattern == SPIRAL:
        pieces = spiral.spiral_pieces(shape, stepover, params.sample_step, params.spiral_direction == INWARD)
        ordered = region_order.curve_chains(pieces, shape, longest)
        count = len(pieces)
    else:
        a = math.radians(params.angle_deg)
        n = np.array([-math.sin(a), math.cos(a)])
        offsets = np.array([float(ln[0] @ n) for ln in lines])
        per_pass = region_mod.clip_raster(region_mod.region_lines(shape, offsets, params.angle_deg), shape)
        ordered = (region_order.zigzag_chains(per_pass, shape, longest) if params.pattern == ZIGZAG
                   else region_order.oneway_chains(per_pass))
        count = sum(len(p) for p in per_pass)
    if not ordered:
        x0, y0, x1, y1 = polygons.bounds(shape)
        raise TmmError(f"no pass reaches the machining region (x {x0:.6g}..{x1:.6g}, y {y0:.6g}..{y1:.6g}, "
                       f"{polygons.area(shape):.4g} mm^2): it is narrower than the step-over {stepover:g} mm "
                       f"between passes; make the step-over smaller or the region larger")
    diagnostics.update(passes=count, jumps=len(ordered) - 1, region_area=polygons.area(shape))
    return region_order.chain_runs(ordered, params.sample_step)


def flatten(chain_list: list[list[Run]]) -> list[Run]:
    out: list[Run] = []
    for k, ch in enumerate(chain_list):
        if k:
            out.append(_BARRIER)
        out.extend(ch)
    return out


def segments(runs: list[Run], z: np.ndarray, air: np.ndarray, params: Any, chain_list: list[list[Run]],
             cut: Callable[..., list]) -> list:
    """raster_drop's segments, chain by chain (`cut`: core.strategies.surface.segments.segments): each chain starts
    with a jump. `runs` as flattened (raster_refine may have added points; the run count is the same)."""
    pattern = ONEWAY if params.pattern == ONEWAY else ZIGZAG
    out = []
    r, k = 0, 0
    for c, ch in enumerate(chain_list):
        if c:
            r += 1  # the barrier
        part = runs[r:r + len(ch)]
        m = sum(len(xy) for _, xy in part)
        out.extend(cut(part, z[k:k + m], air[k:k + m], pattern, params.chord_tol))
        r, k = r + len(ch), k + m
    return out


def slope_flags(runs: list[Run], z: np.ndarray, air: np.ndarray, drop: Callable, cutter: Cutter, params: Any,
                diagnostics: dict) -> np.ndarray:
    """Air flags with the points outside the slope range added (core.strategies.slope_filter); TmmError when
    no point is left. diagnostics: "slope_filtered" (points left out by the slope)."""
    xy = np.concatenate([r for _, r in runs])
    h = max(1e-3, 0.5 * min(params.sample_step, cutter.radius))
    slope = slope_filter.slopes_deg(xy, drop, h)
    flags = slope_filter.out_of_range(runs, slope, air, params.slope_min_deg, params.slope_max_deg, cutter.radius)
    if flags.all():
        finite = slope[np.isfinite(slope)]
        seen = f"{finite.min():.3g}..{finite.max():.3g} deg" if len(finite) else "none"
        raise TmmError(f"no reachable point: no tool position in the region has a surface slope within the slope "
                       f"range {params.slope_min_deg:g}..{params.slope_max_deg:g} deg (the slopes there: {seen})")
    diagnostics["slope_filtered"] = int(flags.sum() - air.sum())
    return flags
