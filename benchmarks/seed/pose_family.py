"""Can another two-contact pose, or another anchor, meet the seed's convex scallop (VCRF simulated 0.53 mm)
on the edge strip 0-18 of seed 001's experiment? (issue 4; docs/seed_experiment.md, "Other poses")

A. The pose family. At a footprint point the multipoint pose has one free choice once the anchor is fixed: the
   tool's orientation before the drop, which decides the first contact P and so the pseudo-insert the tool is
   tilted about. The seed starts vertical. Here the tool starts with a lead angle (axis leaning along the feed,
   towards -y for lead > 0) or a side angle (leaning across it, towards the face's middle for side > 0), is
   dropped vertically (exact line-tool solves of core.zmap on a 0.12 mm grid of the design surface), and is
   tilted about the pseudo-insert axis through P (the exact rotation of the kernel) until any surface point
   farther than 1.5 mm from P touches it (bisection to 1e-4 mm). Passes x = 0 and 18, positions y = 10..44
   every 2 mm (every position whose tool reaches the section y = 27), simulated by core.zmap (0.05 mm needles,
   sub-steps halved to 1e-3 mm). Lead 0, side 0 is the seed's pose and reproduces the kernel's tips to 0.01 mm.
B. The anchor, as the passes' tip spacing: the kernel (VCRF, tip anchor, face extended by Ro + Ri) with pass 0
   at x = 0 and the next one at x = s; the largest deviation between them on the section (the full experiment's
   z-map, feed y = 0..60). The seed's axis anchor puts the tips of passes 0 and 18 17.63 mm apart.

    .venv/bin/python benchmarks/seed/pose_family.py [--part A|B|AB]     # about 7 min (A) + 1 min (B)
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from benchmarks.seed import experiment as se  # noqa: E402
from tmm_workbench.core.geometry.bezier import load_seed_patch  # noqa: E402
from tmm_workbench.core.strategies.multipoint import MultipointParams  # noqa: E402
from tests.core.zmap_reference import ZTool, lowest_z, simulate  # noqa: E402

GRID = 0.12          # mm, design-surface samples under the tool
NEAR_P = 1.5         # mm: a second contact must lie farther than this from P
TOUCH = 1e-4         # mm: what counts as touching in the tilt bisection
LEADS_SIDES = [(0, 0), (-10, 0), (-5, 0), (5, 0), (10, 0), (0, -5), (0, 5), (0, 10)]


class PoseFamily:
    def __init__(self, which: str) -> None:
        self.net = load_seed_patch(se.seed_json_path(), which)
        self.tool = ZTool(se.RO, se.RI)

    def height(self, x, y):
        return se.design_height(self.net, x, y)

    def samples(self, x: float, y: float):
        r = se.RO + se.RI + 0.3
        g = np.arange(-r, r + 1e-9, GRID)
        X, Y = np.meshgrid(x + g, y + g)
        keep = ((X - x) ** 2 + (Y - y) ** 2 <= r * r) & (X >= 0) & (X <= 150) & (Y >= 0) & (Y <= 150)
        X, Y = X[keep], Y[keep]
        return np.column_stack([X, Y]), self.height(X, Y)

    def lift(self, tip, a, xy, z):
        """Surface height above the tool's lowest point on each needle (> 0: inside the tool)."""
        n = len(xy)
        return z - lowest_z(self.tool, np.broadcast_to(tip, (n, 3)), np.broadcast_to(a, (n, 3)), xy)

    def position(self, x: float, y: float, a0: np.ndarray, beta_max: float = math.pi / 4):
        xy, z = self.samples(x, y)
        a = a0 / np.linalg.norm(a0)
        tip = np.array([x, y, 0.0])
        lift = self.lift(tip, a, xy, z)
        i = int(np.argmax(lift))
        tip = tip + np.array([0.0, 0.0, lift[i]])
        P = np.array([xy[i, 0], xy[i, 1], z[i]])
        centre = tip + se.RI * a
        e = P - centre
        e -= (e @ a) * a
        e /= np.linalg.norm(e)
        O1 = centre + se.RO * e           # the pseudo-insert's centre (on the major circle)
        u1 = np.cross(a, e)
        far = np.hypot(xy[:, 0] - P[0], xy[:, 1] - P[1]) > NEAR_P

        def pose(b: float):
            return O1 + _rotate(tip - O1, u1, -b), _rotate(a, u1, -b)

        def touches(b: float) -> bool:
            t, aa = pose(b)
            lf = self.lift(t, aa, xy, z)
            return lf[~far].max() > 0.02 or lf[far].max() > TOUCH

        lo, hi = 0.0, None
        for b in np.arange(0.02, beta_max + 1e-9, 0.02):
            if touches(b):
                hi = b
                break
            lo = b
        if hi is None:
            return pose(beta_max)
        for _ in range(25):
            m = 0.5 * (lo + hi)
            lo, hi = (lo, m) if touches(m) else (m, hi)
        return pose(lo)

    def strip(self, x0: float, x1: float, lead: float, side: float, section_y: float = 27.0):
        paths = []
        for x in (x0, x1):
            inward = 1.0 if x < 75 else -1.0
            a0 = np.array([inward * math.sin(side) * math.cos(lead), -math.sin(lead), math.cos(side) * math.cos(lead)])
            poses = [self.position(x, y, a0) for y in np.arange(10.0, 46.0, 2.0)]
            paths.append((np.array([p[0] for p in poses]), np.array([p[1] for p in poses])))
        xs = np.arange(x0, x1 + 1e-9, 0.05)
        zd = self.height(xs, np.full_like(xs, section_y))
        rep = simulate(self.tool, np.column_stack([xs, np.full_like(xs, section_y)]), zd.max() + 5, paths, 0.25,
                       "slerp", 1e-3)
        dev = rep.z - zd
        k = int(np.argmax(dev))
        tip_x = [float(np.interp(26.0, np.arange(10.0, 46.0, 2.0), p[0][:, 0])) for p in paths]
        return float(dev[k]), float(xs[k]), float(dev.min()), tip_x


