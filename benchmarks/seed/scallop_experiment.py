"""Seed 001's three patches machined with the side step from a scallop height (issue 14 item 5) against the seed's
fixed 18 mm footprint: passes, the largest deviation at the section y = 27 mm (the z-map of
benchmarks.seed.experiment, refined at the peaks) and the deepest gouge, DRD and VCRF.

    .venv/bin/python benchmarks/seed/scallop_experiment.py [--scallop auto|0.5] [--options extend] [--surfaces ...]

Targets (issue 14 item 5): the section's max scallop no larger than the seed's simulated VCRF values (convex
0.53, concave 0.60, saddle 0.62 mm), no more passes than the seed's footprint (10), nothing below -0.01 mm.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from benchmarks.seed.experiment import (CONFIGS, GOUGE_LIMIT, PASSES_X, RI, RO, SEED_SIMULATED_MAX,  # noqa: E402
                                        run_experiment, seed_json_path)
from tmm_workbench.core.geometry.bezier import load_seed_patch  # noqa: E402
from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

SEED_PASSES = len(PASSES_X)


def scallop_case(which: str, method: str, scallop: float, options: dict):
    """The scallop placement on a seed patch (the seed's footprint boundary 0..150, forward step 2 mm, zigzag)
    and its section y = 27."""
    face = BezierFace.from_net(load_seed_patch(seed_json_path(), which), name=f"seed {which}")
    params = MultipointParams(pass_spacing="scallop", scallop=scallop, side_step=18.0, forward_step=2.0,
                              method=method, between_tol=0.0, **options)
    t0 = time.perf_counter()
    result = compute(face, Cutter.torus(RO, RI), params)
    t_place = time.perf_counter() - t0
    res, rep = result.diagnostics["results"], result.diagnostics["scallop"]
    passes = [res.xy[res.passes == k] for k in range(int(res.passes.max()) + 1)]
    sec = run_experiment(which, method, params=params, passes_x=rep.offsets, positions=(res, passes))
    return sec, rep, t_place


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scallop", default="auto",
                    help="scallop height, mm; auto: the surface's target (seed VCRF simulated max) less 0.02 mm")
    ap.add_argument("--options", default="extend", help=f"kernel option set, one of {', '.join(CONFIGS)}")
    ap.add_argument("--surfaces", default="convex,concave,saddle")
    ap.add_argument("--methods", default="drd,vcrf")
    ap.add_argument("--no-fixed", action="store_true", help="skip the seed's fixed footprint rows")
    args = ap.parse_args()
    options = CONFIGS[args.options]
    rows = []
    t_all = time.perf_counter()
    for which in args.surfaces.split(","):
        for method in args.methods.split(","):
            if not args.no_fixed:
                sec = run_experiment(which, method, params=MultipointParams(**options))
                rows.append((which, method, "fixed 18 mm", SEED_PASSES, sec, sec.time_s, None))
            h = SEED_SIMULATED_MAX[(which, "vcrf")] - 0.02 if args.scallop == "auto" else float(args.scallop)
            sec, rep, t = scallop_case(which, method, h, options)
            rows.append((which, method, f"scallop {h:g} mm", len(rep.offsets), sec, t, rep))
            print(f"  {which} {method}: {len(rep.offsets)} passes at "
                  f"{', '.join(f'{a:.2f}' for a in rep.offsets)}; scallop per strip "
                  f"{', '.join(f'{v:.3f}' for v in rep.scallops[1:])}; {rep.trials} trial passes, "
                  f"{rep.rows_skipped} rows not measured, unreached strips {rep.unreached}", flush=True)
    print(f"\noptions: {args.options} {options}; section y = 27 mm\n")
    print("| surface | method | footprint | passes | max dev at y = 27 (mm) | min dev (mm) | seed VCRF simulated "
          "max (mm) | max <= seed VCRF | passes <= 10 | min >= -0.01 | path time (s) |")
    print("|" + "---|" * 11)
    for which, method, label, n, sec, t, _ in rows:
        target = SEED_SIMULATED_MAX[(which, "vcrf")]
        print(f"| {which} | {method.upper()} | {label} | {n} | {sec.max_dev:.3f} (x = {sec.x_at_max:.2f}) "
              f"| {sec.min_dev:+.4f} (x = {sec.x_at_min:.2f}) | {target:.2f} "
              f"| {'yes' if sec.max_dev <= target else 'no'} | {'yes' if n <= SEED_PASSES else 'no'} "
              f"| {'yes' if sec.min_dev >= GOUGE_LIMIT else 'no'} | {t:.2f} |")
    print(f"\ntotal {time.perf_counter() - t_all:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
