"""Cost of the tool holder clearance check (core.verify.holder_clearance) per 100k moves on real STL files.

    .venv/bin/python benchmarks/holder_clearance.py            # about a minute
    .venv/bin/python benchmarks/holder_clearance.py --quick    # fewer moves
    .venv/bin/python benchmarks/holder_clearance.py --threads 1

Per case (a shared benchmark STL, a ball D6 with 6 mm shank in a common holder): a zig-zag raster of about
100k moves dropped with the cutter alone (the holder collides where the part is deep) and with the whole
assembly (clear), each checked with the vertical drop; then the same raster with the tool tilted 10 degrees
(checked by point-to-frustum distances), on a share of the moves, scaled to 100k. Prints seconds per 100k
moves, the samples checked and the colliding ones; the surface sample's build is timed apart (once per
check that needs it).
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.query.drop_assembly import AssemblyDrop  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind, Toolpath  # noqa: E402
from tmm_workbench.core.tools.assembly import ToolAssembly  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tmm_workbench.core.verify.body_distance import SurfacePoints  # noqa: E402
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance  # noqa: E402


def raster(lo, hi, moves: int) -> np.ndarray:
    """Zig-zag rows over the XY box with about `moves` points, 0.5 mm apart along the rows."""
    xs = np.arange(lo[0], hi[0] + 1e-9, 0.5)
    rows = max(2, int(round(moves / len(xs))))
    out = [np.column_stack([xs if k % 2 == 0 else xs[::-1], np.full(xs.size, y)])
           for k, y in enumerate(np.linspace(lo[1], hi[1], rows))]
    return np.concatenate(out)


def path(xy: np.ndarray, z: np.ndarray, axis=(0.0, 0.0, 1.0)) -> Toolpath:
    tp = Toolpath()
    for (x, y), h in zip(xy, z):
        tp.add(MoveKind.FEED, x, y, h, axis)
    return tp


def cases():
    stl = shared_dir() / "benchmarks" / "stl"
    ball6 = Cutter.ball(6)
    yield "wheel_in_box (50 mm deep box)", load_stl(stl / "wheel_in_box.stl"), \
        ToolAssembly(ball6, 6, 30, flute_length=15, holder="SK40 ER32x70")
    yield "mount_rush (27 mm relief)", load_stl(stl / "mount_rush.stl"), \
        ToolAssembly(ball6, 6, 25, flute_length=15, holder="HSK63A shrink 6x80")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--threads", type=int, default=0)
    args = ap.parse_args()
    moves = 20_000 if args.quick else 100_000
    tilted_moves = 2_000 if args.quick else 10_000
    tilt = math.radians(10.0)
    print(f"{'case':34} {'path':22} {'moves':>8} {'samples':>8} {'colliding':>9} {'s/100k moves':>13}")
    for name, mesh, assembly in cases():
        surface = DropSurface(mesh)
        lo, hi = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
        xy = raster(lo[:2], hi[:2], moves)
        floor = float(lo[2])
        zc = surface.drop(assembly.cutter, xy, floor, threads=args.threads)
        za, _ = AssemblyDrop(mesh, assembly, surface).heights(xy, floor, threads=args.threads)
        t0 = time.perf_counter()
        SurfacePoints(mesh, 0.25)
        build = time.perf_counter() - t0
        runs = [("cutter-only drop", path(xy, zc), len(xy)), ("assembly drop", path(xy, za), len(xy))]
        k = np.linspace(0, len(xy) - 1, tilted_moves).astype(int)
        axis = (math.sin(tilt), 0.0, math.cos(tilt))
        runs.append((f"tilted 10 deg ({tilted_moves // 1000}k)", path(xy[k], za[k] + 0.5, axis), tilted_moves))
        for label, tp, n in runs:
            t0 = time.perf_counter()
            r = check_holder_clearance(mesh, assembly, tp, surface, threads=args.threads)
            dt = time.perf_counter() - t0
            print(f"{name:34} {label:22} {n:8,} {r.samples:8,} {r.count:9,} {dt * 100_000 / n:13.2f}")
        print(f"{'':34} surface sample 0.25 mm: {build:.2f} s to build (in the figures where contacts or tilted "
              "poses need it)")
        print(f"{'':34} {replace(assembly).describe()}")


if __name__ == "__main__":
    main()
