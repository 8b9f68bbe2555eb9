"""Seed 000's Fig. 5-5 by the 3D C-space method: adaptive 5-axis passes on the convex surface, flat end mill
D 0.5 in, tolerance 0.004 in, postures chosen for the Tarus motion time; the scallop checked by the slow
reference on the real tool positions; and one pass's motion time against the seed's nearest-to-ideal choice.

    .venv/bin/python benchmarks/mesh5_stepover.py [--surface convex|concave] [--check-x 100 150]

Prints the passes (seed: 49 adaptive, 84 at constant step-over), the compute time, the C-spaces built, the
step between planes, and the remaining height at surface samples between x0 and x1 (all y) under all passes.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tests.core.scallop5_reference import remaining, surface_samples, swept_positions  # noqa: E402
from tmm_workbench.core.machine.tarus import TarusMachine  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace  # noqa: E402
from tmm_workbench.core.strategies.mesh5.optimal import nearest_ideal, pass_motion_time, smooth_postures  # noqa: E402
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid  # noqa: E402
from tmm_workbench.core.strategies.mesh5.stepover import adaptive_passes  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def one_pass_times(mesh, cutter, tol: float, machine: TarusMachine) -> None:
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 2.0, 0.01)[0]
    cs = build_cspace(mesh, cutter, path.points, path.frames, PostureGrid.degrees(), tol, 2.5)
    t0 = time.perf_counter()
    seed = nearest_ideal(cs, cutter, path.points, path.frames, machine)
    t1 = time.perf_counter()
    dp = smooth_postures(cs, cutter, path.points, path.frames, machine)
    t2 = time.perf_counter()
    a, b = pass_motion_time(machine, seed), pass_motion_time(machine, dp)
    print(f"pass y = 0 ({len(path)} CC points, half step 2.5 mm): Tarus motion time nearest-to-ideal {a:.2f} s "
          f"({t1 - t0:.2f} s to choose), shortest path {b:.2f} s ({t2 - t1:.2f} s to choose), ratio {a / b:.2f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--surface", default="convex", choices=("convex", "concave"))
    ap.add_argument("--check-x", type=float, nargs=2, default=(100.0, 150.0))
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter = Cutter.flat(0.5 * INCH)
    tol = 0.004 * INCH
    machine = TarusMachine()
    one_pass_times(mesh, cutter, tol, machine)
    plan = adaptive_passes(mesh, cutter, tol, (1, 0), machine)
    steps = np.diff([p.offset for p in plan.passes])
    print(f"seed 000 {a.surface}: {plan.report()}; seed: 49 adaptive, 84 constant")
    print(f"step between planes (mm): min {steps.min():.2f}, median {np.median(steps):.2f}, max {steps.max():.2f}")
    lam = np.degrees(np.concatenate([q.lam for p in plan.passes for q in p.postures]))
    print(f"CC points {lam.size}; lambda (deg) median {np.median(lam):.0f}, max {lam.max():.0f}")
    t0 = time.perf_counter()
    sw = [swept_positions(q.tips, q.axes) for p in plan.passes for q in p.postures]
    tips, axes = np.concatenate([s[0] for s in sw]), np.concatenate([s[1] for s in sw])
    lo, hi = mesh.bounds
    xs, ys = np.meshgrid(np.linspace(*a.check_x, 6), np.arange(lo[1] + 0.25, hi[1], 0.25), indexing="ij")
    q, nrm, hit = surface_samples(mesh, np.column_stack([xs.ravel(), ys.ravel()]))
    h = remaining(q[hit], nrm[hit], tips, axes, cutter.radius, 2 * cutter.diameter)
    print(f"slow check, {hit.sum()} surface points x {a.check_x[0]:g}..{a.check_x[1]:g} mm (every 0.25 mm across): "
          f"remaining height max {h.max():.4f} mm (tolerance {tol:.4f}), min {h.min():.4f} mm, above the "
          f"tolerance + 0.002: {(h > tol + 0.002).sum()} points; {time.perf_counter() - t0:.1f} s")
    over = np.flatnonzero(h > tol + 0.002)
    for i in over[:20]:
        k = int(np.searchsorted([p.offset for p in plan.passes], q[hit][i, 1]))
        near = [plan.passes[j] for j in (k - 1, k) if 0 <= j < len(plan.passes)]
        print(f"  ({q[hit][i, 0]:.2f}, {q[hit][i, 1]:.2f}) left {h[i]:.4f} mm; planes "
              + ", ".join(f"{p.offset:.2f} band {p.band[0]:.2f}..{p.band[1]:.2f}" for p in near))


if __name__ == "__main__":
    main()
