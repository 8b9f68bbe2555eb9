"""The 'TMM 5-axis Mesh' op's work estimate against its run, and the simulation of what the finish leaves
(SimulateLeft: mesh5.cleanup.left_above) against the same simulation with the simulation's own sub-step: seed
000's surfaces with a flat end mill D 0.5 in (the main job's case: convex at 0.004 in).

    .venv/bin/python benchmarks/mesh5_estimate.py [--surface convex] [--tolerance-in 0.004] [--plan /tmp/p.pkl]
        [--no-old]
    (--plan: the linked path and the plan's figures saved there and read back, so the plan runs once;
    --no-old: without the simulation at the simulation's own sub-step, the slow one)
"""
from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tmm_workbench.core.footprint.rest import without_specks  # noqa: E402
from tmm_workbench.core.linking import link  # noqa: E402
from tmm_workbench.core.sim.simulate import max_tilt, simulate, sub_step  # noqa: E402
from tmm_workbench.core.strategies.mesh5 import cleanup, finish  # noqa: E402
from tmm_workbench.core.strategies.mesh5.estimate import surface_sample  # noqa: E402
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params  # noqa: E402
from tmm_workbench.core.strategies.multipoint import link_policy  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

PACE = {"mesh5": 0.025, "mesh5_left_cells": 2e-6, "mesh5_left_cut": 8e-7}   # app.work_estimate.PACE's rows


def planned(mesh, cutter, params, store: Path | None) -> dict:
    """The op's plan linked as the op links it, with its passes, CC points and wall / CPU seconds."""
    if store is not None and store.is_file():
        return pickle.loads(store.read_bytes())
    t0, c0 = time.perf_counter(), time.process_time()
    r = finish.compute(mesh, cutter, params)
    top = float(mesh.bounds[1][2])
    out = dict(path=link(r.segments, link_policy(cutter, top + 5.0, top + 15.0, 5.0)),
               strips=r.diagnostics["strip_corners"], passes=r.diagnostics["passes"], cc=r.diagnostics["cc_points"],
               wall=time.perf_counter() - t0, cpu=time.process_time() - c0)
    if store is not None:
        store.write_bytes(pickle.dumps(out))
    return out


def timed(f):
    t0, c0 = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - t0, time.process_time() - c0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--surface", default="convex", choices=("convex", "concave", "complex"))
    ap.add_argument("--tolerance-in", type=float, default=0.004)
    ap.add_argument("--plan", type=Path, default=None)
    ap.add_argument("--no-old", action="store_true")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter, tol = Cutter.flat(0.5 * INCH), a.tolerance_in * INCH
    params = Mesh5Params(tolerance=tol)
    lo, hi = mesh.bounds
    work, w_s, _ = timed(lambda: finish.estimate_work(params, cutter, (*lo, *hi), surface_sample(mesh), 0.25))
    box = finish.estimate_work(params, cutter, (*lo, *hi))
    paces = dict(work.paces)
    plan_s = paces["mesh5"] * PACE["mesh5"]
    left_s = sum(paces[k] * PACE[k] for k in ("mesh5_left_cells", "mesh5_left_cut"))
    p = planned(mesh, cutter, params, a.plan)
    print(f"{a.surface}, tolerance {tol:.4g} mm, flat D {cutter.diameter:g}")
    print("| | passes | CC points | plan s | SimulateLeft s |\n|---|---|---|---|---|")
    print(f"| estimate from the box (before) | {box.passes} | {box.count:.0f} | {box.count * 0.1:.0f} | |")
    print(f"| estimate from the needle sample ({w_s:.2f} s) | {work.passes} | {work.count:.0f} | {plan_s:.0f} | "
          f"{left_s:.0f} |")
    left, lw, lc = timed(lambda: cleanup.left_above(mesh, cutter, p["path"], tol, strips=p["strips"]))
    print(f"| run (wall / CPU) | {p['passes']} | {p['cc']} | {p['wall']:.1f} / {p['cpu']:.1f} | {lw:.1f} / {lc:.1f} |")
    print(f"\nleft_above: {left.above.sum()} cells above tau, {left.outside.sum()} outside the strips")
    if a.no_old:
        return
    grid, design, on = left.grid, left.design, np.isfinite(left.design)
    stock = np.where(on, design + max(cleanup.STOCK_ABOVE, 3 * tol), float(lo[2]) - 1.0)
    step = sub_step(cutter, tol, max_tilt(p["path"]))
    old, ow, oc = timed(lambda: simulate(p["path"], cutter, grid, stock, max_step=step).heights)
    above = without_specks(on & ((old - design) * left.cos > tol))
    print(f"the simulation's own sub-step {step:.4f} mm: {ow:.1f} s wall / {oc:.1f} s CPU (the simulation alone), "
          f"{above.sum()} cells above tau; the lead-tilt instances miss {(above & ~left.above).sum()}, find "
          f"{(left.above & ~above).sum()} more; heights differ by {np.nanmin((left.heights - old)[on]):.4f} .. "
          f"{np.nanmax((left.heights - old)[on]):.4f} mm")


if __name__ == "__main__":
    main()
