"""What the 3-axis Surface op's depths, passes and start point cost (core.strategies.finish_passes) against the
plain raster (raster_drop.compute_surface_toolpath) on the shared sphere_on_plate.stl, ball D6, and what the
finishing passes leave (simulated stock, 0.25 mm cells, minus the model: the finish's stock must be the single
pass's).

    .venv/bin/python benchmarks/finish_passes_bench.py            # step-over 1 mm, sample step 0.5 mm
    .venv/bin/python benchmarks/finish_passes_bench.py --quick    # step-over 2 mm, sample step 1 mm

Columns: case, moves, seconds (best of 2), ratio to the plain raster, the first cutting point, the simulated
deviation from the model: min (the stock left where it is thinnest) and median.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies.finish_passes import FinishParams, compute_finish_toolpath  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def best_of(f, n: int = 2):
    best, out = float("inf"), None
    for _ in range(n):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    mesh = load_stl(str(benchmark_file("stl", "sphere_on_plate.stl")))
    lo, hi = mesh.bounds
    box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    ball = Cutter.ball(6)
    step, sample = (2.0, 1.0) if args.quick else (1.0, 0.5)
    params = SurfaceParams(boundary=box, stepover=step, sample_step=sample, stock_to_leave=0.2)
    policy = LinkPolicy(safe_height=float(hi[2]) + 5, clearance_height=float(hi[2]) + 10)
    surface = DropSurface(mesh)
    grid = Grid.covering(*box, 0.25)
    design = mesh_heights(mesh, grid, surface)
    far = (box[2], box[1])  # a corner the zig-zag reaches only when turned by 180 degrees (even pass count)
    cases = [
        ("plain raster", lambda: compute_surface_toolpath(mesh, ball, params, policy, surface=surface)),
        ("finish_passes defaults", lambda: compute_finish_toolpath(mesh, ball, params, FinishParams(), policy,
                                                                   surface=surface)),
        ("start point (far corner)", lambda: compute_finish_toolpath(mesh, ball, params,
                                                                     FinishParams(start_xy=far), policy,
                                                                     surface=surface)),
        ("3 passes, step-down 0.5", lambda: compute_finish_toolpath(mesh, ball, params,
                                                                    FinishParams(passes=3, step_down=0.5),
                                                                    policy, surface=surface)),
    ]
    print(f"sphere_on_plate.stl, ball D6, step-over {step:g} mm, sample step {sample:g} mm, stock to leave 0.2 mm")
    print(f"{'case':28s} {'moves':>7s} {'s':>7s} {'ratio':>6s} {'first cut (x, y)':>18s} {'min dev':>8s} "
          f"{'median':>7s}")
    base = None
    for name, run in cases:
        seconds, path = best_of(run)
        base = base or seconds
        first = path.cutting_points()[0]
        cut = simulate(path, ball, grid, box_heights(grid, float(hi[2]) + 1)).heights
        dev = (cut - design)[np.isfinite(design)]
        print(f"{name:28s} {len(path):7d} {seconds:7.3f} {seconds / base:6.2f} "
              f"{f'({first[0]:.1f}, {first[1]:.1f})':>18s} {dev.min():8.4f} {np.median(dev):7.4f}")


if __name__ == "__main__":
    main()
