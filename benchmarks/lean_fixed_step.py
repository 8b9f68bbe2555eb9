"""Lean passes (issue 14 item 2): what a fixed-sample path needs to hold +-tol, and the least moves any line fit
can use. Core only (no FreeCAD): the README's demo jobs (scripts/demo.py's parameters, boundary the model's XY
box, zig-zag), the exact CL path from the kernel's drop-cutter.

  fixed step h   today's op (forward step "sample": a point every h, thinned above only by reduce_chords at
                 tol) at h = the demo's step, then halved until every cutting move holds +-1.05 tol of the exact path
                 (sampled every 0.01 mm; air and cliff corners left out, as benchmarks/lean_path.py)
  lean           the kernel fit (core.strategies.lean_kernel) from the demo's samples
  lower bound    the least lines any polyline within +-tol of the exact profile can use on the same runs (the
                 kernel's count of the fewest groups of consecutive exact drops each within tol of one line)

Run: .venv/bin/python benchmarks/lean_fixed_step.py [--quick] (sphere_on_plate only) [--cases a,b] [--lean-only]
(about 12 minutes in all, most of it mount_rush's fixed steps down to 0.003 mm)
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.strategies.lean_kernel import ExactDrop, lean_segments_kernel  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

TOL = 0.001
STEP = 0.01
CLIFF = 2e-3
HOLDS = 1.05  # x TOL: today's thinning (reduce_chords) alone may pass TOL above, its sampling a little more


def deviation(segments, surface: DropSurface, cutter: Cutter, floor: float, skip: bool) -> tuple[float, float]:
    pts = []
    for seg in segments:
        t = seg.tips
        for a, b in zip(t[:-1], t[1:]):
            length = math.hypot(*(b[:2] - a[:2]))
            if length < CLIFF:
                continue
            n = int(math.ceil(length / STEP))
            pts.append(a + (np.arange(n + 1)[:, None] / n) * (b - a))
    pts = np.vstack(pts)
    exact = surface.drop(cutter, pts[:, :2], floor - 1e6 if skip else floor)
    on = exact > floor - 1.0
    d = pts[on, 2] - np.maximum(exact[on], floor)
    return float(d.min()), float(d.max())


def moves(segments) -> int:
    return sum(max(0, len(s) - 1) for s in segments)


def main() -> None:
    from demo_jobs import load_demo

    demo = load_demo()

    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--cases", default="")
    ap.add_argument("--lean-only", action="store_true", help="the demo's step only, no halving (minutes less)")
    args = ap.parse_args()
    out = Path(tempfile.mkdtemp(prefix="tmm_lean_fixed_"))
    rows = []
    for case in demo.cases(out):
        if (args.quick and case.name != "sphere_on_plate") or (args.cases and case.name not in args.cases.split(",")):
            continue
        model = case.model or str(demo.bezier_stl(out))
        mesh = load_stl(model)
        p = case.params
        cutter = Cutter.ball(p["diameter"]) if p["tool"] == "ballend" else Cutter.bull(p["diameter"], p["corner_radius"])
        (x0, y0, _), (x1, y1, _) = mesh.bounds
        skip = p.get("off_model") == "skip"
        params = SurfaceParams(boundary=(float(x0), float(y0), float(x1), float(y1)), stepover=p["stepover"],
                               sample_step=p["sample_step"], angle_deg=p["angle_deg"], chord_tol=TOL,
                               off_model="skip" if skip else "floor")
        surface = DropSurface(mesh)
        floor = float(mesh.bounds[0][2])
        h = p["sample_step"]
        base = None
        while True:
            t0 = time.perf_counter()
            segs = compute(mesh, cutter, replace(params, sample_step=h), surface=surface).segments
            dt = time.perf_counter() - t0
            below, above = deviation(segs, surface, cutter, floor, skip)
            row = dict(case=case.name, label=f"fixed step {h:g}", moves=moves(segs), below=below, above=above, s=dt)
            base = base or row["moves"]
            rows.append(row)
            print(row, flush=True)
            if args.lean_only or max(-below, above) <= HOLDS * TOL or h < 0.005:
                break
            h /= 2
        # the lean fit (kernel) from the demo's unthinned samples, and the lower bound on the same runs
        t0 = time.perf_counter()
        sampled = compute(mesh, cutter, replace(params, chord_tol=0.0), surface=surface).segments
        exact = ExactDrop(surface.index, cutter, floor - 1e6 if skip else floor, 0.0, floor,
                          floor - 1e6 + 1.0 if skip else -math.inf)
        lean, st = lean_segments_kernel(sampled, exact, TOL, p["sample_step"] / 2, lower_bound=True)  # as raster_drop
        dt = time.perf_counter() - t0
        below, above = deviation(lean, surface, cutter, floor, skip)
        rows.append(dict(case=case.name, label="lean (kernel)", moves=moves(lean), below=below, above=above, s=dt,
                         lb=st["lower_bound"], stats=st))
        print(rows[-1], flush=True)
        rows[-1]["base"] = base
    print()
    print("| job | path | moves | dev below / above exact mm | s (core) | fixed step at the demo's / this |")
    print("|---|---|---|---|---|---|")
    first = {}
    for r in rows:
        first.setdefault(r["case"], r["moves"])
        print(f"| {r['case']} | {r['label']} | {r['moves']} | {r['below']:+.4f} / {r['above']:+.4f} | {r['s']:.2f} | "
              f"{first[r['case']] / r['moves']:.2f}x |")
        if "lb" in r:
            print(f"| {r['case']} | lower bound (lines within +-tol) | {r['lb']} | | | "
                  f"{first[r['case']] / max(r['lb'], 1):.2f}x |")


if __name__ == "__main__":
    main()
