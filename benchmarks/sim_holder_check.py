"""Cost of the simulation's check of the tool's bodies against the stock (native body check) next to the plain
cut, on two 3-axis paths over a 100 x 100 mm block, 0.25 mm cells:

    .venv/bin/python benchmarks/sim_holder_check.py

  - pocket: z-level clearing of a 70 x 70 mm pocket 30 mm deep, layers of 5 mm, zig-zag passes 3 mm apart, flat D6
    (flutes 18), stick-out 40 in an ER32 chuck (clear: the check finds nothing and prunes by tile bounds);
  - short: the same path with a stick-out of 18.5 (the chuck meets the uncut block: collisions on most moves);
  - raster: a finishing raster of short moves (0.5 mm, passes 0.5 mm apart over 60 x 60 mm, z = 2 + 0.5 sin(x/4)
    cos(y/5)) into a stock at 5 with a ball D6 (flutes 12), stick-out 30 in the same chuck, 0.1 mm cells.
Per case: simulate() seconds without and with the assembly (2 threads, best of 2), their ratio, collisions found.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind, Toolpath  # noqa: E402
from tmm_workbench.core.tools.assembly import ToolAssembly  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def pocket_path(half: float = 35.0, depth: float = 30.0, layer: float = 5.0, step: float = 3.0) -> Toolpath:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, -half + 3, -half + 3, 50.0)
    for k in range(1, int(depth / layer) + 1):
        z = -k * layer
        ys = np.arange(-half + 3, half - 3 + 1e-9, step)
        tp.add(MoveKind.RAPID, -half + 3, ys[0], z + layer + 1)
        tp.add(MoveKind.FEED, -half + 3, ys[0], z)
        for i, y in enumerate(ys):
            xa, xb = (-half + 3, half - 3) if i % 2 == 0 else (half - 3, -half + 3)
            tp.add(MoveKind.FEED, xa, y, z)
            tp.add(MoveKind.FEED, xb, y, z)
        tp.add(MoveKind.RAPID, tp.moves[-1].x, tp.moves[-1].y, 50.0)
    return tp


def raster_path(size: float = 60.0, step: float = 0.5) -> Toolpath:
    tp = Toolpath()
    xs = np.arange(-size / 2, size / 2 + 1e-9, step)
    tp.add(MoveKind.RAPID, xs[0], xs[0], 20.0)
    for i, y in enumerate(xs):
        for x in (xs if i % 2 == 0 else xs[::-1]):
            tp.add(MoveKind.FEED, x, y, 2.0 + 0.5 * np.sin(x / 4) * np.cos(y / 5))
    return tp


def timed(fn) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(2):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    grid = Grid.covering(-50, -50, 50, 50, 0.25)
    stock = box_heights(grid, 0.0)
    cutter = Cutter.flat(6)
    tp = pocket_path()
    plain_s, _ = timed(lambda: simulate(tp, cutter, grid, stock, threads=2))
    print(f"{len(tp)} points, {grid.nx} x {grid.ny} cells; plain cut {plain_s:.2f} s")
    print("case    stick-out  plain s  checked s  ratio  collisions (moves)")
    for name, out in (("pocket", 40.0), ("short", 18.5)):
        assembly = ToolAssembly(cutter, 6, out, flute_length=18, holder="SK40 ER32x70", shank_clearance=0.0)
        s, res = timed(lambda: simulate(tp, cutter, grid, stock, threads=2, assembly=assembly))
        found = res.stock_collisions
        print(f"{name:7s} {out:9.1f}  {plain_s:7.2f}  {s:9.2f}  {s / plain_s:5.2f}  {found.count:,} "
              f"({len(np.unique(found.moves)):,})")
    grid = Grid.covering(-35, -35, 35, 35, 0.1)
    stock = box_heights(grid, 5.0)
    ball = Cutter.ball(6)
    tp = raster_path()
    plain_s, _ = timed(lambda: simulate(tp, ball, grid, stock, threads=2))
    assembly = ToolAssembly(ball, 6, 30.0, flute_length=12, holder="SK40 ER32x70")
    s, res = timed(lambda: simulate(tp, ball, grid, stock, threads=2, assembly=assembly))
    print(f"raster  {30.0:9.1f}  {plain_s:7.2f}  {s:9.2f}  {s / plain_s:5.2f}  {res.stock_collisions.count:,} "
          f"({len(tp):,} points, {grid.nx} x {grid.ny} cells)")


if __name__ == "__main__":
    main()
