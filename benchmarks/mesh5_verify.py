"""The 5-axis mesh finish verified over the whole area by the 5-axis stock simulation (core.sim.simulate, the
kernel's sweep5): seed 000's convex surface at 0.004 in with a flat end mill D 0.5 in (the op's strategy,
core.strategies.mesh5.finish, linked as the op links it), cut from a stock 0.5 mm (or 3 tau, where more) above
the design; every cell of the grid compared with the design (the needle drop of core.sim.stock.mesh_heights):
the least deviation (a gouge below 0) and the largest remaining height along the normal (vertical deviation x
cos(slope)), inside the CC paths' area (cells within half the widest gap between planes of a CC point) and over
the whole surface; and the cells above tau + 0.002 mm outside the strips the plan lists for clean-up
(grown by a radius).

    .venv/bin/python benchmarks/mesh5_verify.py [--surface convex] [--cell 0.2] [--png docs/mesh5_verify.png]
        [--max-step 0.05] [--plan /tmp/plan.pkl] [--cleanup-diameter 6.35]
    (--plan: the cut segments saved there and read back, so the simulation can be rerun without the plan;
    --cleanup-diameter: the ball clean-up (mesh5.cleanup) after the 5-axis path, its note, and the same table
    after both)
"""
from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np
from scipy.ndimage import distance_transform_edt
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import mesh_heights  # noqa: E402
from tmm_workbench.core.strategies.mesh5 import cleanup, finish  # noqa: E402
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params  # noqa: E402
from tmm_workbench.core.strategies.multipoint import link_policy  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

STOCK_ABOVE = 0.5   # mm of stock over the design before the finish (as after a roughing)


def stock_above(tol: float) -> float:
    """mm of stock over the design: STOCK_ABOVE, or 3 tau where more (the complex surface at 0.03 in: tau
    0.762 mm; under 0.5 mm of stock no cell can read above tau, an uncut one included)."""
    return max(STOCK_ABOVE, 3.0 * tol)


def planned(mesh, cutter, tol: float, store: Path | None):
    """(segments, diagnostics without the plan object, seconds); from `store` when it exists."""
    if store is not None and store.is_file():
        return pickle.loads(store.read_bytes())
    t0 = time.perf_counter()
    result = finish.compute(mesh, cutter, Mesh5Params(tolerance=tol, forward_step=2.0, chord_tol=0.01))
    plan = result.diagnostics["plan"]
    offsets = [p.offset for p in plan.passes]
    cc = np.vstack([q.tips for p in plan.passes for q in p.postures])
    pts = np.vstack([path.points for p in plan.passes for path in p.paths])
    out = (result.segments, {"report": finish.report(result.diagnostics), "offsets": offsets, "cc": pts,
                             "cl": cc, "unfinished": list(plan.unfinished),
                             "strip_corners": result.diagnostics["strip_corners"]}, time.perf_counter() - t0)
    if store is not None:
        store.write_bytes(pickle.dumps(out))
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--surface", default="convex", choices=("convex", "concave", "complex"))
    ap.add_argument("--tolerance-in", type=float, default=0.004)
    ap.add_argument("--cell", type=float, default=0.2, help="simulation cell (mm)")
    ap.add_argument("--max-step", type=float, default=0.05, help="mm between the simulated tool instances (a flat "
                    "bottom tilted lambda to the surface along the travel leaves a sawtooth step x tan(lambda))")
    ap.add_argument("--plan", type=Path, default=None)
    ap.add_argument("--png", type=Path, default=None)
    ap.add_argument("--cleanup-diameter", type=float, default=None, help="ball clean-up after the 5-axis path (mm)")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter = Cutter.flat(0.5 * INCH)
    tol = a.tolerance_in * INCH
    segments, info, plan_s = planned(mesh, cutter, tol, a.plan)
    print(f"seed 000 {a.surface}, tau {tol:.4f} mm: {info['report']} (plan {plan_s:.1f} s)")
    lo, hi = mesh.bounds
    above = stock_above(tol)
    top = float(hi[2]) + above
    path = link(segments, link_policy(cutter, top + 5.0, top + 10.0, 5.0))
    grid = Grid.covering(float(lo[0]) - 1, float(lo[1]) - 1, float(hi[0]) + 1, float(hi[1]) + 1, a.cell)
    t0 = time.perf_counter()
    design = mesh_heights(mesh, grid)
    t1 = time.perf_counter()
    stock = np.where(np.isnan(design), float(lo[2]) - 1.0, design + above)
    sim = simulate(path, cutter, grid, stock, max_step=a.max_step)
    t2 = time.perf_counter()
    print(f"grid {grid.nx} x {grid.ny} cells of {a.cell:g} mm; design heights {t1 - t0:.1f} s, simulation "
          f"{t2 - t1:.1f} s (instances {a.max_step:g} mm apart, {sim.moves_cut} moves, rapids through stock "
          f"{len(sim.collisions)})")
    compare(a, grid, design, sim.heights, info, cutter, tol, a.png)
    if a.cleanup_diameter:
        ball = Cutter.ball(a.cleanup_diameter)
        t0 = time.perf_counter()
        segs, note = cleanup.cleanup(mesh, cutter, path, ball, tol, strips=info.get("strip_corners", ()),
                                     stock_above=above)
        t1 = time.perf_counter()
        print(f"{note.summary()} ({t1 - t0:.1f} s)")
        after = simulate(link(segs, LinkPolicy(top + 5.0, top + 10.0)), ball, grid, sim.heights.copy()).heights
        print(f"after the clean-up ({time.perf_counter() - t1:.1f} s):")
        png = a.png.with_name(a.png.stem + "_cleanup.png") if a.png else None
        compare(a, grid, design, after, info, cutter, tol, png, f" + ball D{a.cleanup_diameter:g} clean-up")


