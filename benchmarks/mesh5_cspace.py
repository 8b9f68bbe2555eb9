"""One pass of seed 000's 3D C-space on its convex (or concave) benchmark surface (tessellated), and a picture of one
CC point's C-space like the seed's Fig. 5-4 / 3-25.

    .venv/bin/python benchmarks/mesh5_cspace.py [--surface convex|concave] [--step 3] [--plane 0]
        [--half-step 2.5] [--png docs/mesh5_cspace.png]

Flat end mill D 0.5 in, tolerance 0.004 in (seed 000 section 5), the half step-over on each side given in mm.
Prints the pass's CC points, its compute time split (CC path, top bound, lifts) and the C-space statistics.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths, plane_offsets  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace  # noqa: E402
from tmm_workbench.core.strategies.mesh5.lift import MeshReach  # noqa: E402
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid  # noqa: E402
from tmm_workbench.core.strategies.mesh5.top_bound import profile_arcs, top_bounds  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def picture(cs, k: int, png: str, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    L, W = (np.degrees(g) for g in cs.grid.mesh())
    ok = cs.available[k]
    top = np.where(cs.top[k] >= 0, cs.top[k], np.nan)                    # S1 where it is above delta = 0
    bottom = np.where(np.isfinite(cs.lift[k]), cs.lift[k], np.nan)      # S2 everywhere
    fig = plt.figure(figsize=(11, 4.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot_surface(L, W, top, color="tab:orange", alpha=0.7, label="S1 top (tolerance)")
    ax.plot_surface(L, W, bottom, color="tab:blue", alpha=0.7, label="S2 bottom (gouge-free)")
    ax.set_xlabel("lambda (deg)")
    ax.set_ylabel("omega (deg)")
    ax.set_zlabel("delta (mm)")
    ax.set_title("C-space: between S2 (blue) and S1 (orange)")
    ax2 = fig.add_subplot(1, 2, 2)
    span = np.where(ok, cs.top[k] - cs.lift[k], np.nan)
    im = ax2.pcolormesh(W, L, span, shading="nearest")
    fig.colorbar(im, ax=ax2, label="delta range S1 - S2 (mm); blank: unavailable")
    ax2.set_xlabel("omega (deg)")
    ax2.set_ylabel("lambda (deg)")
    ax2.set_title("available postures")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"picture: {png}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--step", type=float, default=3.0, help="grid step (deg), the seed's 3")
    ap.add_argument("--plane", type=float, default=0.0, help="drive plane y (mm)")
    ap.add_argument("--half-step", type=float, default=2.5, help="half step-over each side (mm)")
    ap.add_argument("--forward", type=float, default=2.0, help="forward step (mm)")
    ap.add_argument("--surface", default="convex", choices=("convex", "concave"))
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter = Cutter.flat(0.5 * INCH)
    tol = 0.004 * INCH
    grid = PostureGrid.degrees(step=a.step)
    t0 = time.perf_counter()
    path = cc_paths(mesh, (1, 0), np.array([a.plane]), a.forward, 0.01)[0]
    t1 = time.perf_counter()
    reach = MeshReach(mesh)
    t_reach = time.perf_counter()
    lam, omg = (g.ravel() for g in grid.mesh())
    top = top_bounds(reach, cutter, path.points, path.frames, lam, omg, tol, a.half_step, profile_arcs(cutter, lam, omg))
    t2 = time.perf_counter()
    cs = build_cspace(reach, cutter, path.points, path.frames, grid, tol, a.half_step)
    t3 = time.perf_counter()
    n, P = len(path), lam.size
    asked = int((top >= 0).sum())
    print(f"seed 000 {a.surface}, {len(mesh)} triangles; flat D{cutter.diameter:.2f} mm, tolerance {tol:.4f} mm, "
          f"half step {a.half_step} mm; grid {grid.shape[0]} x {grid.shape[1]} = {P} postures ({a.step:g} deg)")
    print(f"pass y = {a.plane:g} mm: {n} CC points")
    print(f"| stage | s |\n|---|---|\n| CC path (drive plane) | {t1 - t0:.2f} |\n| mesh reach (KD-tree) | "
          f"{t_reach - t1:.2f} |\n| top bound S1 (all postures) | {t2 - t_reach:.2f} |\n| build_cspace (S1 again + "
          f"S2 for the {asked} of {n * P} postures with S1 >= 0) | {t3 - t2:.2f} |")
    av = cs.available.reshape(n, -1)
    print(f"available postures per CC point: min {av.sum(1).min()}, median {int(np.median(av.sum(1)))}, "
          f"max {av.sum(1).max()} of {P}; {cs.report()}")
    fine, _ = seed000_mesh(a.surface, nt=1221, ns=42)                       # ~100k triangles
    t4 = time.perf_counter()
    passes = cc_paths(fine, (1, 0), plane_offsets(fine, (1, 0), 2 * a.half_step), a.forward, 0.01)
    t5 = time.perf_counter()
    print(f"CC paths of every drive plane ({2 * a.half_step:g} mm apart) on a {len(fine)}-triangle tessellation: "
          f"{len(passes)} paths, {sum(len(p) for p in passes)} CC points in {t5 - t4:.2f} s")
    if a.png:
        k = n // 2
        full = build_cspace(reach, cutter, path.points[k:k + 1], path.frames[k:k + 1], grid, tol, a.half_step,
                            all_lifts=True)
        p = path.points[k]
        picture(full, 0, a.png, f"seed 000 {a.surface} surface, CC point ({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f}) mm; "
                f"flat D12.7, tolerance 0.1016 mm, half step {a.half_step} mm, {a.step:g} deg grid")


if __name__ == "__main__":
    main()
