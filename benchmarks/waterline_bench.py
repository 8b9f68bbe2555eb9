"""Waterline speed and agreement, TMM side by side with OpenCAMLib's Waterline and AdaptiveWaterline in one run.

    .venv/bin/python benchmarks/waterline_bench.py            # 3 levels per case, 3 cutters (about 25 minutes)
    .venv/bin/python benchmarks/waterline_bench.py --quick    # 1 level, the ball only (under 3 minutes)
    .venv/bin/python benchmarks/waterline_bench.py --quick --chord-tol 0.003 --step 0.25   # at matched accuracy
    .venv/bin/python benchmarks/waterline_bench.py --quick --all-tools --chord-tol 0.003 --step 0.5 --min-step 0.05
                                                         # the adaptive grid at matched accuracy (docs/results.md)

Cases: the shared STLs sphere_on_plate.stl and mount_rush.stl and the 80k-triangle height field of
drop_cutter_bench.py; ball D6, flat D6, bull D10 r2. Per case and level all three compute the loops at the
same tip height over the model's bounds grown by the cutter radius + 1 mm, on the same threads, with the same
sampling (OpenCAMLib's fibre spacing = our grid step; AdaptiveWaterline's minimum sampling a tenth of it).
Printed per case: seconds per level (ours for the batch of levels, which shares one drop grid, and for one
level alone), the ratios, the loop counts, and the accuracy of each against the other's points: our points
are exact crossings (drop height z within 1e-6 mm, tests/core/test_waterline.py), OpenCAMLib's lie on the
exact loop too (push-cutter fibre ends), so the largest distance of their points from our polylines is our
chord error and the largest distance of our points from their polylines theirs. "AWL loops found": how many
of AdaptiveWaterline's loops have all their points within 0.05 mm (its minimum sampling) of one of our loops
of the same orientation. Equal or better accuracy (the last column): every AdaptiveWaterline loop found and our
chord error against its points no larger than its chord error against ours.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from drop_cutter_bench import STL_DIR, height_field, ocl_surface  # noqa: E402
from opencamlib import ocl  # noqa: E402

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.query.waterline import waterline_loops  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CUTTERS = [
    ("ball d6", Cutter.ball(6.0), lambda: ocl.BallCutter(6.0, 50.0)),
    ("flat d6", Cutter.flat(6.0), lambda: ocl.CylCutter(6.0, 50.0)),
    ("bull d10 r2", Cutter.bull(10.0, 2.0), lambda: ocl.BullCutter(10.0, 2.0, 50.0)),
]
STEP = 0.5       # grid step = fibre spacing, mm
CHORD_TOL = 0.01  # ours, mm
LEVEL_FRACTIONS = (0.62, 0.37, 0.81)  # of the model's height (away from the shared STLs' flat tops)


def segments(loops: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return np.vstack(loops), np.vstack([np.roll(lp, -1, axis=0) for lp in loops])


def distance_to_polylines(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance of the points from the nearest segment a[k] -> b[k]."""
    if not len(pts) or not len(a):
        return float("nan")
    d = b - a
    dd = np.maximum((d * d).sum(1), 1e-300)
    worst = 0.0
    for s in range(0, len(pts), 500):
        p = pts[s:s + 500, None, :]
        t = np.clip(((p - a) * d).sum(2) / dd, 0.0, 1.0)
        worst = max(worst, float(np.sqrt(((p - (a + t[..., None] * d)) ** 2).sum(2)).min(1).max()))
    return worst


def found(theirs: list[np.ndarray], mine: list[np.ndarray], within: float = 0.05) -> int:
    """How many of their loops lie, every point, within `within` of one of our loops of the same orientation."""
    def area(lp: np.ndarray) -> float:
        x, y = lp[:, 0], lp[:, 1]
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    n = 0
    for t in theirs:
        for m in mine:
            if (area(t) > 0) == (area(m) > 0) and distance_to_polylines(t, *segments([m])) <= within:
                n += 1
                break
    return n


def run_ocl(kind, surf, make_cutter, z: float, threads: int, step: float = STEP) -> tuple[float, list[np.ndarray]]:
    w = kind()
    w.setSTL(surf)
    w.setCutter(make_cutter())
    w.setZ(z)
    w.setSampling(step)
    if kind is ocl.AdaptiveWaterline:
        w.setMinSampling(step / 10)
    w.setThreads(threads)
    t = time.perf_counter()
    w.run()
    seconds = time.perf_counter() - t
    return seconds, [np.array([[p.x, p.y] for p in loop]) for loop in w.getLoops() if len(loop)]


