"""Independent check of the z-map's reading of a scallop cusp in seed 001's experiment.

Two passes of the seed footprint (feed y = 0..60) are positioned and simulated by benchmarks.seed.experiment as in
the full run; then, around the cusp between them on the section y = 27, the lowest point of the swept tool on
each vertical needle is found another way: the motion re-interpolated here (tip linear, axis slerp, 100
sub-steps per 2 mm move, 0.02 mm), and on each needle z scanned every 0.002 mm with the kernel's signed
distance to the tool (not the z-map's closed-form line-torus solve), the first point inside bisected to 1e-9.

    cd /work/wt-mp && .venv/bin/python benchmarks/seed/cusp_check.py concave 18 36 25.86 [axis|tip] [extend_mm]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from benchmarks.seed import experiment as se  # noqa: E402
from tmm_workbench.core.geometry.bezier import load_seed_patch  # noqa: E402
from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams, make_positioner  # noqa: E402


def slerp(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    w = float(np.arccos(np.clip(a @ b, -1.0, 1.0)))
    if w < 1e-12:
        return a
    return (np.sin((1 - t) * w) * a + np.sin(t * w) * b) / np.sin(w)


def main() -> int:
    which, lo, hi, xc = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    anchor = sys.argv[5] if len(sys.argv) > 5 else "axis"
    extend = float(sys.argv[6]) if len(sys.argv) > 6 else 0.0
    params = MultipointParams(anchor=anchor, extend=extend)
    y_sec = 27.0
    r = se.run_experiment(which, "vcrf", params=params, passes_x=(lo, hi), y_range=(0.0, 60.0), x_range=(lo, hi),
                          spacing=0.5, section_y=y_sec)
    net = load_seed_patch(se.seed_json_path(), which)
    mp = make_positioner(BezierFace.from_net(net), se.RO, se.RI, params)
    res = r.results
    n = len(res.xy) // 2
    instances = []
    for p in range(2):
        tips, axes = res["tip"][p * n:(p + 1) * n], res["axis"][p * n:(p + 1) * n]
        for k in range(n - 1):
            if min(tips[k, 1], tips[k + 1, 1]) > y_sec + 14 or max(tips[k, 1], tips[k + 1, 1]) < y_sec - 14:
                continue
            for t in np.linspace(0.0, 1.0, 101):
                instances.append(((1 - t) * tips[k] + t * tips[k + 1], slerp(axes[k], axes[k + 1], t)))
    xs = np.arange(xc - 0.06, xc + 0.0601, 0.005)
    zd = se.design_height(net, xs, np.full_like(xs, y_sec))
    t0 = time.perf_counter()
    dev = []
    for x, z0 in zip(xs, zd):
        zz = np.arange(z0 - 0.1, z0 + 1.5, 0.002)
        pts = np.column_stack([np.full_like(zz, x), np.full_like(zz, y_sec), zz])
        zlow = np.inf
        for tip, ax in instances:
            inside = np.flatnonzero(mp.tool_distance(tip, ax, pts) <= 0)
            if len(inside) == 0 or zz[inside[0]] >= zlow:
                continue
            j = inside[0]
            a, b = (zz[j - 1] if j > 0 else zz[j] - 0.002), zz[j]
            while b - a > 1e-9:
                m = 0.5 * (a + b)
                if mp.tool_distance(tip, ax, np.array([[x, y_sec, m]]))[0] <= 0:
                    b = m
                else:
                    a = m
            zlow = min(zlow, b)
        dev.append(zlow - z0)
    dev = np.array(dev)
    i = int(np.argmax(dev))
    print(f"{which}, passes x = {lo:g}, {hi:g}, anchor {anchor}, extend {extend:g}: z-map max {r.max_dev:.5f} mm at "
          f"x = {r.x_at_max:.4f}; brute force max {dev[i]:.5f} mm at x = {xs[i]:.4f} ({len(instances)} tool "
          f"instances, {time.perf_counter() - t0:.0f} s); difference {dev[i] - r.max_dev:+.2e} mm")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
