"""Seed 000's Fig. 5-5 by the 3D C-space method: adaptive 5-axis passes on the convex surface, flat end mill
D 0.5 in, tolerance 0.004 in, postures chosen for the Tarus motion time; the scallop checked by the slow
reference on the real tool positions; and one pass's motion time against the seed's nearest-to-ideal choice.

    .venv/bin/python benchmarks/mesh5_stepover.py [--surface convex|concave|complex] [--tolerance-in 0.004]
        [--x-lines 11] [--step 0.25] [--no-pass-times] [--constant [--every 5]] [--widest [--every 5]]

Prints the passes (seed: 49 adaptive, 84 at constant step-over), the compute time (wall and CPU: the machine is
shared), the C-spaces built, the step between planes, and the slow check: the material left at surface samples
on lines across the whole surface (every 0.25 mm) under all passes' tools with their overruns; then a table.
--constant: instead, the largest constant step-over (constant_step) and its pass count. --widest: instead, an upper
bound on each pass's width (widest_steps) and the least pass count it allows.
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
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths, plane_normal  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace  # noqa: E402
from tmm_workbench.core.strategies.mesh5.optimal import nearest_ideal, pass_motion_time, smooth_postures  # noqa: E402
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid  # noqa: E402
from tmm_workbench.core.strategies.mesh5.lift import MeshReach  # noqa: E402
from tmm_workbench.core.strategies.mesh5.stepover import INTERIOR, MARGIN, tilt_reached, adaptive_passes  # noqa: E402
from tmm_workbench.core.strategies.mesh5.tool_moves import OVERRUN_STEPS  # noqa: E402
from tmm_workbench.core.strategies.mesh5.top_bound import top_bounds  # noqa: E402
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


def constant_step(mesh, cutter, tol: float, machine: TarusMachine, every: float = 5.0) -> tuple[float, int, float]:
    """Seed 000's constant step-over by the same machinery: the largest step s between drive planes with which
    every CC point of planes `every` mm apart (across the whole mesh) has a posture in its C-space (S2 <= S1
    at MARGIN x tau, within the machine's tilt) leaving the tolerance at s / 2 on both sides (along LY: s / 2
    over LY's share of the plane normal), so that any two neighbouring passes s apart meet. Bisection on S1
    (S1 >= 0 is necessary), then on the whole C-space. (s, passes over the mesh, seconds)."""
    t0 = time.perf_counter()
    reach, grid = MeshReach(mesh), PostureGrid.degrees()
    lo, hi = mesh.bounds[0][1], mesh.bounds[1][1]
    lam, omg = (g.ravel() for g in grid.mesh())
    best = np.inf
    for offset in np.arange(lo + 0.125 * cutter.diameter, hi - 0.125 * cutter.diameter + 1e-9, every):
        paths = cc_paths(mesh, (1, 0), np.array([offset]), 2.0, 0.01)
        pts, frm = np.concatenate([p.points for p in paths]), np.concatenate([p.frames for p in paths])
        ask = tilt_reached(machine, frm, grid)
        keep = ask.any(axis=(1, 2))                                       # as the plan: beyond the tilt, left
        pts, frm, ask = pts[keep], frm[keep], ask[keep]
        across = np.maximum(frm[:, 1] @ plane_normal((1, 0)), 0.2)         # LY's share of the plane normal

        def side(s: float) -> np.ndarray:
            return np.minimum(0.5 * s / across, 2 * cutter.radius)

        def s1_ok(s: float) -> bool:
            top = top_bounds(reach, cutter, pts, frm, lam, omg, MARGIN * tol, side(s), interior=INTERIOR)
            return bool(((top.reshape(ask.shape) >= 0) & ask).any(axis=(1, 2)).all())

        def full_ok(s: float) -> bool:
            return not build_cspace(reach, cutter, pts, frm, grid, MARGIN * tol, side(s), interior=INTERIOR,
                                    ask=ask).empty.any()

        b = min(best, 4 * cutter.radius)                                  # only a smaller step matters
        if s1_ok(b) and full_ok(b):
            continue
        s = _largest(s1_ok, b)                                            # S1 >= 0 is necessary
        best = s if full_ok(s) else _largest(full_ok, s)
        print(f"  plane y = {offset:7.2f} mm: constant step <= {best:.3f} mm", flush=True)
    count = 1 + int(np.ceil((hi - lo - 0.25 * cutter.diameter) / best - 1e-9))
    return best, count, time.perf_counter() - t0


def widest_steps(mesh, cutter, tol: float, machine: TarusMachine, every: float = 10.0
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """An upper bound on the width one pass can finish, per drive plane `every` mm across: the largest w such
    that every CC point of the plane (within the machine's tilt, as the plan) has a posture whose top bound S1
    at the full tolerance is >= 0 (necessary: S2 >= 0) with its side steps a and w - a along the plane normal
    (a = w / 3, w / 2 or 2 w / 3), by bisection. A pass covers at most its plane's w, so the passes number at
    least the integral of dy / w(y) across the mesh. (planes' y, w, seconds)."""
    t0 = time.perf_counter()
    reach, grid = MeshReach(mesh), PostureGrid.degrees()
    lo, hi = mesh.bounds[0][1], mesh.bounds[1][1]
    lam, omg = (g.ravel() for g in grid.mesh())
    ys, ws = [], []
    for offset in np.arange(lo + 0.5 * every, hi, every):
        paths = cc_paths(mesh, (1, 0), np.array([offset]), 2.0, 0.01)
        pts, frm = np.concatenate([p.points for p in paths]), np.concatenate([p.frames for p in paths])
        ask = tilt_reached(machine, frm, grid)
        keep = ask.any(axis=(1, 2))
        pts, frm, ask = pts[keep], frm[keep], ask[keep].reshape(int(keep.sum()), -1)
        across = np.maximum(frm[:, 1] @ plane_normal((1, 0)), 0.2)

        def ok(w: float) -> bool:
            met = np.zeros(len(pts), dtype=bool)
            for share in (0.5, 1 / 3, 2 / 3):
                side = np.minimum(np.column_stack([share * w / across, (1 - share) * w / across]), 2 * cutter.radius)
                top = top_bounds(reach, cutter, pts, frm, lam, omg, tol, side, interior=INTERIOR)
                met |= ((top >= 0) & ask).any(axis=1)
                if met.all():
                    return True
            return False

        w = _largest(ok, 4 * cutter.radius, 8)
        ys.append(offset)
        ws.append(w)
        print(f"  plane y = {offset:7.2f} mm ({len(pts)} CC points): widest pass <= {w:.2f} mm", flush=True)
    return np.array(ys), np.array(ws), time.perf_counter() - t0


def _largest(ok, b: float, rounds: int = 10) -> float:
    """The largest s in (0, b) found ok by bisection (ok(0) taken as true)."""
    a = 0.0
    for _ in range(rounds):
        mid = 0.5 * (a + b)
        a, b = (mid, b) if ok(mid) else (a, mid)
    return a


def _in_strips(q: np.ndarray, strips, grow: float) -> np.ndarray:
    """(n,) whether each point (feed X, across Y) lies in one of the plan's unfinished strips (feed from, to,
    across from, to), each grown by `grow` mm."""
    inside = np.zeros(len(q), dtype=bool)
    for f0, f1, c0, c1 in strips:
        inside |= (q[:, 0] >= f0 - grow) & (q[:, 0] <= f1 + grow) & (q[:, 1] >= min(c0, c1) - grow) & \
            (q[:, 1] <= max(c0, c1) + grow)
    return inside


def slow_check(mesh, plan, cutter, x_lines: int, step: float, sub: int = 16) -> tuple[np.ndarray, np.ndarray, float]:
    """The material left (mm, along the facet normals) at surface samples on `x_lines` lines across the whole
    feed width, every `step` mm across, under all passes' tools with their overruns, `sub` - 1 positions
    between each two CL points (a flat end tilted by lambda sits up to sin(lambda) x the spacing above the
    surface between two sampled positions: 0.026 mm at 3 deg with 4 positions on a 2 mm step); and the
    seconds."""
    t0 = time.perf_counter()
    sw = [swept_positions(t, a, sub) for t, a in plan.tool_positions()]
    tips, axes = np.concatenate([s[0] for s in sw]), np.concatenate([s[1] for s in sw])
    lo, hi = mesh.bounds
    reach = cutter.radius + 2 * cutter.diameter
    qs, hs = [], []
    for x in np.linspace(lo[0] + 0.05, hi[0] - 0.05, x_lines):          # the edge itself: no facet normal
        ys = np.arange(lo[1] + step / 2, hi[1], step)
        q, nrm, hit = surface_samples(mesh, np.column_stack([np.full(len(ys), x), ys]))
        near = np.abs(tips[:, 0] - x) <= reach
        qs.append(q[hit])
        hs.append(remaining(q[hit], nrm[hit], tips[near], axes[near], cutter.radius, 2 * cutter.diameter))
    return np.concatenate(qs), np.concatenate(hs), time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--surface", default="convex", choices=("convex", "concave", "complex"))
    ap.add_argument("--tolerance-in", type=float, default=0.004, help="the tolerance in inches (seed: 0.004; "
                    "the complex surface also at 0.03)")
    ap.add_argument("--x-lines", type=int, default=11, help="lines across the feed for the slow check")
    ap.add_argument("--step", type=float, default=0.25, help="mm between the slow check's samples across")
    ap.add_argument("--no-pass-times", action="store_true")
    ap.add_argument("--constant", action="store_true", help="only the constant step-over (seed: 84 passes on "
                    "the convex surface at 0.004 in), planes every --every mm")
    ap.add_argument("--every", type=float, default=5.0)
    ap.add_argument("--widest", action="store_true", help="only an upper bound on each pass's width (planes "
                    "every 2 x --every mm) and the least pass count it allows")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter = Cutter.flat(0.5 * INCH)
    tol = a.tolerance_in * INCH
    machine = TarusMachine()
    if a.constant:
        cpu = time.process_time()
        step, count, secs = constant_step(mesh, cutter, tol, machine, a.every)
        print(f"seed 000 {a.surface}, tau {tol:.4f} mm: largest constant step {step:.3f} mm -> {count} passes over "
              f"{mesh.bounds[1][1] - mesh.bounds[0][1]:.1f} mm (planes checked every {a.every:g} mm; "
              f"{secs:.1f} s wall / {time.process_time() - cpu:.1f} s CPU)")
        return
    if a.widest:
        ys, ws, secs = widest_steps(mesh, cutter, tol, machine, 2 * a.every)
        span = mesh.bounds[1][1] - mesh.bounds[0][1]
        least = float(np.sum(2 * a.every / ws))
        print(f"seed 000 {a.surface}, tau {tol:.4f} mm: widest pass per plane (mm) min {ws.min():.2f}, median "
              f"{np.median(ws):.2f}, max {ws.max():.2f}; passes >= sum(dy / w) = {least:.1f} over {span:.1f} mm "
              f"({secs:.1f} s)")
        return
    if not a.no_pass_times:
        one_pass_times(mesh, cutter, tol, machine)
    cpu = time.process_time()
    plan = adaptive_passes(mesh, cutter, tol, (1, 0), machine)
    cpu = time.process_time() - cpu
    steps = np.diff([p.offset for p in plan.passes])
    print(f"seed 000 {a.surface}: {plan.report()}")
    print(f"step between planes (mm): min {steps.min():.2f}, median {np.median(steps):.2f}, max {steps.max():.2f}")
    lam = np.degrees(np.concatenate([q.lam for p in plan.passes for q in p.postures]))
    print(f"CC points {lam.size}; lambda (deg) median {np.median(lam):.0f}, max {lam.max():.0f}")
    runs = plan.tool_positions()
    print(f"tool positions {sum(len(t) for t, _ in runs)}: the CC points' {lam.size}, on the overruns and between "
          f"{sum(len(t) for t, _ in runs) - lam.size} ({len(runs)} paths, up to {2 * OVERRUN_STEPS} overrun each)")
    q, h, secs = slow_check(mesh, plan, cutter, a.x_lines, a.step)
    over = np.flatnonzero(h > tol + 0.002)
    print(f"slow check: {len(h)} surface points on {a.x_lines} lines x {mesh.bounds[0][0]:g}..{mesh.bounds[1][0]:g} "
          f"mm, every {a.step:g} mm across, tools with a {plan.overrun:.2f} mm overrun; {secs:.1f} s")
    for x in np.unique(q[:, 0]):
        on = q[:, 0] == x
        print(f"  x = {x:6.1f} mm: {on.sum()} points, max {h[on].max():.4f} mm, above tau + 0.002 mm: "
              f"{(h[on] > tol + 0.002).sum()}, uncut {(~np.isfinite(h[on])).sum()}, least {h[on].min():.4f} mm")
    if plan.unfinished:
        inside = _in_strips(q, plan.unfinished, cutter.radius)
        print(f"  outside the {len(plan.unfinished)} strips left for clean-up (grown by a radius): "
              f"{int((~inside).sum())} points, max {h[~inside & np.isfinite(h)].max():.4f} mm, above tau + 0.002 mm: "
              f"{int((h[~inside] > tol + 0.002).sum())}, uncut {int((~np.isfinite(h[~inside])).sum())}")
    for i in over[:: max(1, len(over) // 20)]:
        print(f"  ({q[i, 0]:.2f}, {q[i, 1]:.2f}) left {h[i]:.4f} mm")
    print()
    print("| | passes | max scallop (mm) | points above tau + 0.002 mm | uncut points | least (gouge < 0) (mm) | "
          "seconds (wall / CPU) |")
    print("|---|---|---|---|---|---|---|")
    print(f"| TMM, {a.surface}, tau {tol:.4f} mm | {len(plan.passes)} | {h[np.isfinite(h)].max():.4f} | "
          f"{len(over)} | {int((~np.isfinite(h)).sum())} | {h.min():.4f} | {plan.seconds:.1f} / {cpu:.1f} |")
    if a.surface == "convex" and a.tolerance_in == 0.004:
        print("| seed 000 (Fig. 5-5), adaptive | 49 | | | | | |")
        print("| seed 000 (Fig. 5-5), constant step-over | 84 | | | | | |")
    if a.surface == "complex" and a.tolerance_in == 0.03:
        print("| seed 000 (Fig. 5-6 (e)), adaptive | 30 | | | | | |")
        print("| seed 000's CAD application A, constant 0.25 in (cusp not verifiable) | 40 | | | | | |")
        print("| seed 000's CAD application B | 182 | | | | | |")


if __name__ == "__main__":
    main()
