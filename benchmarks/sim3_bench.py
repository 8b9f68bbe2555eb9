"""Exact 3-axis z-map simulation (native cut_3axis) speed, with a plain numpy stamping reference in the same run.

    .venv/bin/python benchmarks/sim3_bench.py            # the table (about 1.5 minutes on 2 cores)
    TMM_SIM3_BUILD=build-sim3 .venv/bin/python benchmarks/sim3_bench.py   # the module of a side build

A zig-zag raster finishing path over 50 x 50 mm (passes along X every 0.05 mm, moves of 0.05 mm, about one
million moves) following a wavy z = 2 + 0.5 sin(x/4) cos(y/5), cut into a stock at z = 5 by a D6 ball and a
D6 r1 bull-nose, on 1000 x 1000 cells of 0.05 mm and 500 x 500 cells of 0.1 mm. Per case: cut_3axis time
on 1 and 2 threads, moves/s (2 threads), the grid's memory, and the numpy reference: the tool stamped at
sub-steps of half a cell along each move (vectorised over the tool's window of cells), timed on a subset
of the moves in the middle of the path and scaled to all of them, with its ratio to cut_3axis (2 threads).
The reference is approximate (it misses up to the sub-step's scallop) where cut_3axis is exact.
"""
from __future__ import annotations

import importlib
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

if os.environ.get("TMM_SIM3_BUILD"):
    sys.path.insert(0, os.path.abspath(os.environ["TMM_SIM3_BUILD"]))
    native = importlib.import_module("_native")
else:
    from tmm_workbench.core.kernel import native  # noqa: E402

AREA, STEP, MOVE, TOP = 50.0, 0.05, 0.05, 5.0
SUBSET = 400  # moves the numpy reference stamps


def raster() -> np.ndarray:
    xs = np.linspace(0.0, AREA, int(round(AREA / MOVE)) + 1)
    ys = np.linspace(0.0, AREA, int(round(AREA / STEP)) + 1)
    x = np.concatenate([xs if k % 2 == 0 else xs[::-1] for k in range(len(ys))])
    y = np.repeat(ys, len(xs))
    return np.column_stack([x, y, 2.0 + 0.5 * np.sin(x / 4) * np.cos(y / 5)])


def profile(radius: float, corner: float):
    e = radius - corner

    def h(rho):
        t = np.maximum(rho - e, 0.0)
        return corner - np.sqrt(np.maximum(corner * corner - t * t, 0.0))
    return h


def numpy_reference(z: np.ndarray, x0: float, cell: float, tips: np.ndarray, radius: float, corner: float) -> None:
    """Stamps the tool at sub-steps of half a cell along each move: z = min(z, tip + h(rho)) over its window."""
    h = profile(radius, corner)
    w = int(np.ceil(radius / cell)) + 1
    offs = np.arange(-w, w + 1)
    for a, b in zip(tips[:-1], tips[1:]):
        n = max(1, int(np.ceil(np.hypot(*(b[:2] - a[:2])) / (cell / 2))))
        for t in np.linspace(0.0, 1.0, n + 1)[1:]:
            px, py, pz = a + t * (b - a)
            ci, cj = int((px - x0) / cell), int((py - x0) / cell)
            i = np.clip(ci + offs, 0, z.shape[1] - 1)
            j = np.clip(cj + offs, 0, z.shape[0] - 1)
            cx, cy = x0 + (i + 0.5) * cell, x0 + (j + 0.5) * cell
            rho = np.hypot(cx[None, :] - px, cy[:, None] - py)
            stamp = np.where(rho <= radius, pz + h(np.minimum(rho, radius)), np.inf)
            win = z[np.ix_(j, i)]
            z[np.ix_(j, i)] = np.minimum(win, stamp)


def main() -> None:
    tips = raster()
    kinds = np.zeros(len(tips) - 1, np.uint8)
    moves = len(kinds)
    print(f"raster: {moves} moves of {MOVE} mm, step-over {STEP} mm, over {AREA:g} x {AREA:g} mm; "
          f"numpy reference on {SUBSET} moves, scaled\n")
    print("| grid | cell mm | tool | 1 thread s | 2 threads s | moves/s (2 thr) | grid MB | cells lowered "
          "| numpy ref s (scaled) | numpy / kernel |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    mid = moves // 2
    sub = tips[mid:mid + SUBSET + 1]
    for n, cell in ((1000, 0.05), (500, 0.1)):
        for name, radius, corner in (("ball D6", 3.0, 3.0), ("bull D6 r1", 3.0, 1.0)):
            cutter = native.Cutter(radius, corner)
            times = []
            for threads in (1, 2):
                stock = native.ZMap(0.0, 0.0, cell, n, n, TOP)
                t = time.perf_counter()
                r = native.cut_3axis(stock, cutter, tips, kinds, threads=threads)
                times.append(time.perf_counter() - t)
            ref = np.full((n, n), TOP)
            t = time.perf_counter()
            numpy_reference(ref, 0.0, cell, sub, radius, corner)
            ref_s = (time.perf_counter() - t) * moves / SUBSET
            mb = native.ZMap.bytes_for(n, n) / 2**20
            print(f"| {n} x {n} | {cell:g} | {name} | {times[0]:.2f} | {times[1]:.2f} | {moves / times[1]:,.0f} | "
                  f"{mb:.1f} | {r['cells_lowered']:,} | {ref_s:,.0f} | {ref_s / times[1]:,.0f} |", flush=True)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak RSS {rss:.0f} MB; cpu count {os.cpu_count()}")


if __name__ == "__main__":
    main()
