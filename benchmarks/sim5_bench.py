"""5-axis z-map simulation: the kernel's cut_5axis on a seed-001-size job, against the Python reference
(tests/core/zmap_reference.py) on a subset. Prints a markdown table.

    .venv/bin/python benchmarks/sim5_bench.py             # the kernel in the package (tmm_workbench._native)
    TMM_SIM5_BUILD=build-sim5 .venv/bin/python benchmarks/sim5_bench.py   # a side build's module

Job: seed 001's convex patch (150 x 150 mm), VCRF tool path of compute_multipoint_toolpath (side step 18 mm
fixed, forward step 2 mm, torus Ro 6.7 Ri 6, linked along the axis: safe height 5 mm above the face), a
1500 x 1500 z-map of 0.1 mm cells over the patch (a row of centres on y = 27), the stock the design surface
plus a 0.5 mm finishing allowance (the linking's rapids, 5 mm above the face, then stay clear of it),
max_step 0.05 mm.
The reference simulates the section y = 27 (the seed's, 1500 needles at the cell centres) with the same
moves and max_step, verify_tol off; the kernel is timed on the same section (a one-row z-map) for the ratio,
and the two sections are compared.
"""
from __future__ import annotations

import argparse
import importlib
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies.multipoint import (BezierFace, MultipointParams,  # noqa: E402
                                                      compute_multipoint_toolpath, face_top, link_policy)
from tmm_workbench.core.toolpath import MoveKind  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tests.core import zmap_reference as zmap  # noqa: E402

RO, RI = 6.7, 6.0
CELL = 0.1
MAX_STEP = 0.05
SECTION_Y = 27.0


def kernel_module():
    build = os.environ.get("TMM_SIM5_BUILD")
    if build:
        sys.path.insert(0, str((ROOT / build).resolve()))
        mod = importlib.import_module("_native")
        # One module for the whole package (two would register the same pybind11 types twice).
        sys.modules["tmm_workbench._native"] = mod
        return mod
    from tmm_workbench.core.kernel import native
    native.load()
    return native


