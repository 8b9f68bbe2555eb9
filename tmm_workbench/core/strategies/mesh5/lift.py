"""The lift delta that clears every triangle for many postures at many CC points, by the kernel's exact drop.

For posture (lambda, omega) at a CC point the tool touches the CC point's tangent plane (posture.touch_tip)
and is lifted along its own axis by delta (seed 000 eq. 3.8). The least delta >= 0 from which the tool is
clear of the mesh all the way up is the drop along -axis: in the tool frame of that posture (tip at delta = 0
at the origin, axis +Z) it is the plain drop-cutter's tip height. This covers all five contact cases of the
seed (vertex / edge / facet against the bottom, the corner torus and the side; VTCBT ... TTCBT) in one exact
query instead of their separate closed forms.

Batching: every (CC point, posture) pair becomes one copy of the triangles the tool can reach there, turned
into that posture's tool frame and laid side by side in XY on an "atlas"; one spatial index over the atlas and
one batched drop-cutter call answer all pairs (chunked to bound the memory). The kernel's DirectionalIndex
would need one index per axis, and the axes differ for every posture and CC point.

Reach: the triangles within reach of the CC point (the tool modelled up to tool_length above its tip), and
of those, per posture, the ones whose shadow along the axis comes within the tool's radius (each column's:
cutter, and with a ToolAssembly the flutes, neck, shank and holder grown by their clearances, dropped by the
kernel's assembly drop) above the column's bottom. A lift above `lift_limit` is returned as inf (not resolved: the far parts of
the mesh were left out), which the C-space treats as unavailable.
"""
from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import native
from tmm_workbench.core.strategies.mesh5.posture import tool_rotation, touch_tip
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]

CHUNK_TRIANGLES = 1_500_000   # triangles per atlas: ~100 MB of kernel index and copies


