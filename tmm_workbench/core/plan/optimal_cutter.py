"""The optimal cutter (seed 003, section 4.2): the same finishing raster (step-over, sampling, direction) with
each candidate cutter, each simulated in the same stock and compared with the model; the scallops (material
left) overall and per slope band of the design (seed 003's finding is angle-dependent: radiused cutters
leave less on gentle slopes, ball cutters on steep ones), the volume left and removed, and the cycle time;
ranked with the reason, and a map of which cutter leaves the least in each cell (seed 003, Figure 4.10's
"best scallop height").

Deviations are vertical (core.sim.compare); the slope bands use the design's slope from its heights. A plan above
the strategies: it runs the raster strategy for each candidate and measures what each leaves in the simulation."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.compare import compare, slope_deg
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath
from tmm_workbench.core.tools.cutter import Cutter

SLOPE_BANDS = ((0.0, 20.0), (20.0, 40.0), (40.0, 60.0), (60.0, 90.0))  # degrees from the horizontal
TIE_MM = 1e-4


@dataclass
class CutterScore:
    label: str
    cutter: Cutter
    cycle_seconds: float
    max_left: float             # mm
    mean_left: float            # mm, over the design cells
    std_left: float
    p95_left: float
    remaining_volume: float     # mm^3 above the design
    removed_volume: float
    gouge: float                # mm, the deepest cut below the design (0: none)
    by_slope: dict = field(default_factory=dict)   # (lo, hi) deg -> mean left, mm (NaN: no cell there)


@dataclass
class CutterComparison:
    scores: list                # CutterScore, ranked best first
    reasons: list               # one sentence per rank
    best_cell: np.ndarray       # (ny, nx) index into `labels` of the cutter leaving the least (the first of
    #                             those tied); -1: no design
    labels: list                # candidate labels in the order given
    grid: Grid


def compare_cutters(mesh: TriMesh, candidates: Sequence[tuple[str, Cutter]], *, stepover: float,
                    sample_step: float, cell: float = 0.1, tolerance: float = 0.01, angle_deg: float = 0.0,
                    boundary: Optional[tuple[float, float, float, float]] = None, horiz_feed: float = 1000 / 60,
                    vert_feed: float = 300 / 60, margin: float = 0.0,
                    rapid: Optional[tuple[float, float]] = None) -> CutterComparison:
    """Each candidate finishes `mesh` with the same raster (core.strategies.raster_drop) and is simulated in a
    box stock 1 mm above the model over `boundary` (default: the model's XY box shrunk by `margin`).
    Ranked by: no gouge first, then the volume left above the design, then the cycle time (feeds and `rapid`,
    the machine's rapid rates in XY and Z, in mm/s; None: the cycle estimate's default)."""
    if not candidates:
        raise TmmError("no candidate cutters to compare")
    lo, hi = mesh.bounds
    x0, y0, x1, y1 = boundary or (lo[0] + margin, lo[1] + margin, hi[0] - margin, hi[1] - margin)
    grid = Grid.covering(x0, y0, x1, y1, cell)
    surface = DropSurface(mesh)
    design = mesh_heights(mesh, grid, surface)
    slope = slope_deg(design, cell)
    stock = box_heights(grid, float(hi[2]) + 1.0)
    policy = LinkPolicy(float(hi[2]) + 5.0, float(hi[2]) + 10.0)
    params = SurfaceParams(boundary=(x0, y0, x1, y1), stepover=stepover, sample_step=sample_step,
                           angle_deg=angle_deg)
    scores, deviations = [], []
    for label, cutter in candidates:
        tp = compute_surface_toolpath(mesh, cutter, params, policy, surface=surface)
        res = simulate(tp, cutter, grid, stock)
        cmp = compare(res, design, tolerance)
        d = cmp.deviation
        left = d[np.isfinite(d)]
        by_slope = {}
        for band in SLOPE_BANDS:
            sel = np.isfinite(d) & (slope >= band[0]) & (slope < band[1])
            by_slope[band] = float(np.mean(np.clip(d[sel], 0, None))) if sel.any() else math.nan
        seconds = three_axis_time(tp.points(), toolpath_feeds(tp, horiz_feed, vert_feed), *(rapid or ())).seconds
        scores.append(CutterScore(label, cutter, seconds, cmp.overall.max_left, float(np.mean(np.clip(left, 0, None))),
                                  float(np.std(left)), cmp.overall.percentiles[95], cmp.overall.remaining_volume,
                                  cmp.removed_volume, max(0.0, -cmp.overall.min_deviation), by_slope))
        deviations.append(np.where(np.isfinite(d), np.abs(d), np.inf))
    stack = np.stack(deviations)
    best_cell = np.where(np.isfinite(design), np.argmin(stack, axis=0), -1)
    labels = [label for label, _ in candidates]
    ranked = sorted(scores, key=lambda s: (s.gouge > tolerance, s.remaining_volume, s.cycle_seconds))
    reasons = []
    least = stack.min(axis=0)
    on_design = np.isfinite(design)
    for k, s in enumerate(ranked):
        # ties are common (every cutter leaves 0 on a flat): "the least" is within TIE_MM of the best
        mine = stack[labels.index(s.label)]
        share = float(np.mean((mine <= least + TIE_MM)[on_design])) * 100
        text = (f"{k + 1}. {s.label}: {s.remaining_volume / 1000:.3f} cm3 left above the design, max scallop "
                f"{s.max_left:.4f} mm (mean {s.mean_left:.4f}), {s.cycle_seconds / 60:.1f} min; leaves the least "
                f"(within {TIE_MM * 1000:g} um) in {share:.0f} % of the surface")
        if s.gouge > tolerance:
            text += f"; GOUGES {s.gouge:.4f} mm (ranked last)"
        reasons.append(text)
    return CutterComparison(ranked, reasons, best_cell, labels, grid)
