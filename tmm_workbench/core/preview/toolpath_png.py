"""Pictures of a tool path over its model (PNG, matplotlib Agg): a shaded 3D view and a top view.

matplotlib is imported inside the functions so importing this module never starts a GUI backend
(FreeCAD may already have one running).
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from tmm_workbench.core.toolpath import MoveKind, Toolpath

if TYPE_CHECKING:
    from tmm_workbench.core.geometry.mesh import TriMesh

MAX_DRAWN_TRIANGLES = 20_000      # above this the model is decimated for drawing (matplotlib 3D is slow)
MAX_DRAWN_PATH_POINTS = 400_000   # above this cutting polylines are thinned for drawing
MAX_PASSES_3D = 60                # denser rasters show every k-th pass, or the view is a red mat
MAX_PASSES_TOP = 110
CUT_COLOUR = "#d62728"
RAPID_COLOUR = "#000000"  # black dashed: stands out on the grey model and on viridis
MODEL_COLOUR = np.array([0.72, 0.75, 0.80])
_GCODE_WORD = re.compile(r"([GXYZ])\s*([-+]?\d*\.?\d+)")


def toolpath_of_gcode(text: str) -> Toolpath:
    """The G0 / G1 (and G2 / G3, as lines to their end: for drawing) moves of a 3-axis program in absolute mm,
    coordinates modal (a move before all three are known is not drawn: its start is the machine's); comments in
    parentheses or after ';' skipped."""
    path = Toolpath()
    pos: dict[str, float] = {}
    mode = None
    for line in text.splitlines():
        line = re.sub(r"\([^)]*\)", "", line).split(";")[0].upper()
        words = _GCODE_WORD.findall(line)
        moved = False
        for letter, value in words:
            if letter == "G" and value in ("0", "00", "1", "01", "2", "02", "3", "03"):
                mode = int(value)
            elif letter in "XYZ":
                pos[letter] = float(value)
                moved = True
        if moved and mode is not None and len(pos) == 3:
            path.add(MoveKind.RAPID if mode == 0 else MoveKind.FEED, pos["X"], pos["Y"], pos["Z"])
    return path


def decimate_for_drawing(vertices: np.ndarray, triangles: np.ndarray,
                         max_triangles: int = MAX_DRAWN_TRIANGLES) -> tuple[np.ndarray, np.ndarray]:
    """Vertex clustering on a uniform grid, coarsened until at most `max_triangles` remain.

    Keeps the silhouette and leaves no holes at drawing resolution, unlike drawing a random subset.
    A cluster on the mesh border is placed at the mean of its border vertices, so outlines stay put.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(triangles, dtype=np.int64)
    if len(f) <= max_triangles:
        return v, f
    border = _border_vertices(f, len(v))
    lo, hi = v.min(axis=0), v.max(axis=0)
    extent = np.maximum(hi - lo, 1e-9)
    # A grid with about max_triangles / 2 occupied cells over the surface's projected area.
    cell = float(np.sqrt(extent[0] * extent[1] / (max_triangles / 2.0))) or float(extent.max()) / 100
    while True:
        ijk = np.floor((v - lo) / cell).astype(np.int64)
        dims = ijk.max(axis=0) + 1
        _, cluster = np.unique((ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2], return_inverse=True)
        cluster = cluster.ravel()
        n = int(cluster.max()) + 1
        weight = np.where(border, 1e6, 1.0)  # border vertices outweigh inner ones in their cluster
        centre = np.zeros((n, 3))
        np.add.at(centre, cluster, v * weight[:, None])
        centre /= np.bincount(cluster, weights=weight, minlength=n)[:, None]
        g = cluster[f]
        keep = (g[:, 0] != g[:, 1]) & (g[:, 1] != g[:, 2]) & (g[:, 0] != g[:, 2])
        g = g[keep]
        # Two triangles on the same three clusters (the two sides of a thin wall) draw as one.
        sg = np.sort(g, axis=1)
        _, first = np.unique((sg[:, 0] * n + sg[:, 1]) * n + sg[:, 2], return_index=True)
        g = g[np.sort(first)]
        if len(g) <= max_triangles:
            return centre, g
        cell *= 1.25


def _border_vertices(f: np.ndarray, n: int) -> np.ndarray:
    """Vertices on an edge used by one triangle only (the open border of a surface)."""
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    key, count = np.unique(e[:, 0] * n + e[:, 1], return_counts=True)
    once = key[count == 1]
    flag = np.zeros(n, dtype=bool)
    flag[once // n] = True
    flag[once % n] = True
    return flag


def _segments(toolpath: Toolpath) -> dict[str, np.ndarray]:
    """Polylines per move kind as (k, 3) arrays with NaN rows between pieces (one artist per kind).

    A move is the segment from the previous position to its own, so a run of moves of one kind
    starting at move s is the polyline through positions s-1 .. e.
    """
    pts = toolpath.points()
    codes = np.array([list(MoveKind).index(m.kind) for m in toolpath.moves], dtype=np.int64)
    out: dict[str, list[np.ndarray]] = {k.value: [] for k in MoveKind}
    if len(pts) > 1:
        change = np.flatnonzero(np.diff(codes[1:])) + 2  # first move of each new run
        starts = np.concatenate([[1], change])
        ends = np.concatenate([change - 1, [len(pts) - 1]])
        kinds = list(MoveKind)
        for s, e in zip(starts, ends):
            out[kinds[codes[s]].value].append(pts[s - 1:e + 1])
    gap = np.full((1, 3), np.nan)
    return {k: (np.concatenate([x for p in pieces for x in (p, gap)]) if pieces else np.empty((0, 3)))
            for k, pieces in out.items()}


def path_statistics(toolpath: Toolpath) -> dict[str, float]:
    """Lengths (mm) and counts of the moves by kind."""
    pts = toolpath.points()
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1) if len(pts) > 1 else np.zeros(0)
    kinds = np.array([m.kind.value for m in toolpath.moves[1:]])
    stats = {}
    for k in MoveKind:
        sel = kinds == k.value
        stats[f"{k.value}_length"] = float(seg[sel].sum()) if len(seg) else 0.0
        stats[f"{k.value}_count"] = int(sel.sum())
    stats["cutting_length"] = stats["feed_length"] + stats["plunge_length"]
    return stats


def _thin(poly: np.ndarray, limit: int) -> np.ndarray:
    """Every k-th point of a long polyline, keeping the NaN breaks (drawing only)."""
    if len(poly) <= limit:
        return poly
    k = int(np.ceil(len(poly) / limit))
    keep = np.zeros(len(poly), dtype=bool)
    keep[::k] = True
    nan = np.isnan(poly[:, 0])
    keep |= nan
    keep[np.flatnonzero(nan) - 1] = True  # the last point before each break
    keep[-1] = True
    return poly[keep]


def _pieces(poly: np.ndarray) -> list[np.ndarray]:
    """The NaN-separated polylines of `poly`."""
    parts = np.split(poly, np.flatnonzero(np.isnan(poly[:, 0])))
    parts = [p[~np.isnan(p[:, 0])] for p in parts]
    return [p for p in parts if len(p) > 1]


def _join(pieces: list[np.ndarray]) -> np.ndarray:
    gap = np.full((1, 3), np.nan)
    return np.concatenate([x for p in pieces for x in (p, gap)]) if pieces else np.empty((0, 3))


def _strokes(piece: np.ndarray) -> list[np.ndarray]:
    """A polyline split where it turns sharply in XY (> 45 deg) or goes straight up or down:
    for a raster, the passes and the links between them."""
    d = np.diff(piece[:, :2], axis=0)
    ln = np.linalg.norm(d, axis=1)
    vertical = ln <= 1e-9 * max(1.0, float(np.abs(piece[:, :2]).max()))
    u = d / np.where(vertical, 1.0, ln)[:, None]
    turn = (np.einsum("ij,ij->i", u[:-1], u[1:]) < np.cos(np.radians(45))) | vertical[:-1] | vertical[1:]
    brk = np.concatenate([[0], np.flatnonzero(turn) + 1, [len(piece) - 1]])
    return [piece[a:b + 1] for a, b in zip(brk[:-1], brk[1:]) if b > a]


def thin_passes(cut: np.ndarray, max_passes: int) -> tuple[np.ndarray, int, int]:
    """For drawing a dense raster: every k-th pass (long stroke) of the cutting polylines.

    Returns (polylines, k, number of passes); k == 1 returns `cut` unchanged. Links between passes
    are left out when passes are skipped (they would join passes that are not drawn).
    """
    strokes = [st for p in _pieces(cut) for st in _strokes(p)]
    if not strokes:
        return cut, 1, 0
    length = np.array([np.linalg.norm(np.diff(st[:, :2], axis=0), axis=1).sum() for st in strokes])
    passes = [st for st, ln in zip(strokes, length) if ln >= 0.2 * length.max()]
    k = int(np.ceil(len(passes) / max_passes))
    if k <= 1:
        return cut, 1, len(passes)
    keep = passes[::k] + ([passes[-1]] if (len(passes) - 1) % k else [])
    return _join(keep), k, len(passes)


def _densify(poly: np.ndarray, max_len: float) -> np.ndarray:
    """Segments longer than `max_len` split evenly, so visibility can be judged point by point."""
    out = []
    for p in _pieces(poly):
        seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
        n = np.maximum(1, np.ceil(seg / max_len).astype(int))
        t = np.concatenate([np.arange(k) / k for k in n])
        i = np.repeat(np.arange(len(seg)), n)
        out.append(np.vstack([p[i] + t[:, None] * (p[i + 1] - p[i]), p[-1:]]))
    return _join(out)


def hide_occluded(poly: np.ndarray, vertices: np.ndarray, triangles: np.ndarray,
                  view_dir: np.ndarray) -> np.ndarray:
    """`poly` with the points hidden behind the model (seen from `view_dir`, orthographic) set to NaN.

    The model is turned so the viewer looks down -Z; a tiny ball dropped at each point's position
    finds the model's front-most surface there (the kernel's drop-cutter is a z-buffer query).
    """
    from tmm_workbench.core.tools.cutter import Cutter
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.geometry.mesh import TriMesh

    pts = poly[~np.isnan(poly[:, 0])]
    if len(pts) == 0:
        return poly
    w = view_dir / np.linalg.norm(view_dir)
    a = np.array([0.0, 0.0, 1.0]) if abs(w[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = np.cross(a, w)
    e1 /= np.linalg.norm(e1)
    rot = np.stack([e1, np.cross(w, e1), w])  # rows: screen x, screen y, towards the viewer
    v = vertices @ rot.T
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    surface = DropSurface(TriMesh(v, triangles, name="view"))
    q = poly @ rot.T
    ok = ~np.isnan(q[:, 0])
    front = np.full(len(q), -np.inf)
    floor = float(min(v[:, 2].min(), np.nanmin(q[:, 2]))) - 1.0
    front[ok] = surface.drop(Cutter.ball(2e-4 * diag), q[ok, :2], floor)
    hidden = ok & (q[:, 2] < front - 3e-3 * diag)
    out = poly.copy()
    out[hidden] = np.nan
    return out


def cull_back_faces(vertices: np.ndarray, triangles: np.ndarray, view_dir: np.ndarray) -> np.ndarray:
    """Triangles of a closed mesh that face the viewer (all of them for an open surface, whose
    back may show). Hidden faces are not merely wasted: mplot3d's painter's sort by triangle
    centre lets a large bottom or back facet paint over the top."""
    f = np.asarray(triangles, dtype=np.int64)
    if _border_vertices(f, len(vertices)).any():
        return f
    c = vertices[f]
    n = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    outward = np.sign(np.einsum("ij,ij->i", c[:, 0], n).sum()) or 1.0  # signed volume: inside-out files
    facing = outward * (n @ view_dir) >= -1e-9 * np.linalg.norm(n, axis=1)
    return f[facing] if facing.any() else f


def subdivide_for_drawing(vertices: np.ndarray, triangles: np.ndarray, max_edge: float,
                          budget: int) -> tuple[np.ndarray, np.ndarray]:
    """Large triangles split 1:4 until edges are below `max_edge` (or `budget` triangles): mplot3d
    sorts polygons by their centres, and one big triangle (a flat plate) would paint over the
    model standing on it."""
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int64)
    while True:
        c = v[f]
        edge = np.linalg.norm(c - np.roll(c, -1, axis=1), axis=2).max(axis=1)
        big = edge > max_edge
        room = (budget - len(f)) // 3
        if not big.any() or room <= 0:
            return v, f
        if big.sum() > room:  # over budget: split the largest first
            big = np.zeros(len(f), dtype=bool)
            big[np.argsort(edge)[-room:]] = True
        fb = f[big]
        mids = (v[fb] + v[np.roll(fb, -1, axis=1)]) / 2  # (b, 3 edges, 3)
        base = len(v)
        v = np.vstack([v, mids.reshape(-1, 3)])
        m = base + np.arange(3 * len(fb)).reshape(-1, 3)  # mid of edges 01, 12, 20
        new = np.concatenate([np.column_stack([fb[:, 0], m[:, 0], m[:, 2]]),
                              np.column_stack([m[:, 0], fb[:, 1], m[:, 1]]),
                              np.column_stack([m[:, 2], m[:, 1], fb[:, 2]]),
                              m])
        f = np.vstack([f[~big], new])


def _shade(corners: np.ndarray, light: np.ndarray) -> np.ndarray:
    """Per-triangle RGB: Lambert shading, two-sided so wrongly oriented facets do not go black."""
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    lam = np.abs(n @ light)
    return np.clip(MODEL_COLOUR[None, :] * (0.35 + 0.65 * lam[:, None]), 0, 1)


def render_toolpath_png(mesh: "TriMesh", toolpath: Toolpath, path: str, title: str = "",
                        elev: float = 35, azim: float = -60,
                        size_px: tuple[int, int] = (1800, 850), dpi: int = 100) -> str:
    """Write a PNG of `toolpath` over `mesh`: left a shaded 3D view (orthographic, cutting moves solid,
    rapids dashed, the parts hidden behind the model left out), right a top view over the model
    coloured by height. Returns `path`.

    Drawing only: meshes above MAX_DRAWN_TRIANGLES are decimated, and dense rasters show every
    k-th pass (said in the legend); the statistics in the legend are those of the whole path.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.transforms import offset_copy
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    v, f = decimate_for_drawing(mesh.vertices, mesh.triangles)
    lo, hi = mesh.bounds
    pts = toolpath.points()
    if len(pts):
        lo, hi = np.minimum(lo, pts.min(axis=0)), np.maximum(hi, pts.max(axis=0))
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    seg = _segments(toolpath)
    stats = path_statistics(toolpath)
    cut = _thin(_join(_pieces(seg["feed"]) + _pieces(seg["plunge"])), MAX_DRAWN_PATH_POINTS)
    rapid = seg["rapid"]
    cut3d, k3d, n_passes = thin_passes(cut, MAX_PASSES_3D)
    cut_top, k_top, _ = thin_passes(cut, MAX_PASSES_TOP)

    az, el = np.radians(azim), np.radians(elev)
    eye = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    try:
        cut3d = hide_occluded(_densify(cut3d, diag / 150), v, f, eye)
        rapid3d = hide_occluded(_densify(rapid, diag / 150), v, f, eye)
    except ImportError:  # no kernel: draw everything over the model
        rapid3d = rapid

    fig = plt.figure(figsize=(size_px[0] / dpi, size_px[1] / dpi), dpi=dpi)
    try:
        grid = fig.add_gridspec(1, 2, width_ratios=[1.2, 1.0], left=0.02, right=0.95, bottom=0.12,
                                top=0.88, wspace=0.22)
        # 3D view. computed_zorder=False: the (visible part of the) path is drawn over the model.
        ax = fig.add_subplot(grid[0, 0], projection="3d", computed_zorder=False)
        ax.set_proj_type("ortho")  # as hide_occluded assumes
        vs, fs = subdivide_for_drawing(v, cull_back_faces(v, f, eye), diag / 40, 2 * MAX_DRAWN_TRIANGLES)
        corners = vs[fs]
        light = eye + np.array([0.3, 0.3, 0.6])  # from above and a little to the side of the viewer
        light /= np.linalg.norm(light)
        shade = _shade(corners, light)
        # Edges in the face colour: antialiased polygons alone leave light seams between them.
        ax.add_collection3d(Poly3DCollection(corners, facecolors=shade, edgecolors=shade, linewidths=0.3,
                                             zorder=1))
        every = f", every {_ordinal(k3d)} of {n_passes} passes shown" if k3d > 1 else ""
        cut_label = (f"cutting {stats['cutting_length']:.0f} mm ({stats['feed_count']} feeds, "
                     f"{stats['plunge_count']} plunges{every})")
        rapid_label = f"rapids: {stats['rapid_count']} moves, {stats['rapid_length']:.0f} mm"
        if len(cut3d):
            ax.plot(cut3d[:, 0], cut3d[:, 1], cut3d[:, 2], color=CUT_COLOUR, lw=0.8, zorder=3,
                    label=cut_label)
        if len(rapid3d):
            ax.plot(rapid3d[:, 0], rapid3d[:, 1], rapid3d[:, 2], color=RAPID_COLOUR, lw=1.0, ls="--",
                    zorder=4, label=rapid_label)
        centre, half = (lo + hi) / 2, (hi - lo) / 2
        ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
        ax.set_ylim(centre[1] - half[1], centre[1] + half[1])
        ax.set_zlim(centre[2] - half[2], centre[2] + half[2])
        # Equal scale on all axes; zoom fills the panel (mplot3d leaves a wide margin by default).
        ax.set_box_aspect(np.maximum(hi - lo, 1e-3 * diag), zoom=1.2)
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("X mm")
        ax.set_ylabel("Y mm")
        ax.set_zlabel("Z mm")
        ax.legend(loc="upper left", fontsize=8)
        ax.set_title("3D view", fontsize=10)

        # Top view: highest facets drawn last, so what the tool sees from above shows.
        ax2 = fig.add_subplot(grid[0, 1])
        order = np.argsort(v[f][:, :, 2].mean(axis=1))
        tpc = ax2.tripcolor(v[:, 0], v[:, 1], f[order], v[:, 2], cmap="viridis", shading="gouraud",
                            rasterized=True)
        cax = make_axes_locatable(ax2).append_axes("right", size="3%", pad=0.08)  # as tall as the plot
        fig.colorbar(tpc, cax=cax, label="model Z mm")
        if len(cut_top):
            every = f" (every {_ordinal(k_top)} pass)" if k_top > 1 else ""
            ax2.plot(cut_top[:, 0], cut_top[:, 1], color=CUT_COLOUR, lw=0.6, label="cutting" + every)
        if len(rapid):
            ax2.plot(rapid[:, 0], rapid[:, 1], color=RAPID_COLOUR, lw=1.0, ls="--", label="rapids")
        if len(pts):
            ax2.plot(pts[0, 0], pts[0, 1], "o", color="black", ms=6, label="start")
            ax2.plot(pts[-1, 0], pts[-1, 1], "s", color="white", mec="black", ms=6, label="end")
        ax2.set_aspect("equal")
        pad = 0.01 * diag
        ax2.set_xlim(lo[0] - pad, hi[0] + pad)
        ax2.set_ylim(lo[1] - pad, hi[1] + pad)
        ax2.set_xlabel("X mm")
        ax2.set_ylabel("Y mm")
        below = offset_copy(ax2.transAxes, fig=fig, y=-30, units="points")  # under the X label
        ax2.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncol=4, fontsize=8,
                   frameon=False)
        cz = toolpath.cutting_points()[:, 2]
        zr = f", cutting Z {cz.min():.2f}..{cz.max():.2f} mm" if len(cz) else ""
        ax2.set_title(f"top view  (model {len(mesh.triangles)} triangles, path {len(toolpath)} moves{zr})",
                      fontsize=10)
        if title:
            fig.suptitle(title, fontsize=12)
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)
    return path


def _ordinal(k: int) -> str:
    return f"{k}{'th' if 10 <= k % 100 <= 20 else {1: 'st', 2: 'nd', 3: 'rd'}.get(k % 10, 'th')}"