class MeshReach:
    """The mesh's triangles as corners, centroids and circumradii about the centroid, with a KD-tree of the
    centroids for the neighbourhood of each CC point (built once per mesh, shared by the passes)."""

    def __init__(self, mesh: TriMesh) -> None:
        from scipy.spatial import cKDTree
        self.mesh = mesh
        self.corners = mesh.vertices[mesh.triangles]                       # (m, 3, 3)
        self.centroids = self.corners.mean(axis=1)
        self.radii = np.linalg.norm(self.corners - self.centroids[:, None, :], axis=2).max(axis=1)
        self.max_radius = float(self.radii.max())
        self.tree = cKDTree(self.centroids)

    def near(self, point: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the triangles that may come within `radius` of `point`."""
        idx = np.asarray(self.tree.query_ball_point(point, radius + self.max_radius), dtype=np.int64)
        d = np.linalg.norm(self.centroids[idx] - point, axis=1)
        return idx[d <= radius + self.radii[idx]]


def default_tool_length(cutter: Cutter) -> float:
    """The tool's length modelled above the tip: its cutting length, or 2 D for a plain cutter without one."""
    return float(cutter.cutting_length) if math.isfinite(cutter.cutting_length) else 2.0 * cutter.diameter


def tool_columns(cutter: Cutter, tool_length: float, assembly: Optional[ToolAssembly] = None) -> np.ndarray:
    """(c, 3) columns (radius, lowest z, highest z) about the axis in the tool frame (tip at the origin) that
    hold the modelled tool: the cutter up to tool_length, or the assembly's cutter and bodies (each grown by
    its clearance) up to its top."""
    if assembly is None:
        return np.array([[cutter.radius, 0.0, tool_length]])
    cc = assembly.cutter_clearance
    cols = [[cutter.radius + cc, -cc, assembly.top]]
    cols += [[max(r0, r1) + c, z0 - c, assembly.top] for z0, z1, r0, r1, c in assembly.bodies()]
    return np.array(cols, dtype=float)


def _pair_copies(reach: MeshReach, cutter: Cutter, point: np.ndarray, frame: np.ndarray, rot: np.ndarray,
                 tip_t: np.ndarray, postures: np.ndarray, columns: np.ndarray, lift_limit: float):
    """For one CC point: (posture of each copy, triangles of each copy (k, 3, 3) in the posture's tool frame)."""
    R = cutter.radius
    rmax = float(columns[:, 0].max())
    top = float(columns[:, 2].max()) + lift_limit
    zlow = float(columns[:, 1].min())
    idx = reach.near(point, R + rmax + top)
    cen = (reach.centroids[idx] - point) @ frame.T                       # LCS
    rad = reach.radii[idx]
    # the tool of any posture stays within R + rmax + tan(lambda) (z + rmax) of LZ at height z above the plane
    rp = rot[postures]                                                   # (P, 3, 3)
    tan_max = float(np.max(np.hypot(rp[:, 2, 0], rp[:, 2, 1]) / rp[:, 2, 2]))
    cone = R + rmax + tan_max * (np.maximum(cen[:, 2] + rad, 0.0) + rmax) + rad
    near = np.hypot(cen[:, 0], cen[:, 1]) <= cone
    idx, cen, rad = idx[near], cen[near], rad[near]
    # the centroid test, a necessary condition of the exact one below: the centroids in every posture's tool
    # frame, (k, P) per component, in float32 (memory-bound; its rounding, < 1e-5 mm here, is covered by
    # `slack`, so the candidates are a superset and the exact test's result is the same)
    tp = tip_t[postures].astype(np.float32)
    rq = np.ascontiguousarray(rp.transpose(1, 2, 0), dtype=np.float32)    # (component, LCS axis, P)
    c32 = cen.astype(np.float32)
    slack = 1e-6 * (float(np.abs(cen).max(initial=0.0)) + R + top) + 1e-9 * R
    qx = c32 @ rq[0]
    qx -= tp[:, 0]
    qy = c32 @ rq[1]
    qy -= tp[:, 1]
    qx *= qx
    qy *= qy
    qx += qy
    reach_r = (rmax + slack + rad.astype(np.float32))[:, None]
    keep = qx <= reach_r * reach_r
    del qx, qy
    qz = c32 @ rq[2]
    qz -= tp[:, 2]
    r32 = (rad + slack).astype(np.float32)[:, None]
    keep &= (qz + r32 >= zlow) & (qz - r32 <= top)
    k_of, p_of = np.nonzero(keep)
    eps = 1e-9 * R
    loc = (reach.corners[idx] - point) @ frame.T
    tri = np.matmul(loc[k_of], rp[p_of].transpose(0, 2, 1)) - tip_t[postures][p_of][:, None, :]
    # the exact test on the candidates: the triangle's shadow within a column's radius, its z range reaching it
    dist = _axis_distance(tri[..., :2])
    zmax, zmin = tri[..., 2].max(axis=1), tri[..., 2].min(axis=1)
    ok = np.zeros(len(tri), dtype=bool)
    for radius, low, _high in columns:
        ok |= (dist <= radius * (1 + 1e-9)) & (zmax >= low - eps)
    ok &= zmin <= top
    return p_of[ok], tri[ok]


def _axis_distance(xy: np.ndarray) -> np.ndarray:
    """(m,) distance from the origin to each triangle (m, 3, 2) in the plane (0 inside)."""
    best = np.full(len(xy), np.inf)
    cross = []
    for i in range(3):
        a, b = xy[:, i], xy[:, (i + 1) % 3]
        e = b - a
        ee = np.einsum("ij,ij->i", e, e)
        t = np.clip(-np.einsum("ij,ij->i", a, e) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
        best = np.minimum(best, np.hypot(a[:, 0] + t * e[:, 0], a[:, 1] + t * e[:, 1]))
        cross.append(a[:, 0] * e[:, 1] - a[:, 1] * e[:, 0])          # the origin's side of each edge
    c = np.stack(cross, 1)
    inside = (c >= 0).all(axis=1) | (c <= 0).all(axis=1)
    return np.where(inside, 0.0, best)


def lifts(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, lam: np.ndarray,
          omg: np.ndarray, lift_limit: float, mask: Optional[np.ndarray] = None,
          tool_length: Optional[float] = None, progress: Optional[Progress] = None,
          assembly: Optional[ToolAssembly] = None, paired: bool = False) -> np.ndarray:
    """Lifts (n, P) of the P postures (lam, omg: (P,) radians) at the n CC points (points (n, 3), frames
    (n, 3, 3) rows LX, LY, LZ). NaN where `mask` (n, P) is False (not asked), inf above `lift_limit`. With an
    `assembly` (of this cutter) the flutes, neck, shank and holder keep their clearances too (the kernel's
    assembly drop), and tool_length is the assembly's top. `paired`: the k-th posture is the k-th CC
    point's only one (P = n, no mask), and the lifts come back (n,)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    lam = np.asarray(lam, dtype=float).reshape(-1)
    omg = np.asarray(omg, dtype=float).reshape(-1)
    if not (isinstance(lift_limit, (int, float)) and math.isfinite(lift_limit) and lift_limit >= 0):
        raise TmmError(f"lift limit must be a finite number of mm >= 0, got {lift_limit!r}")
    if assembly is not None:
        if not isinstance(assembly, ToolAssembly) or assembly.cutter != cutter:
            raise TmmError(f"assembly must be a ToolAssembly of the {cutter.describe()} cutter, got {assembly!r}")
        tool_length = assembly.top
    tool_length = default_tool_length(cutter) if tool_length is None else float(tool_length)
    if not (math.isfinite(tool_length) and tool_length > 0):
        raise TmmError(f"tool length must be a positive number of mm, got {tool_length!r}")
    n, P = len(pts), len(lam)
    if paired and (P != n or mask is not None):
        raise TmmError(f"paired lifts take one posture per CC point and no mask: {n} CC points, {P} postures")
    ask = None if mask is None or paired else np.asarray(mask, dtype=bool).reshape(n, P)
    columns = tool_columns(cutter, tool_length, assembly)
    rot = tool_rotation(lam, omg)                                        # (P, 3, 3)
    tip_t = np.einsum("pij,pj->pi", rot, touch_tip(cutter, rot))         # tip in each tool frame
    out = np.full((n, 1 if paired else P), np.nan)
    ask_progress = cancel.asker() if progress is None else progress
    pairs, tris = [], []
    budget = 0

    def flush() -> None:
        nonlocal pairs, tris, budget
        if pairs:
            _drop_atlas(cutter, assembly, float(columns[:, 0].max()), pairs, tris, out, lift_limit)
        pairs, tris, budget = [], [], 0

    for i in range(n):
        postures = np.array([i]) if paired else np.arange(P) if ask is None else np.flatnonzero(ask[i])
        if postures.size == 0:
            continue
        p_of, tri = _pair_copies(reach, cutter, pts[i], frm[i], rot, tip_t, postures, columns, lift_limit)
        pairs.append((i, np.zeros(1, dtype=np.int64) if paired else postures, p_of))
        tris.append(tri)
        budget += len(tri)
        if budget >= CHUNK_TRIANGLES:
            flush()
        if ask_progress is not None and not ask_progress((i + 1) / n):
            raise Cancelled("tool path computation cancelled")
    flush()
    return out[:, 0] if paired else out


def _drop_atlas(cutter: Cutter, assembly: Optional[ToolAssembly], reach_radius: float, pairs, tris,
                out: np.ndarray, lift_limit: float) -> None:
    """Lays the copies side by side, indexes them once and drops the tool on each copy's origin."""
    counts = [len(post) for _, post, _ in pairs]
    ncopy = int(sum(counts))
    grid = int(math.ceil(math.sqrt(ncopy)))
    spacing = 2.0 * reach_radius + 2.0 * max(float(np.abs(t[..., :2]).max(initial=0.0)) for t in tris) + 1.0
    cx = (np.arange(ncopy) % grid) * spacing
    cy = (np.arange(ncopy) // grid) * spacing
    corners, first = [], 0
    for (_, post, p_of), tri in zip(pairs, tris):
        copy = first + p_of      # the copy of a triangle: its posture's place in this CC point's list
        shifted = tri.copy()
        shifted[..., 0] += cx[copy][:, None]
        shifted[..., 1] += cy[copy][:, None]
        corners.append(shifted)
        first += len(post)
    V = np.ascontiguousarray(np.concatenate(corners).reshape(-1, 3))
    if len(V) == 0:                                   # nothing within reach of any copy: nothing to clear
        for i, post, _ in pairs:
            out[i, post] = 0.0
        return
    F = np.arange(len(V), dtype=np.int32).reshape(-1, 3)
    index = native.MeshIndex(V, F)
    floor = -1e-6 * max(1.0, cutter.radius)
    xy = np.column_stack([cx, cy])
    if assembly is None:
        z = native.drop_cutter(index, cutter.native, xy, floor, 0, None)
    else:
        rows = np.array(assembly.bodies(), dtype=np.float64).reshape(-1, 5)
        z, _owner = native.drop_assembly(index, cutter.native, rows, xy, floor, float(assembly.cutter_clearance),
                                         0, None)
    lift = np.maximum(z, 0.0)
    lift[lift > lift_limit] = np.inf
    first = 0
    for (i, post, _), _tri in zip(pairs, tris):
        out[i, post] = lift[first:first + len(post)]
        first += len(post)