def compare(a, grid: Grid, design: np.ndarray, heights: np.ndarray, info: dict, cutter: Cutter, tol: float,
            png: Path | None, what: str = "") -> None:
    """The table of the simulated heights against the design (module doc), and the heat map to `png`."""
    dev = heights - design                                               # vertical, NaN off the surface
    gy, gx = np.gradient(design, grid.cell)
    cos = 1.0 / np.sqrt(1.0 + gx ** 2 + gy ** 2)
    # along the normal (locally planar); at the rim, where the slope is unknown, vertical
    normal = np.where(np.isfinite(cos), dev * cos, dev)
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    gap = float(np.max(np.diff(info["offsets"]))) if len(info["offsets"]) > 1 else cutter.diameter
    near, _ = cKDTree(info["cc"][:, :2]).query(np.column_stack([X.ravel(), Y.ravel()]),
                                               distance_upper_bound=0.5 * gap + 1e-9)
    inside = (np.isfinite(near).reshape(X.shape)) & np.isfinite(design)
    # the surface's own boundary rim (a cell whose needle hits the mesh's edge): a radius in from the box
    rows = []
    for name, mask in (("inside the CC paths' area", inside), ("whole surface", np.isfinite(design))):
        d, n = dev[mask], normal[mask]
        k = int(np.argmin(d))
        j = int(np.argmax(np.where(mask, normal, -np.inf)))
        rows.append((name, mask.sum(), d.min(), (X[mask][k], Y[mask][k]), n.max(), (X.flat[j], Y.flat[j]),
                     int((n > tol).sum()), int((n > tol + 0.002).sum()), int((d < -0.01).sum()),
                     int((n >= stock_above(tol) * 0.99).sum())))
    print("| area | cells | least deviation (mm, vertical) | at (x, y) | max scallop along the normal (mm) | at "
          "(x, y) | cells above tau | above tau + 0.002 | below -0.01 mm | uncut (stock left) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, cells, least, at, most, at2, over, over2, gouge, uncut in rows:
        print(f"| {name} | {cells} | {least:.4f} | ({at[0]:.1f}, {at[1]:.1f}) | {most:.4f} | ({at2[0]:.1f}, "
              f"{at2[1]:.1f}) | {over} | {over2} | {gouge} | {uncut} |")
    rim = distance_transform_edt(np.isfinite(design)) * grid.cell        # mm from the surface's boundary
    over = np.flatnonzero((normal > tol + 0.002).ravel() & inside.ravel())
    print(f"cells above tau + 0.002 mm: {len(over)}, of them within 1 mm of the surface's boundary "
          f"{int((rim.flat[over] <= 1.0).sum())}, within 3 mm {int((rim.flat[over] <= 3.0).sum())}")
    for i in over[np.argsort(-normal.flat[over])][:12]:
        print(f"  ({X.flat[i]:.1f}, {Y.flat[i]:.1f}): {normal.flat[i]:.4f} mm, {rim.flat[i]:.1f} mm from the boundary")
    strip = np.zeros(X.shape, dtype=bool)
    for f0, f1, c0, c1 in info.get("unfinished", ()):                   # listed for clean-up, grown by R
        g = cutter.radius
        strip |= (X >= f0 - g) & (X <= f1 + g) & (Y >= min(c0, c1) - g) & (Y <= max(c0, c1) + g)
    out = (normal > tol + 0.002) & np.isfinite(design) & ~strip
    print(f"above tau + 0.002 mm outside the {len(info.get('unfinished', ()))} strips listed for clean-up (grown by "
          f"R): {int(out.sum())}, of them more than 1 mm inside the boundary {int((out & (rim > 1.0)).sum())}")
    deep_out = np.flatnonzero((out & (rim > 1.0)).ravel())
    for i in deep_out[np.argsort(-normal.flat[deep_out])][:12]:
        print(f"  outside the strips, inside: ({X.flat[i]:.1f}, {Y.flat[i]:.1f}): {normal.flat[i]:.4f} mm, "
              f"{rim.flat[i]:.1f} mm from the boundary")
    deep = inside & (rim > 1.0)
    print(f"more than 1 mm inside the boundary: {deep.sum()} cells, max scallop {normal[deep].max():.4f} mm, "
          f"above tau + 0.002 mm {int((normal[deep] > tol + 0.002).sum())}, least {dev[deep].min():.4f} mm")
    n = normal[inside]
    for q in (50, 90, 99, 99.9):
        print(f"  scallop percentile {q}: {np.percentile(n, q):.4f} mm")
    if png:
        heat_map(png, grid, np.where(inside, normal, np.nan), tol, a.surface + what)
        print(f"wrote {png}")


def heat_map(png: Path, grid: Grid, normal: np.ndarray, tol: float, surface: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import TwoSlopeNorm

    fig, ax = plt.subplots(figsize=(8, 7.5), dpi=110)
    ext = (grid.x0, grid.x0 + grid.nx * grid.cell, grid.y0, grid.y0 + grid.ny * grid.cell)
    im = ax.imshow(normal, origin="lower", extent=ext, cmap="RdYlBu_r",
                   norm=TwoSlopeNorm(vmin=-0.02, vcenter=0.0, vmax=1.2 * tol))
    fig.colorbar(im, ax=ax, label="material left along the normal (mm); < 0: below the design")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(f"seed 000 {surface}: 5-axis finish, simulated (tau {tol:.4f} mm)")
    fig.tight_layout()
    fig.savefig(png)


if __name__ == "__main__":
    main()
