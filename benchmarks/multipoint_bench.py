"""Multipoint positioning speed (seed 001): DRD and VCRF on the seed's convex, concave and saddle patches, 1 and 2
threads, the seed's footprint (10 passes 0..150 mm, 2 mm forward step: 760 positions on the face).

    .venv/bin/python benchmarks/multipoint_bench.py            # VCRF on all 760 points, DRD on every 10th
    .venv/bin/python benchmarks/multipoint_bench.py --drd-all  # DRD on all points too (minutes)

Positions/s are wall clock; `cpu/s` is positions per CPU-second of the calling thread for 1 thread (per
core, unaffected by other processes on the machine). The ratio column is VCRF over DRD with the same thread
count; work/pos is the kernel's mean count of surface evaluations, sample tests and rays per position (a
load-independent measure of cost). Also printed: status counts, worst gap at P and Q, worst penetration found by the kernel's check, the
largest tilt, and how far the seed's global-X rotation of the axis is from the exact pseudo-insert one.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.strategies.multipoint import (BezierFace, MultipointParams, make_positioner,  # noqa: E402
                                           STATUS_NAMES)

Z = {"convex": [80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80],
     "concave": [80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80],
     "saddle": list(bezier.SEED_001_SADDLE_Z)}  # seed table 1
RO, RI = 6.7, 6.0


def seed_net(kind: str) -> np.ndarray:
    net = np.zeros((4, 4, 3))
    net[..., 0] = 50.0 * np.arange(4)[:, None]
    net[..., 1] = 50.0 * np.arange(4)[None, :]
    net[..., 2] = np.asarray(Z[kind], dtype=float).reshape(4, 4)
    return net


def seed_footprint() -> np.ndarray:
    """Seed 5.1: passes at x = 0, 18, ..., 144 and 150; 76 positions 2 mm apart on the face per pass
    (the seed's first and last of 78 only lift the tool)."""
    xs = list(np.arange(0.0, 150.0, 18.0)) + [150.0]
    ys = np.arange(0.0, 150.0 + 1e-9, 2.0)
    return np.array([(x, y) for x in xs for y in ys])


def run(face, method, xy, threads):
    mp = make_positioner(face, RO, RI, MultipointParams(), method)
    t0, c0 = time.perf_counter(), time.thread_time()
    r = mp.position_batch(xy, threads, None)
    wall, cpu = time.perf_counter() - t0, time.thread_time() - c0
    return r, len(xy) / wall, (len(xy) / cpu if threads == 1 and cpu > 0 else float("nan"))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--drd-all", action="store_true", help="run DRD on all points, not every 10th")
    args = ap.parse_args()
    xy = seed_footprint()
    print(f"seed footprint: {len(xy)} positions; tool Ro {RO} Ri {RI} (round insert)\n")
    head = (f"{'surface':8} {'method':6} {'thr':>3} {'n':>5} {'pos/s':>9} {'cpu/s':>9} {'VCRF/DRD':>9} "
            f"{'work/pos':>9}  status counts")
    print(head)
    print("-" * len(head))
    summary = {}
    for kind in ("convex", "concave", "saddle"):
        face = BezierFace.from_net(seed_net(kind), name=kind)
        speeds = {}
        for threads in (1, 2):
            for method in ("drd", "vcrf"):
                pts = xy if (method == "vcrf" or args.drd_all) else xy[::10]
                r, ps, cps = run(face, method, pts, threads)
                speeds[(method, threads)] = ps
                counts = {STATUS_NAMES[k]: int((r["status"] == k).sum()) for k in range(3)}
                ratio = f"{ps / speeds[('drd', threads)]:9.1f}" if method == "vcrf" else f"{'':9}"
                work = float(np.mean(r["evaluations"]))
                print(f"{kind:8} {method:6} {threads:3d} {len(pts):5d} {ps:9.0f} {cps:9.0f} {ratio} {work:9.0f}  {counts}")
                if threads == 1:
                    two = r["status"] == 0
                    summary[(kind, method)] = (
                        float(np.abs(r["gap_P"]).max()), float(np.abs(r["gap_Q"][two]).max(initial=0.0)),
                        float(r["penetration"].max()), math.degrees(float(r["beta"].max())),
                        math.degrees(float(r["seed_axis_angle"][two].max(initial=0.0))),
                        math.degrees(float(r["seed_axis_angle"][two].mean() if two.any() else 0.0)))
    print()
    print(f"{'surface':8} {'method':6} {'max|gapP|':>10} {'max|gapQ|':>10} {'max pen':>10} {'max tilt':>9} "
          f"{'seed axis err max/mean (deg)':>29}")
    for (kind, method), (gp, gq, pen, tilt, emax, emean) in summary.items():
        print(f"{kind:8} {method:6} {gp:10.2e} {gq:10.2e} {pen:10.2e} {tilt:8.2f}° {emax:14.2f} / {emean:.2f}")


if __name__ == "__main__":
    main()
