"""Rest machining against a full finish with the small tool (issue target: the rest path with a ball D3 after a
ball D10 finish at most 25 % of the length and of the time of a full D3 finish that leaves the same).

For each model: a D10 raster finish (cusp 0.01 mm), simulated on the stock's top (cells 0.25 mm); a D3 rest path
(core.footprint.rest's region and core.strategies.rest_filter, raster or 3D offset, cusp 0.008 mm between passes;
waterline loops over the sloped cells they leave above the tolerance: core.strategies.rest_steep)
and a full D3 raster with the same step-over, both simulated from what the D10 left; printed side by side: feed
length, cycle time (feed 1000 mm/min, plunge 300, rapid 5000), and what each leaves where the D3 reaches the model
(cells above 0.01 mm, the largest), the plunges (entries), with the ratios.

Run: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/rest_bench.py [model.stl ...] [--offset3d]
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core import polygons  # noqa: E402
from tmm_workbench.core.footprint import rest  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.surface.params import SurfaceParams  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CELL, TOL = 0.25, 0.01
FEED, PLUNGE, RAPID = 1000 / 60, 300 / 60, 5000 / 60


def step_for(cutter: Cutter, cusp: float) -> float:
    return 2 * math.sqrt(2 * cutter.radius * cusp)


def cycle(tp) -> tuple[float, float]:
    t = three_axis_time(tp.points(), toolpath_feeds(tp, FEED, PLUNGE), RAPID, RAPID)
    return t.cutting_length, t.seconds


def left_where_reached(after: np.ndarray, design: np.ndarray, reach: np.ndarray) -> tuple[int, float]:
    d = np.where(reach, after - design, np.nan)
    return int(np.sum(d > TOL)), float(np.nanmax(d))


def run(path: Path, offset3d: bool) -> None:
    mesh = load_stl(path)
    lo, hi = mesh.bounds
    box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    grid = Grid.covering(*box, CELL)
    design = mesh_heights(mesh, grid)
    stock = box_heights(grid, float(hi[2]))
    policy = LinkPolicy(safe_height=float(hi[2]) + 2, clearance_height=float(hi[2]) + 5)
    d10, d3 = Cutter.ball(10), Cutter.ball(3)
    t0 = time.perf_counter()
    finish = raster_drop.compute_surface_toolpath(mesh, d10, SurfaceParams(boundary=box, stepover=step_for(d10, TOL),
                                                                           sample_step=0.25), policy)
    left = simulate(finish, d10, grid, stock).heights
    t_finish = time.perf_counter() - t0
    t0 = time.perf_counter()
    envelope = rest.tool_envelope(mesh, d3, grid)
    area = rest.rest_area(left, design, envelope, grid, TOL, d3.radius)
    step = step_for(d3, 0.8 * TOL)
    mode = dict(stepover_mode="offset3d", cusp=0.8 * TOL) if offset3d else dict(stepover=step)
    params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, sample_step=0.25,
                           rest=area.stock(left), verify_notes=[], **mode)
    rest_policy = LinkPolicy(policy.safe_height, policy.clearance_height, material_top=StockHeights(grid, left, d3),
                             low_links=True)
    result = raster_drop.compute(mesh, d3, params)
    rest_path = link(result.segments, rest_policy)
    t_rest = time.perf_counter() - t0
    t0 = time.perf_counter()
    full = raster_drop.compute_surface_toolpath(mesh, d3, SurfaceParams(boundary=box, stepover=step, sample_step=0.25),
                                                LinkPolicy(policy.safe_height, policy.clearance_height,
                                                           material_top=StockHeights(grid, left, d3)))
    t_full = time.perf_counter() - t0
    reach = np.isfinite(design) & (envelope - design <= TOL)
    rows = []
    for name, tp in (("rest D3", rest_path), ("full D3", full)):
        sim = simulate(tp, d3, grid, left)
        after = sim.heights
        length, seconds = cycle(tp)
        above, worst = left_where_reached(after, design, reach)
        plunges = sum(m.kind is MoveKind.PLUNGE for m in tp.moves)
        rows.append((name, length, seconds, above, worst, float(np.nanmin(after - design)), len(sim.collisions),
                     plunges))
    print(f"\n{path.name}: {area.summary()}; D10 finish {t_finish:.1f} s, rest {t_rest:.1f} s, full D3 {t_full:.1f} s "
          f"to compute ({'offset3d' if offset3d else 'raster'} rest)")
    steep = result.diagnostics.get("steep")
    if steep:
        print(f"the sloped rest the passes leave above {TOL} mm: {steep['cells']} cells, waterline loops in "
              f"{steep['groups']} group(s), {steep['levels']} levels, {steep['segments']} pieces")
    print(f"pieces of passes and loops reached by a join with the tool down: {result.diagnostics.get('joins', 0)}")
    for note in params.verify_notes:   # what the op reports (a z-map of the rest cells cut by the pieces)
        print(f"op's report: {note.summary()}")
    print(f"{'path':10s} {'feed mm':>10s} {'cycle s':>9s} {'cells > tol':>12s} {'max left':>9s} {'min dev':>9s} "
          f"{'rapids in stock':>16s} {'plunges':>8s}")
    for name, length, seconds, above, worst, low, rapids, plunges in rows:
        print(f"{name:10s} {length:10.0f} {seconds:9.0f} {above:12d} {worst:9.4f} {low:9.4f} {rapids:16d} "
              f"{plunges:8d}")
    (_, lr, sr, *_), (_, lf, sf, *_) = rows
    print(f"{'ratio':10s} {lr / lf:10.2f} {sr / sf:9.2f}   (target <= 0.25 both, leaving the same)")
    # a path that leaves the full finish's cusp over the rest cells passes over them at most `step` apart: its
    # XY length is at least their area over the step, against the full finish's XY length
    xy = float(np.linalg.norm(np.diff(full.points()[:, :2], axis=0), axis=1).sum())
    print(f"lower bound of the length ratio: rest area {area.area:.0f} mm2 / step {step:.3f} mm = "
          f"{area.area / step:.0f} mm against the full finish's {xy:.0f} mm in XY: {area.area / step / xy:.2f}")


def main() -> None:
    offset3d = "--offset3d" in sys.argv
    names = [a for a in sys.argv[1:] if not a.startswith("--")] or ["mount_rush.stl", "sphere_on_plate.stl"]
    for name in names:
        path = Path(name) if Path(name).is_file() else benchmark_file("stl", name)
        run(path, offset3d)


if __name__ == "__main__":
    main()
