"""A picture of one CC point's 3D C-space as seed 000's Fig. 5-4 draws it: over the whole (lambda, omega) grid, the
bottom surface S2 (the least lift that clears every triangle) and the top surface S1 (the largest lift within
the tolerance, eq. 3.82-3.84), unclipped, and the available set between them (S2 <= delta <= S1); beside it, cuts
at constant omega (the seed: "when omega is constant, delta decreases while lambda increases") and at lambda =
45 deg (the seed: "when lambda is 0.25 pi, the maximum delta occurs while omega is 0").

    .venv/bin/python benchmarks/mesh5_cspace_figure.py [--surface concave] [--plane 0] [--half-step 1.5]
        [--png docs/mesh5_cspace_fig54.png]

Flat end mill D 0.5 in, tolerance 0.004 in, the seed's grid (lambda 0..45, omega -45..45 deg, 3 deg); the CC
point in the middle of the drive plane y = `--plane`. Prints the seed's two statements checked on the grid.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths  # noqa: E402
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace  # noqa: E402
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def checks(L: np.ndarray, W: np.ndarray, top: np.ndarray) -> None:
    """The seed's two statements about S1, on the grid."""
    last = top[-1]
    print(f"lambda = {L[-1, 0]:.0f} deg: S1 is largest at omega = {W[-1, int(np.argmax(last))]:.0f} deg "
          f"({last.max():.4f} mm; at omega = +-45 deg {last[0]:.4f} / {last[-1]:.4f} mm)")
    falls = np.diff(top, axis=0) <= 1e-9
    print(f"S1 falls (or stays) as lambda grows, at constant omega: {falls.sum()} of {falls.size} grid steps "
          f"({np.all(falls, axis=0).sum()} of {top.shape[1]} omegas throughout)")


def picture(L, W, top, bottom, png: str, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = bottom <= top
    top = np.where(np.isfinite(top), top, np.nan)                        # no lift within the tolerance: not drawn
    fig = plt.figure(figsize=(14.5, 5.0))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    ax.plot_surface(L, W, top, color="tab:orange", alpha=0.55)
    ax.plot_surface(L, W, np.where(np.isfinite(bottom), bottom, np.nan), color="tab:blue", alpha=0.7)
    ax.scatter(L[ok], W[ok], top[ok], color="tab:green", s=6)
    ax.set_xlabel("lambda (deg)")
    ax.set_ylabel("omega (deg)")
    ax.set_zlabel("delta (mm)")
    ax.set_title("S1 top (orange), S2 bottom (blue);\ngreen: available (S2 <= S1)", fontsize=9)
    ax.view_init(elev=22, azim=-60)
    ax2 = fig.add_subplot(1, 3, 2)
    for j, c in zip((len(W[0]) // 2, len(W[0]) // 2 + 5, len(W[0]) - 1), ("tab:green", "tab:purple", "tab:red")):
        w = W[0, j]
        ax2.plot(L[:, j], top[:, j], color=c, label=f"S1, omega {w:.0f} deg")
        ax2.plot(L[:, j], bottom[:, j], color=c, linestyle="--", label=f"S2, omega {w:.0f} deg")
        ax2.fill_between(L[:, j], bottom[:, j], top[:, j], where=ok[:, j], color=c, alpha=0.25)
    ax2.axhline(0.0, color="grey", linewidth=0.6)
    ax2.set_xlabel("lambda (deg)")
    ax2.set_ylabel("delta (mm)")
    ax2.set_title("constant omega (shaded: available)", fontsize=9)
    ax2.legend(fontsize=7)
    ax3 = fig.add_subplot(1, 3, 3)
    for i, c in zip((0, 2, len(L) - 1), ("tab:green", "tab:purple", "tab:red")):
        ax3.plot(W[i], top[i], color=c, label=f"S1, lambda {L[i, 0]:.0f} deg")
        ax3.plot(W[i], bottom[i], color=c, linestyle="--", label=f"S2, lambda {L[i, 0]:.0f} deg")
    ax3.set_xlabel("omega (deg)")
    ax3.set_ylabel("delta (mm)")
    ax3.set_title("constant lambda", fontsize=9)
    ax3.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(w_pad=4.0)
    fig.savefig(png, dpi=100)
    print(f"picture: {png}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--surface", default="concave", choices=("convex", "concave", "complex"))
    ap.add_argument("--plane", type=float, default=0.0, help="drive plane y (mm)")
    ap.add_argument("--half-step", type=float, default=1.5, help="half step-over each side (mm)")
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    cutter = Cutter.flat(0.5 * INCH)
    tol = 0.004 * INCH
    grid = PostureGrid.degrees()
    path = cc_paths(mesh, (1, 0), np.array([a.plane]), 2.0, 0.01)[0]
    k = len(path) // 2
    cs = build_cspace(mesh, cutter, path.points[k:k + 1], path.frames[k:k + 1], grid, tol, a.half_step,
                      all_lifts=True)
    L, W = (np.degrees(g) for g in grid.mesh())
    top, bottom = cs.top[0], cs.lift[0]                                 # -inf: no lift within the tolerance
    p = path.points[k]
    print(f"seed 000 {a.surface}, CC point ({p[0]:.1f}, {p[1]:.1f}, {p[2]:.2f}) mm, half step {a.half_step} mm: "
          f"{int(cs.available[0].sum())} of {top.size} postures available; S2 {np.nanmin(bottom):.4f}.."
          f"{np.nanmax(bottom[np.isfinite(bottom)]):.4f} mm, S1 {top.min():.4f}..{top.max():.4f} mm "
          f"(-inf: {int(np.isneginf(top).sum())} postures no lift brings within the tolerance)")
    checks(L, W, top)
    if a.png:
        picture(L, W, top, bottom, a.png, f"seed 000 {a.surface} surface, CC point ({p[0]:.1f}, {p[1]:.1f}, "
                f"{p[2]:.1f}) mm: flat D 12.7 mm, tolerance 0.1016 mm, half step {a.half_step} mm, 3 deg grid")


if __name__ == "__main__":
    main()
