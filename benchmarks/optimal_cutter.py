"""Seed 003's optimal-cutter comparison (section 4.2) on a surface of our own making (the seed's signs are
not available): a 100 x 60 mm plate with a flat background, a spherical dome (slopes 0-50 deg) and a 40 deg
chamfered ridge, finished by the same raster (0.79375 mm = 1/32 inch step-over as the seed's Table 4.2,
0.4 mm sampling) with a ball, a flat and two radiused end mills of the same diameter (the seed compares
cutters of the same radius), each simulated (core.sim) and compared with the design.

    .venv/bin/python benchmarks/optimal_cutter.py
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import TriMesh  # noqa: E402
from tmm_workbench.core.plan.optimal_cutter import SLOPE_BANDS, compare_cutters  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

D = 6.0


def sign_surface(n: int = 400) -> TriMesh:
    """Flat background z = 0; a spherical cap (radius 30, 8 mm high) at (35, 30); a ridge with 40 deg flanks
    along y at x = 78, 8 mm high with a 4 mm wide flat top."""
    xs, ys = np.linspace(0, 100, n + 1), np.linspace(0, 60, int(n * 0.6) + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    R, h = 30.0, 8.0
    r2 = (X - 35) ** 2 + (Y - 30) ** 2
    dome = np.where(r2 < R * R, np.sqrt(np.maximum(R * R - r2, 0)) - (R - h), 0.0).clip(min=0)
    ridge = np.clip(8.0 - (np.abs(X - 78) - 2.0) * np.tan(np.radians(40)), 0, 8.0)
    Z = np.maximum(dome, ridge)
    nx, ny = X.shape
    v = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    a = (i * ny + j).ravel()
    f = np.vstack([np.column_stack([a, a + ny, a + 1]), np.column_stack([a + 1, a + ny, a + ny + 1])])
    return TriMesh(v, f, "sign")


def main() -> None:
    mesh = sign_surface()
    candidates = [("ball D6", Cutter.ball(D)), ("flat D6", Cutter.flat(D)), ("bull D6 r1", Cutter.bull(D, 1.0)),
                  ("bull D6 r2", Cutter.bull(D, 2.0))]
    t0 = time.perf_counter()
    out = compare_cutters(mesh, candidates, stepover=0.79375, sample_step=0.4, cell=0.1, margin=5.0)
    seconds = time.perf_counter() - t0
    bands = " | ".join(f"mean left {lo:g}-{hi:g} deg" for lo, hi in SLOPE_BANDS)
    print(f"| cutter | max left mm | mean left mm | std mm | p95 mm | left cm3 | removed cm3 | cycle min | {bands} |")
    print("|---|---|---|---|---|---|---|---|" + "---|" * len(SLOPE_BANDS))
    for s in out.scores:
        cols = " | ".join(f"{s.by_slope[b]:.4f}" for b in SLOPE_BANDS)
        print(f"| {s.label} | {s.max_left:.4f} | {s.mean_left:.4f} | {s.std_left:.4f} | {s.p95_left:.4f} | "
              f"{s.remaining_volume / 1000:.3f} | {s.removed_volume / 1000:.2f} | {s.cycle_seconds / 60:.1f} | {cols} |")
    print()
    for r in out.reasons:
        print(r)
    print(f"\n{len(candidates)} cutters planned, simulated (cells {out.grid.cell:g} mm, {out.grid.nx} x {out.grid.ny}) "
          f"and compared in {seconds:.1f} s")


if __name__ == "__main__":
    main()
