"""What the panel's work estimate costs and how close it is: the strategies' `estimate_work` (what the panel runs
on every value entered, and TmmOp.execute before loading anything) side by side with the computation it
stands for, on the shared STLs.

    .venv/bin/python benchmarks/work_estimate_bench.py --quick    # sphere_on_plate, 3 sample steps (~1 min)
    .venv/bin/python benchmarks/work_estimate_bench.py            # also mount_rush and finer steps

Printed per case: the estimated and the real CL points of the 3-axis raster (ball D6, step-over 1 mm, the
model's bounds), their ratio (>= 1: an upper bound; the estimate covers the boundary's diagonal in every
direction), the seconds of the estimate and of the computation.
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def seconds(run) -> tuple[float, object]:
    t0 = time.perf_counter()
    out = run()
    return time.perf_counter() - t0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    models = ["sphere_on_plate.stl"] + ([] if args.quick else ["mount_rush.stl"])
    steps = [1.0, 0.5, 0.25] + ([] if args.quick else [0.1])
    cutter = Cutter.ball(6.0)
    print(f"{'model':18} {'sample mm':>9} {'estimate':>11} {'real':>11} {'ratio':>6} {'estimate s':>11} "
          f"{'compute s':>10}")
    for name in models:
        mesh = load_stl(benchmark_file("stl", name))
        lo, hi = mesh.bounds
        box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        for step in steps:
            params = SurfaceParams(stepover=1.0, sample_step=step, boundary=box)
            t_est, est = seconds(lambda: raster_drop.count_points(params))
            t_run, res = seconds(lambda: raster_drop.compute(mesh, cutter, replace(params)))
            real = res.diagnostics["points"]
            print(f"{name:18} {step:9g} {est:11.4g} {real:11d} {est / real:6.2f} {t_est:11.2e} {t_run:10.2f}")


if __name__ == "__main__":
    main()
