"""Where the 3D offset's simulated cusp exceeds the tolerance, and why (issue 14 item 1, third bullet; item 7).

The path is made and measured exactly as `benchmarks/cusp_spacing.py --offset3d-only` does (its functions, the same
cusp field), then every measured cell above the tolerance is classified at the CL point whose tool cuts it (the
cell plus core.sim.cusp_field's contact offset), where the arrival field T lives, by the first cause that applies:

- border: within the tool radius + one flat step of the region's edge (the outer passes, their ends);
- ridge of T: the front's direction turns by more than 30 deg across three cells (a convex corner's bisector, two
  fronts meeting, a hilltop: where the half level and the corner spikes are cut);
- concave: the CL section along grad T bends up with R k above 0.05 over a quarter of a flat step either side
  (detail the rule's probe over half a step smooths);
- slope: the CL surface's slope along grad T above 10 deg (the planar rule at the slope, chords on a slope);
- other (a plane's first-order marching and 0.25 mm chords).

    .venv/bin/python benchmarks/offset3d_where.py --quick      # sphere_on_plate
    .venv/bin/python benchmarks/offset3d_where.py              # and mount_rush, seed 000's windows
    .venv/bin/python benchmarks/offset3d_where.py --only convex,concave --window 0   # seed 000's whole surfaces
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from cusp_spacing import SLOPE_LIMIT, cycle, raster  # noqa: E402

from tmm_workbench.core.footprint import offset_field  # noqa: E402
from tmm_workbench.core.footprint.region import box_region  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.strategies.surface.reference import cusp_field  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CAUSES = ("border", "ridge of T", "concave", "slope", "other")


def where(name, mesh, cutter: Cutter, tol: float, cell: float, boundary=None) -> list[str]:
    lo, hi = mesh.bounds
    if boundary is None:
        boundary = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    field = cusp_field(mesh, cutter, boundary, tol, cell, SLOPE_LIMIT, sample_step=0.25)
    path, secs, n = raster(mesh, cutter, boundary, stepover_mode="offset3d", cusp=tol, max_slope_deg=SLOPE_LIMIT)
    cusp = field.cusp(field.cut(path, cutter))
    measured = np.isfinite(cusp)
    above = measured & (cusp > tol)
    # the arrival field as the strategy made it (same region, heights and rule)
    surface = DropSurface(mesh)
    floor = float(lo[2])
    heights = lambda xy: np.maximum(surface.drop(cutter, xy, floor), floor)  # noqa: E731
    t, rule = offset_field.arrival(box_region(boundary), heights, cutter, tol, SLOPE_LIMIT)
    flat = rule.flat
    xs, ys = field.grid.xs(), field.grid.ys()
    gx, gy = np.meshgrid(xs, ys)
    tip = np.stack([gx, gy], axis=2) + field.contact_offset(cutter)
    p = tip[above]
    g = t.gradient(p)
    gn = np.hypot(*g.T)
    u = g / np.where(gn > 0, gn, 1.0)[:, None]
    # ridge: the front's direction 1.5 cells either side of p, across and along
    h = 1.5 * (t.xs[1] - t.xs[0])
    turn = np.zeros(len(p))
    for d in (np.array([1.0, 0.0]), np.array([0.0, 1.0])):
        ga, gb = t.gradient(p + h * d), t.gradient(p - h * d)
        na, nb = np.hypot(*ga.T), np.hypot(*gb.T)
        with np.errstate(invalid="ignore", divide="ignore"):
            cosang = (ga * gb).sum(axis=1) / (na * nb)
        turn = np.maximum(turn, np.where(np.isfinite(cosang), np.degrees(np.arccos(np.clip(cosang, -1, 1))), 180.0))
    a = 0.25 * flat
    z0, zf, zb = heights(p), heights(p + a * u), heights(p - a * u)
    grad = (zf - zb) / (2 * a)
    rk = cutter.radius * (zf - 2 * z0 + zb) / (a * a) / (1 + grad * grad) ** 1.5
    slope = np.degrees(np.arctan(np.abs(grad)))
    box = np.array(boundary)
    edge = np.minimum.reduce([p[:, 0] - box[0], box[2] - p[:, 0], p[:, 1] - box[1], box[3] - p[:, 1]])
    cause = np.full(len(p), 4)
    cause[slope > 10] = 3
    cause[rk > 0.05] = 2
    cause[turn > 30] = 1
    cause[edge < cutter.radius + flat] = 0
    excess = cusp[above] - tol
    out = [f"\n{name}: {n} loops, max cusp {np.nanmax(cusp):.4f} mm (tol {tol:g}), "
           f"{above.sum() / measured.sum():.3%} of {measured.sum()} measured cells above, "
           f"{(cusp > 1.1 * tol).sum() / measured.sum():.3%} above 1.1 x, cycle {cycle(path) / 60:.1f} min, "
           f"compute {secs:.1f} s",
           "| cause | cells above | share of those | largest cusp mm |", "|---|---|---|---|"]
    for k, c in enumerate(CAUSES):
        m = cause == k
        big = f"{tol + excess[m].max():.4f}" if m.any() else "-"
        out.append(f"| {c} | {int(m.sum())} | {m.mean() if len(m) else 0:.0%} | {big} |")
    if len(p):
        worst = int(np.argmax(excess))
        t_worst = float(t.at(p[worst:worst + 1])[0])
        out.append(f"worst cell at CL ({p[worst, 0]:.2f}, {p[worst, 1]:.2f}): T {t_worst:.2f}, "
                   f"turn {turn[worst]:.0f} deg, R k {rk[worst]:.3f}, slope {slope[worst]:.1f} deg, "
                   f"{edge[worst]:.1f} mm from the edge")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="sphere_on_plate only")
    ap.add_argument("--only", default="", help="comma-separated: sphere_on_plate, mount_rush, convex, concave")
    ap.add_argument("--window", type=float, default=100.0, help="seed 000: the square region's side, mm (0: whole)")
    args = ap.parse_args()
    only = set(filter(None, args.only.split(",")))
    stl = shared_dir() / "benchmarks" / "stl"
    t0 = time.perf_counter()
    for name in ("sphere_on_plate", "mount_rush"):
        if (only and name not in only) or (args.quick and name != "sphere_on_plate"):
            continue
        print("\n".join(where(name, load_stl(stl / f"{name}.stl"), Cutter.ball(6.0), 0.01, 0.1)), flush=True)
    if args.quick:
        return
    from seed000_surfaces import INCH, seed000_mesh
    for name in ("convex", "concave"):
        if only and name not in only:
            continue
        mesh, _ = seed000_mesh(name)
        lo, hi = mesh.bounds
        c, h = 0.5 * (lo + hi), 0.5 * args.window
        region = (float(c[0] - h), float(c[1] - h), float(c[0] + h), float(c[1] + h)) if args.window else None
        where_ = f"{args.window:g} mm window" if args.window else "whole"
        print("\n".join(where(f"seed 000 {name}, {where_}", mesh, Cutter.ball(0.5 * INCH), 0.002 * INCH, 0.2,
                              region)), flush=True)
    print(f"\n# {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
