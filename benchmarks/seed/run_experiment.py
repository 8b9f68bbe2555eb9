"""Seed 001's experiment (section 5.1) reproduced: VCRF and DRD multipoint tool paths on the convex and concave
bicubic patches (Ro 6.7 mm, Ri 6.0 mm, 10 passes, 18 mm side step with the 10th pass at x = 150, 2 mm forward
step), simulated with the z-map of core.zmap, deviations at the section y = 27 mm against the seed's Tables 2-3.
Each case runs with the kernel option sets of benchmarks.seed.experiment.CONFIGS: "seed" (as the seed describes it),
"extend" (the face continued past its edges by Ro + Ri) and "extend+tip" (that, and the tilted tip on the
footprint point).

    cd /work/wt-mp && .venv/bin/python benchmarks/seed/run_experiment.py [--configs seed,extend,extend+tip]

Prints the tables and writes docs/seed_experiment_section.png ("seed" options, DRD and VCRF) and
docs/seed_experiment_options.png (VCRF, every option set).
"""
from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.strategies.multipoint import MultipointParams  # noqa: E402
from benchmarks.seed.experiment import (CONFIGS, GOUGE_LIMIT, PASSES_X, SEED_MACHINED_MAX,  # noqa: E402
                                                SEED_SIMULATED_MAX, options_plot, run_experiment,
                                                section_plot)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", default=",".join(CONFIGS), help="comma-separated names from CONFIGS")
    args = ap.parse_args()
    names = [c for c in args.configs.split(",") if c]
    for c in names:
        if c not in CONFIGS:
            ap.error(f"unknown configuration {c!r}; known: {', '.join(CONFIGS)}")
    t0 = time.perf_counter()
    results = []
    for name in names:
        for which in ("convex", "concave"):
            for method in ("drd", "vcrf"):
                r = run_experiment(which, method, params=MultipointParams(**CONFIGS[name]))
                r.label = name
                results.append(r)
                res = r.results
                print(f"  {name:10s} {which:7s} {method:4s} done: positioning {r.time_s:.2f} s, z-map "
                      f"{r.sim_time_s:.1f} s, sub-step refinement x{r.refine} (last change "
                      f"{r.last_change * 1e3:.2f} um), max at x = {r.x_at_max:.3f}, min at x = {r.x_at_min:.3f}, "
                      f"needles {len(r.x)}; penetration max {res['penetration'].max():.1e} mm, into the real "
                      f"face {res['penetration_real'].max():.1e} mm; anchor error max "
                      f"{res['anchor_error'].max():.4f} mm; P / Q on the extension "
                      f"{int((res['on_extension'] & 1).sum())} / {int(((res['on_extension'] & 2) > 0).sum())}",
                      flush=True)
    print()
    print(f"machine: {platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, {platform.system()} {platform.release()}")
    hdr = (f"| options | surface | method | two-contact | one-contact | failed | max dev, whole section (mm) "
           f"| max dev, interior x 18..126 (mm) | min dev (mm) "
           f"| seed simulated max (mm) | max <= seed: whole / interior "
           f"| min >= {GOUGE_LIMIT} | path time (s) |")
    print(hdr)
    print("|" + "---|" * 13)
    for r in results:
        key = (r.which, r.method)
        s = r.statuses
        print(f"| {r.label} | {r.which} | {r.method.upper()} | {s['two']} | {s['one']} | {s['failed']} "
              f"| {r.max_dev:.3f} (x = {r.x_at_max:.2f}) | {r.max_dev_interior:.3f} (x = {r.x_at_max_interior:.2f}) "
              f"| {r.min_dev:+.4f} (x = {r.x_at_min:.2f}) | {SEED_SIMULATED_MAX[key]:.2f} "
              f"| {'yes' if r.max_dev <= SEED_SIMULATED_MAX[key] else 'no'} / "
              f"{'yes' if r.max_dev_interior <= SEED_SIMULATED_MAX[key] else 'no'} "
              f"| {'yes' if r.min_dev >= GOUGE_LIMIT else 'no'} | {r.time_s:.2f} |")
    print("\n(seed machined max: " + ", ".join(f"{w} {m.upper()} {v:.2f}" for (w, m), v in SEED_MACHINED_MAX.items())
          + ")")
    print("\nlargest deviation (mm) in each strip between consecutive passes:")
    edges = list(PASSES_X)
    print("| options | surface | method | " + " | ".join(f"{a:g}-{b:g}" for a, b in zip(edges[:-1], edges[1:])) + " |")
    print("|" + "---|" * (len(edges) + 2))
    for r in results:
        cells = []
        for a, b in zip(edges[:-1], edges[1:]):
            m = (r.x >= a) & (r.x <= b)
            cells.append(f"{r.deviation[m].max():.3f}")
        print(f"| {r.label} | {r.which} | {r.method.upper()} | " + " | ".join(cells) + " |")
    print("\npass tips at the section (mean tip x of the positions y = 26, 28; VCRF):")
    for r in results:
        if r.method != "vcrf":
            continue
        res = r.results
        tx = []
        for x in PASSES_X:
            m = (np.abs(res.xy[:, 0] - x) < 1e-9) & (np.abs(res.xy[:, 1] - 27.0) < 1.5)
            tx.append(f"{res['tip'][m, 0].mean():.2f}")
        print(f"  {r.label:10s} {r.which:7s}: " + " ".join(tx))
    seed_results = [r for r in results if r.label == "seed"]
    if seed_results:
        out = section_plot(seed_results, ROOT / "docs" / "seed_experiment_section.png")
        print(f"\nplot: {out.relative_to(ROOT)}")
    if len(names) > 1:
        out = options_plot(results, ROOT / "docs" / "seed_experiment_options.png", "vcrf")
        print(f"plot: {out.relative_to(ROOT)}")
    print(f"total {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