def case(name, mesh, threads: int, fractions, cutters, step: float = STEP, chord_tol: float = CHORD_TOL,
         ocl_step: float = STEP, min_step: float | None = None) -> list[dict]:
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    surf = ocl_surface(mesh)
    zs = [float(lo[2] + f * (hi[2] - lo[2])) for f in fractions]
    rows = []
    for cname, cutter, make in cutters:
        g = cutter.radius + 1.0
        bounds = (lo[0] - g, lo[1] - g, hi[0] + g, hi[1] + g)
        t = time.perf_counter()
        ours = waterline_loops(surface, cutter, zs, bounds, sample_step=step, chord_tol=chord_tol, threads=threads,
                               min_step=min_step)
        batch = (time.perf_counter() - t) / len(zs)
        t = time.perf_counter()
        waterline_loops(surface, cutter, zs[:1], bounds, sample_step=step, chord_tol=chord_tol, threads=threads,
                        min_step=min_step)
        single = time.perf_counter() - t
        row = {"model": name, "tool": cname, "levels": len(zs), "tmm": batch, "tmm1": single,
               "wl": 0.0, "awl": 0.0, "n": [0, 0, 0], "ours_err": 0.0, "wl_err": 0.0, "awl_err": 0.0,
               "wl_ours": 0.0, "found": 0}
        for z, level in zip(zs, ours):
            mine = [lp.xy for lp in level]
            row["n"][0] += len(mine)
            for key, kind, k in (("wl", ocl.Waterline, 1), ("awl", ocl.AdaptiveWaterline, 2)):
                seconds, theirs = run_ocl(kind, surf, make, z, threads, ocl_step)
                row[key] += seconds / len(zs)
                row["n"][k] += len(theirs)
                if key == "awl":
                    row["found"] += found(theirs, mine)
                if not mine or not theirs:
                    continue
                ta, tb = segments(theirs)
                row[f"{key}_err"] = max(row[f"{key}_err"], distance_to_polylines(np.vstack(mine), ta, tb))
                oa, ob = segments(mine)
                d = distance_to_polylines(np.vstack(theirs), oa, ob)
                row["ours_err" if key == "awl" else "wl_ours"] = max(row["ours_err" if key == "awl" else "wl_ours"], d)
        rows.append(row)
        print(f"| {name} | {cname} | {row['levels']} | {row['tmm'] * 1e3:.1f} | {row['tmm1'] * 1e3:.1f} | "
              f"{row['wl'] * 1e3:.0f} | {row['awl'] * 1e3:.0f} | {row['wl'] / row['tmm']:.0f}x | "
              f"{row['awl'] / row['tmm']:.0f}x | {row['awl'] / row['tmm1']:.0f}x | "
              f"{row['n'][0]} / {row['n'][1]} / {row['n'][2]} | {row['ours_err']:.4f} / {row['wl_ours']:.4f} | "
              f"{row['wl_err']:.4f} | {row['awl_err']:.4f} | {row['found']} / {row['n'][2]} | "
              f"{'yes' if row['found'] == row['n'][2] and row['ours_err'] <= row['awl_err'] else 'no'} |", flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one level per case, the ball cutter only")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--step", type=float, default=STEP, help="our grid step, mm")
    ap.add_argument("--chord-tol", type=float, default=CHORD_TOL, help="our chord tolerance, mm")
    ap.add_argument("--min-step", type=float, default=None,
                    help="our adaptive grid's finest cell, mm (default: none, a uniform grid)")
    ap.add_argument("--all-tools", action="store_true", help="with --quick: ball, flat and bull")
    ap.add_argument("--ocl-step", type=float, default=STEP,
                    help="OpenCAMLib's fibre spacing, mm (AdaptiveWaterline's minimum: a tenth of it)")
    args = ap.parse_args()
    fractions = LEVEL_FRACTIONS[:1] if args.quick else LEVEL_FRACTIONS
    print(f"# waterline, TMM vs OpenCAMLib {ocl.version()} Waterline / AdaptiveWaterline, {args.threads} threads, "
          f"sampling {args.ocl_step:g} mm (AdaptiveWaterline min {args.ocl_step / 10:g} mm), our grid {args.step:g} mm "
          f"{'' if args.min_step is None else f'(adaptive down to {args.min_step:g} mm) '}"
          f"and chord tolerance {args.chord_tol:g} mm")
    print("| model | tool | levels | TMM ms/level (batch) | TMM ms (1 level) | WL ms/level | AWL ms/level | "
          "WL/TMM | AWL/TMM | AWL/TMM (1 level) | loops TMM / WL / AWL | our chord err vs AWL / WL pts (mm) | "
          "WL chord err (mm) | AWL chord err (mm) | AWL loops found | equal or better |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    models = [("sphere_on_plate.stl", load_stl(STL_DIR / "sphere_on_plate.stl")),
              ("mount_rush.stl", load_stl(STL_DIR / "mount_rush.stl")),
              ("height field 80k", height_field(200, False))]
    for name, mesh in models:
        case(name, mesh, args.threads, fractions, CUTTERS[:1] if args.quick and not args.all_tools else CUTTERS,
             args.step, args.chord_tol, args.ocl_step, args.min_step)


if __name__ == "__main__":
    main()
