"""Seed 001's experiment (section 5.1) reproduced: VCRF and DRD multipoint tool paths on the convex and concave
bicubic patches (Ro 6.7 mm, Ri 6.0 mm, 10 passes, 18 mm side step with the 10th pass at x = 150, 2 mm forward
step), simulated with the z-map of core.zmap, deviations at the section y = 27 mm against the seed's Tables 2-3.

    cd /work/main && .venv/bin/python benchmarks/seed_experiment.py

Prints the table and writes docs/seed_experiment_section.png.
"""
from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.seed_experiment import (GOUGE_LIMIT, PASSES_X, SEED_MACHINED_MAX,  # noqa: E402
                                                SEED_SIMULATED_MAX, run_experiment, section_plot)


def main() -> int:
    t0 = time.perf_counter()
    results = []
    for which in ("convex", "concave"):
        for method in ("drd", "vcrf"):
            r = run_experiment(which, method)
            results.append(r)
            print(f"  {which:7s} {method:4s} done: positioning {r.time_s:.2f} s, z-map {r.sim_time_s:.1f} s, "
                  f"sub-step refinement x{r.refine} (last change {r.last_change * 1e3:.2f} um), "
                  f"max at x = {r.x_at_max:.3f}, min at x = {r.x_at_min:.3f}, needles {len(r.x)}", flush=True)
    print()
    print(f"machine: {platform.machine()} {platform.processor() or ''} {os.cpu_count()} cores, "
          f"Python {platform.python_version()}, {platform.system()} {platform.release()}")
    hdr = (f"| surface | method | positions | two-contact | one-contact | failed | max dev (mm) "
           f"| max dev, interior strips (mm) | min dev (mm) "
           f"| seed simulated max (mm) | seed machined max (mm) | max <= seed (whole / interior) "
           f"| min >= {GOUGE_LIMIT} | path time (s) |")
    print(hdr)
    print("|" + "---|" * 14)
    for r in results:
        key = (r.which, r.method)
        s = r.statuses
        print(f"| {r.which} | {r.method.upper()} | {r.n_positions} | {s['two']} | {s['one']} | {s['failed']} "
              f"| {r.max_dev:.3f} (x = {r.x_at_max:.2f}) | {r.max_dev_interior:.3f} (x = {r.x_at_max_interior:.2f}) "
              f"| {r.min_dev:+.4f} (x = {r.x_at_min:.2f}) | {SEED_SIMULATED_MAX[key]:.2f} "
              f"| {SEED_MACHINED_MAX[key]:.2f} "
              f"| {'yes' if r.max_dev <= SEED_SIMULATED_MAX[key] else 'no'} / "
              f"{'yes' if r.max_dev_interior <= SEED_SIMULATED_MAX[key] else 'no'} "
              f"| {'yes' if r.min_dev >= GOUGE_LIMIT else 'no'} | {r.time_s:.2f} |")
    print("\nlargest deviation (mm) in each strip between consecutive passes:")
    edges = list(PASSES_X)
    print("| surface | method | " + " | ".join(f"{a:g}-{b:g}" for a, b in zip(edges[:-1], edges[1:])) + " |")
    print("|" + "---|" * (len(edges) + 1))
    for r in results:
        cells = []
        for a, b in zip(edges[:-1], edges[1:]):
            m = (r.x >= a) & (r.x <= b)
            cells.append(f"{r.deviation[m].max():.3f}")
        print(f"| {r.which} | {r.method.upper()} | " + " | ".join(cells) + " |")
    out = section_plot(results, ROOT / "docs" / "seed_experiment_section.png")
    print(f"\nplot: {out.relative_to(ROOT)}; total {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