def seed_job():
    """The tool path (tips, axes, kinds) and the face's top."""
    face = BezierFace.from_net(bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex"))
    tool = Cutter.torus(RO, RI)
    safe = face_top(face) + 5.0
    params = MultipointParams(side_step=18.0, pass_spacing="fixed", forward_step=2.0, between_tol=0.0)
    tp, _ = compute_multipoint_toolpath(face, tool, params, link_policy(tool, safe, safe + 5.0, 5.0))
    tips, axes = tp.points(), tp.axes()
    # The kind of the move k -> k + 1 is that of the move arriving at k + 1.
    kinds = np.array([1 if m.kind is MoveKind.RAPID else 0 for m in tp.moves[1:]], dtype=np.uint8)
    return tips, axes, kinds, face


def design(net, x, y):
    """Design height at (x, y): the seed nets have x(u) = 150 u, y(v) = 150 v (evenly spaced control x, y)."""
    return bezier.evaluate(net, np.asarray(x) / 150.0, np.asarray(y) / 150.0)[..., 2]


def face_net():
    return bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")


def cutting_runs(tips, axes, kinds):
    """Runs of consecutive cut moves as (tips, axes) paths for the Python reference (rapids run above)."""
    runs, start = [], 0
    for k, kind in enumerate(kinds):
        if kind != 0:
            if k > start:
                runs.append((tips[start:k + 1], axes[start:k + 1]))
            start = k + 1
    if len(tips) - 1 > start:
        runs.append((tips[start:], axes[start:]))
    return runs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-step", type=float, default=MAX_STEP)
    ap.add_argument("--threads", default="1,2", help="thread counts of the full z-map runs")
    args = ap.parse_args()
    nat = kernel_module()
    t0 = time.perf_counter()
    tips, axes, kinds, _ = seed_job()
    net = face_net()
    t_path = time.perf_counter() - t0
    n = 1500
    y0 = SECTION_Y - (round(SECTION_Y / CELL) + 0.5) * CELL     # row j = 270 on y = 27
    xs = (np.arange(n) + 0.5) * CELL
    ys = y0 + (np.arange(n) + 0.5) * CELL
    X, Y = np.meshgrid(xs, ys)
    allowance = design(net, X, Y) + 0.5
    rows = []
    grids = {}
    for threads in [int(t) for t in args.threads.split(',')]:
        stock = nat.ZMap(0.0, y0, CELL, n, n, 0.0)
        stock.heights[:] = allowance
        t0 = time.perf_counter()
        r = nat.cut_5axis(stock, RO, RI, "round_insert", tips, axes, kinds, max_step=args.max_step,
                          threads=threads)
        dt = time.perf_counter() - t0
        grids[threads] = np.array(stock.heights)
        rows.append((threads, dt, r))
    first = next(iter(grids.values()))
    identical = all(np.array_equal(first, g) for g in grids.values())
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0

    # The section y = 27: the reference and the kernel on the same needles (the cell centres).
    needles = np.column_stack([xs, np.full(n, SECTION_Y)])
    z0 = design(net, xs, np.full(n, SECTION_Y)) + 0.5
    runs = cutting_runs(tips, axes, kinds)
    t0 = time.perf_counter()
    ref = zmap.simulate(zmap.ZTool(RO, RI), needles, z0, runs, max_step=args.max_step, verify_tol=None)
    t_py = time.perf_counter() - t0
    section = nat.ZMap(0.0, SECTION_Y - 0.5 * CELL, CELL, n, 1, 0.0)
    section.heights[:] = z0
    t0 = time.perf_counter()
    nat.cut_5axis(section, RO, RI, "round_insert", tips, axes, kinds, max_step=args.max_step, threads=1)
    t_sec = time.perf_counter() - t0
    zk = np.array(section.heights)[0]
    full_row = first[int(round(SECTION_Y / CELL))]
    bound = args.max_step ** 2 / (8 * RI)

    print(f"seed 001 convex, VCRF, {len(tips)} points ({int((kinds == 0).sum())} cut moves, "
          f"{int((kinds == 1).sum())} rapids; path {t_path:.1f} s), z-map {n} x {n} cells of {CELL} mm "
          f"({n * n * 8 / 2**20:.0f} MiB), max_step {args.max_step} mm, cusp bound {bound:.1e} mm")
    print()
    print("| run | threads | time s | instances | instances/s | cells tested | quartics solved | fallback "
          "solves | cell lowerings | cells lowered | collisions | peak RSS MiB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for threads, dt, r in rows:
        print(f"| kernel, full z-map | {threads} | {dt:.2f} | {r['instances']} | {r['instances'] / dt:,.0f} | "
              f"{r['cells_tested']:,} | {r['exact_solves']:,} | {r['fallback_solves']:,} | {r['lowerings']:,} | "
              f"{r['cells_lowered']:,} | {len(r['collisions'])} | {rss:.0f} |")
    print(f"| kernel, section y = {SECTION_Y:g} (1 row) | 1 | {t_sec:.3f} | | | | | | | | | |")
    print(f"| zmap.py, section y = {SECTION_Y:g} ({n} needles) | 1 | {t_py:.1f} | {ref.instances} | "
          f"{ref.instances / t_py:,.0f} | | {ref.solves:,} | | | | | |")
    print()
    print(f"threads {args.threads} bit-identical: {identical}; section: zmap.py / kernel time "
          f"{t_py / t_sec:,.0f}x; kernel section vs zmap.py max |diff| {np.max(np.abs(zk - ref.z)):.2e} mm, "
          f"full z-map row y = {SECTION_Y:g} vs zmap.py {np.max(np.abs(full_row - ref.z)):.2e} mm")
    if len(rows) > 1:
        print(f"speed-up {rows[0][0]} -> {rows[-1][0]} threads: {rows[0][1] / rows[-1][1]:.2f}")


if __name__ == "__main__":
    main()
