"""Seed 000's clean-up case (section 5.6) of our own (tests/core/crease_case.py: a floor meeting a 75 deg wall in a
sharp concave crease, and a V groove 3 mm wide): finished with a ball D10 (raster, cusp 0.01 mm), then cleaned up
with a ball D2 in Region Rest, PencilPasses 0 (passes around the curves covering the strip), three ways:

  creases      the pencil's creases (the D2's CL valleys found on a grid of half the sample step, dropped);
  strips       seed 000's strips (the D10's normal jumps, eq. 3.125, with the derived threshold, joined with the
               rest cells) thinned into curves, dropped vertically where the thinning put them;
  clean-up     the same strips, each point slid across to its crease by the kernel's drop along a vector
               (eq. 3.126-3.188), then dropped (Pattern Pencil, PencilSource CleanUp).

Simulated on 0.1 mm cells from what the D10 left; printed: feed length, cycle time (feed 1000 mm/min, plunge 300,
rapid 5000), cells more than 0.01 mm above the design where the D2 reaches (its envelope within 0.01 mm of the
design), the largest left there, the lowest deviation (a gouge below -0.005 mm fails), and where the wall's pass
runs against the exact two-contact x of the D2 ball.

Run: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/cleanup_crease.py
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy import ndimage

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.rest_bench import cycle, step_for  # noqa: E402
from tests.core.crease_case import HEIGHT, WALL_H, WIDTH, crease_mesh, fold_x  # noqa: E402
from tmm_workbench.core import polygons  # noqa: E402
from tmm_workbench.core.footprint import cleanup, pencil, rest  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.surface.params import SurfaceParams  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CELL, TOL, GOUGE = 0.1, 0.01, -0.005
BOX = (0.0, 0.0, WIDTH, HEIGHT)
FINISH, SMALL = Cutter.ball(10), Cutter.ball(2)


def main() -> None:
    mesh = crease_mesh()
    grid = Grid.covering(*BOX, CELL)
    design = mesh_heights(mesh, grid)
    top = WALL_H + 1.0
    policy = LinkPolicy(top + 2, top + 5)
    finish = raster_drop.compute_surface_toolpath(
        mesh, FINISH, SurfaceParams(boundary=BOX, stepover=step_for(FINISH, TOL), sample_step=0.25), policy)
    left = simulate(finish, FINISH, grid, box_heights(grid, top)).heights
    envelope = rest.tool_envelope(mesh, SMALL, grid)
    area = rest.rest_area(left, design, envelope, grid, TOL, SMALL.radius)
    reach = np.isfinite(design) & (envelope - design <= TOL)
    t0 = time.perf_counter()
    found = cleanup.strips(mesh, DropSurface(mesh), FINISH, grid, design, area.mask, TOL, SMALL.diameter)
    t_strips = time.perf_counter() - t0
    step = step_for(SMALL, 0.8 * TOL)
    base = dict(boundary=polygons.bounds(area.region), region=area.region, sample_step=0.2, rest=area.stock(left),
                pattern="pencil", pencil_passes=0, stepover=step, cusp=TOL)
    # the same strips and flank passes without the slide: the curves where the thinning put them
    unslid = pencil.sampled(found.curves, 0.1)
    near = ndimage.binary_dilation(found.mask, iterations=2)
    unslid += cleanup.flank_passes(DropSurface(mesh), SMALL, unslid, -5.0, step, 50, (grid, near))
    ways = {"creases": dict(pencil_source="creases"),
            "strips, no slide": dict(pencil_source="file", pencil_curves=unslid, pencil_passes=1),
            "clean-up": dict(pencil_source="cleanup", cleanup_reference=FINISH)}
    rest_policy = LinkPolicy(policy.safe_height, policy.clearance_height, material_top=StockHeights(grid, left, SMALL),
                             low_links=True)
    print(f"crease_groove: {area.summary()}; {found.summary()} ({t_strips:.1f} s); normal jump limit "
          f"{math.degrees(found.limit):.2f} deg for D10 and {TOL} mm")
    print(f"{'path':22s} {'feed mm':>8s} {'cycle s':>8s} {'cells > tol':>11s} {'max left':>9s} {'min dev':>8s} "
          f"{'wall pass x':>11s} {'compute s':>9s}")
    before = np.where(reach, left - design, np.nan)
    print(f"{'D10 finish':22s} {cycle(finish)[0]:8.0f} {cycle(finish)[1]:8.0f} {int(np.sum(before > TOL)):11d} "
          f"{np.nanmax(before):9.4f} {np.nanmin(left - design):8.4f}")
    exact = fold_x(SMALL.radius)
    for name, extra in ways.items():
        params = SurfaceParams(**{**base, **extra})
        t0 = time.perf_counter()
        tp = link(raster_drop.compute(mesh, SMALL, params).segments, rest_policy)
        seconds = time.perf_counter() - t0
        after = simulate(tp, SMALL, grid, left).heights
        d = np.where(reach, after - design, np.nan)
        length, cyc = cycle(tp)
        pts = tp.points()
        on_floor = pts[(np.abs(pts[:, 0] - exact) < 1.5) & (np.abs(pts[:, 2]) < 0.05) & (pts[:, 1] > 5)
                       & (pts[:, 1] < HEIGHT - 5)]   # along the wall, away from the mesh's ends
        wall_x = f"{on_floor[:, 0].max() - exact:+11.4f}" if len(on_floor) else f"{'-':>11s}"
        print(f"{name + ' D2':22s} {length:8.0f} {cyc:8.0f} {int(np.sum(d > TOL)):11d} {np.nanmax(d):9.4f} "
              f"{np.nanmin(after - design):8.4f} {wall_x} {seconds:9.1f}")
    full = raster_drop.compute_surface_toolpath(mesh, SMALL, SurfaceParams(boundary=BOX, stepover=step,
                                                                           sample_step=0.2), policy)
    after = simulate(full, SMALL, grid, left).heights
    d = np.where(reach, after - design, np.nan)
    print(f"{'full D2 raster':22s} {cycle(full)[0]:8.0f} {cycle(full)[1]:8.0f} {int(np.sum(d > TOL)):11d} "
          f"{np.nanmax(d):9.4f} {np.nanmin(after - design):8.4f}")
    print(f"wall pass x: the floor pass nearest the wall, minus the D2's exact two-contact x {exact:.4f} "
          f"(negative: short of the wall)")


if __name__ == "__main__":
    main()
