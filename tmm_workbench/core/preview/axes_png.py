"""Pictures of a 5-axis multipoint tool path (PNG, matplotlib Agg): the face shaded, and at every footprint
position a short segment along the tool axis from the tip, coloured by the contact status (two contacts,
one contact; failed positions are marked on the footprint). A top view beside it shows the tilt.

matplotlib is imported inside the functions (importing this module never starts a GUI backend).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from tmm_workbench.core.strategies.multipoint import STATUS_FAILED, STATUS_ONE, STATUS_TWO, BezierFace, MultipointResults
from tmm_workbench.core.toolpath import MoveKind, Toolpath

STATUS_COLOURS = {STATUS_TWO: "#1a9641", STATUS_ONE: "#f39c12", STATUS_FAILED: "#d7191c"}
STATUS_LABELS = {STATUS_TWO: "two contacts", STATUS_ONE: "one contact", STATUS_FAILED: "failed"}


def face_grid(face: BezierFace, samples: int = 40) -> np.ndarray:
    """Points of the face on a (samples+1)^2 parameter grid, shape (samples+1, samples+1, 3)."""
    u0, u1, v0, v1 = face.domain
    U, V = np.meshgrid(np.linspace(u0, u1, samples + 1), np.linspace(v0, v1, samples + 1), indexing="ij")
    S = face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
    return S.reshape(samples + 1, samples + 1, 3)


def render_axes_png(grid: np.ndarray, results: MultipointResults, path: str, title: str = "",
                    toolpath: Optional[Toolpath] = None, axis_length: Optional[float] = None,
                    every: int = 1, dpi: int = 110) -> str:
    """The face (`grid`, (a, b, 3) points, e.g. from face_grid) with the tool axes of `results` drawn from
    each tip over `axis_length` mm (default: 8 % of the face's size), every `every`-th position; the cut
    moves of `toolpath` as a thin line. Returns `path`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    grid = np.asarray(grid, dtype=float)
    tip, axis, status = results["tip"], results["axis"], results.status
    lo, hi = grid.reshape(-1, 3).min(0), grid.reshape(-1, 3).max(0)
    size = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
    length = axis_length or 0.08 * size
    good = np.isfinite(tip).all(1) & np.isfinite(axis).all(1) & (status != STATUS_FAILED)
    idx = np.arange(len(status))
    shown = good & (idx % max(1, int(every)) == 0)

    fig = plt.figure(figsize=(14, 6.4))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot_surface(grid[..., 0], grid[..., 1], grid[..., 2], color="#9ecae1", alpha=0.55, linewidth=0.2,
                    edgecolor="#6b8fb3", shade=True, rcount=grid.shape[0], ccount=grid.shape[1])
    if toolpath is not None:
        cut = [(m.x, m.y, m.z) if m.kind is not MoveKind.RAPID else (np.nan, np.nan, np.nan) for m in toolpath]
        cut = np.array(cut, dtype=float).reshape(-1, 3)
        ax.plot(cut[:, 0], cut[:, 1], cut[:, 2], color="#333333", linewidth=0.6, alpha=0.8)
    for s in (STATUS_TWO, STATUS_ONE):
        sel = shown & (status == s)
        if not sel.any():
            continue
        segs = np.stack([tip[sel], tip[sel] + length * axis[sel]], axis=1)
        ax.add_collection3d(Line3DCollection(segs, colors=STATUS_COLOURS[s], linewidths=0.9,
                                             label=f"{STATUS_LABELS[s]} ({int((status == s).sum())})"))
    top = max(hi[2], float(np.nanmax(tip[good][:, 2] + length * axis[good][:, 2])) if good.any() else hi[2])
    ax.set_xlim(lo[0], lo[0] + size)
    ax.set_ylim(lo[1], lo[1] + size)
    ax.set_zlim(lo[2], top)
    ax.set_box_aspect((1, 1, max((top - lo[2]) / size, 0.15)))
    ax.view_init(elev=28, azim=-60)
    ax.set_xlabel("X mm")
    ax.set_ylabel("Y mm")
    ax.set_zlabel("Z mm", labelpad=12)
    ax.tick_params(axis="z", pad=4)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title("tool axes from the tips (tip -> spindle)", fontsize=10)

    ax2 = fig.add_subplot(1, 2, 2)
    tilt = np.degrees(np.arccos(np.clip(axis[:, 2], -1, 1)))
    sc = ax2.scatter(tip[good, 0], tip[good, 1], c=tilt[good], s=9, cmap="viridis")
    fig.colorbar(sc, ax=ax2, label="tilt from vertical (deg)")
    bad = status == STATUS_FAILED
    if bad.any():
        ax2.scatter(results.xy[bad, 0], results.xy[bad, 1], marker="x", color=STATUS_COLOURS[STATUS_FAILED],
                    s=18, label=f"failed ({int(bad.sum())})")
        ax2.legend(loc="upper right", fontsize=8)
    one = good & (status == STATUS_ONE)
    if one.any():
        ax2.scatter(tip[one, 0], tip[one, 1], facecolors="none", edgecolors=STATUS_COLOURS[STATUS_ONE], s=30,
                    linewidths=0.9, label=f"one contact ({int(one.sum())})")
        ax2.legend(loc="upper right", fontsize=8)
    ax2.set_aspect("equal")
    ax2.set_xlabel("X mm")
    ax2.set_ylabel("Y mm")
    ax2.set_title("tips, top view, coloured by tilt", fontsize=10)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return str(path)