def _rotate(v: np.ndarray, k: np.ndarray, t: float) -> np.ndarray:
    k = k / np.linalg.norm(k)
    return v * math.cos(t) + np.cross(k, v) * math.sin(t) + k * (k @ v) * (1 - math.cos(t))


def part_a() -> None:
    fam = PoseFamily("convex")
    print("A. convex, strip 0-18, section y = 27: start orientation -> largest deviation")
    print("| lead (deg) | side (deg) | tip x at y = 26, passes 0 / 18 | max dev (mm) | at x | min dev (mm) | s |")
    print("|---|---|---|---|---|---|---|")
    for lead, side in LEADS_SIDES:
        t0 = time.perf_counter()
        mx, xm, mn, tips = fam.strip(0.0, 18.0, math.radians(lead), math.radians(side))
        print(f"| {lead} | {side} | {tips[0]:.2f} / {tips[1]:.2f} | {mx:.3f} | {xm:.2f} | {mn:+.4f} | "
              f"{time.perf_counter() - t0:.0f} |", flush=True)


def part_b() -> None:
    print("B. kernel, VCRF, tip anchor, extend Ro + Ri: passes x = 0 and s -> largest deviation between them")
    print("| surface | s (mm) | max dev (mm) | at x |")
    print("|---|---|---|---|")
    params = MultipointParams(extend=se.RO + se.RI, anchor="tip")
    for which in ("convex", "concave"):
        for s in (17.0, 17.25, 17.5, 17.63, 18.0):
            r = se.run_experiment(which, "vcrf", params=params, passes_x=(0.0, s), y_range=(0.0, 60.0),
                                  x_range=(0.0, s))
            print(f"| {which} | {s:.2f} | {r.max_dev:.3f} | {r.x_at_max:.2f} |", flush=True)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", default="AB", choices=["A", "B", "AB"])
    args = ap.parse_args()
    if "B" in args.part:
        part_b()
    if "A" in args.part:
        part_a()
    return 0


if __name__ == "__main__":
    sys.exit(main())
