"""CC paths on a mesh cut by drive planes (seed 000, section 3.5.1-3.5.2 and 3.3).

Parallel vertical drive planes a step apart cut the tessellated surface; each cut is a polyline on the mesh
(a CC path, split where the plane leaves the mesh). CC points are taken along it: the polyline's vertices
kept where the chord between kept points would leave the mesh polyline by more than the chord tolerance,
then points inserted so that no two neighbours are farther apart than the forward step or their normals
differ by more than the normal limit (the seed inserts points where the normal changes too much). Every CC
point lies on the mesh. Its normal is interpolated from the vertex normals: on the edge where the plane
crosses it (eq. 3.5, the affine rule along the edge) and linearly between two crossings of one facet (the
facet's barycentric interpolation restricted to the cut). The local frame (LCS, section 3.3): LZ the normal,
LX the feed direction = the drive plane's line in the tangent plane (oriented along the path), LY = LZ x LX.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import List, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh


@dataclass(frozen=True)
class CCPath:
    """One CC path: the points of one drive plane's cut between two places where it leaves the mesh."""
    plane: int              # index of the drive plane (passes in order of offset)
    offset: float           # the plane's signed distance along the plane normal (mm)
    points: np.ndarray      # (n, 3) CC points on the mesh, in feed order
    normals: np.ndarray     # (n, 3) unit normals interpolated from the vertex normals
    frames: np.ndarray      # (n, 3, 3) rows LX (feed), LY, LZ (normal) of each CC point's LCS
    # the path stops inside the mesh at its start / end (the planner left out CC points beyond the machine's
    # tilt there), not where the plane leaves the mesh
    cut_short: tuple[bool, bool] = (False, False)
    # mm along the feed its start / end lie inside the place where the plane leaves the mesh (the planner
    # moves them in: stepover._Planes.paths); the overrun beyond an end that is not cut short goes this much
    # further, so that the tool reaches the mesh's edge (tool_moves.overrun_positions)
    inset: tuple[float, float] = (0.0, 0.0)

    def __len__(self) -> int:
        return len(self.points)

    def take(self, index, cut_short: Optional[tuple[bool, bool]] = None) -> "CCPath":
        """The path's CC points at `index` (a slice or a mask, in order), cut short as given (else as it is)."""
        return replace(self, points=self.points[index], normals=self.normals[index], frames=self.frames[index],
                       cut_short=self.cut_short if cut_short is None else cut_short)


def _unit_xy(direction: Sequence[float]) -> np.ndarray:
    d = np.asarray(direction, dtype=float).reshape(-1)
    if d.size not in (2, 3) or not np.isfinite(d).all():
        raise TmmError(f"feed direction must be 2 or 3 finite numbers, got {direction!r}")
    d = np.array([d[0], d[1], 0.0])
    n = float(np.linalg.norm(d))
    if n < 1e-12:
        raise TmmError(f"feed direction must have a horizontal component, got {direction!r}")
    return d / n


def plane_normal(direction: Sequence[float]) -> np.ndarray:
    """The horizontal unit normal m of the vertical drive planes that contain the feed `direction`."""
    d = _unit_xy(direction)
    return np.array([-d[1], d[0], 0.0])


def plane_offsets(mesh: TriMesh, direction: Sequence[float], step: float,
                  first: Optional[float] = None) -> np.ndarray:
    """Offsets (along plane_normal) of drive planes `step` mm apart across the mesh, the first `first` mm
    inside its extent (default: half a step)."""
    if not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0):
        raise TmmError(f"drive plane step must be a positive number of mm, got {step!r}")
    s = mesh.vertices @ plane_normal(direction)
    lo, hi = float(s.min()), float(s.max())
    first = 0.5 * step if first is None else float(first)
    if not 0 <= first <= hi - lo:
        raise TmmError(f"first drive plane {first!r} mm must lie within the mesh's width 0..{hi - lo:g} mm")
    return np.arange(lo + first, hi, step)


def _plane_segments(mesh: TriMesh, f: np.ndarray):
    """The cut of one plane (vertex distances f, zeros nudged positive): per crossing triangle its two edge
    keys (vertex pairs, sorted) and the crossing parameter on each edge."""
    tri = mesh.triangles
    pos = f[tri] > 0
    cross = pos.any(axis=1) & ~pos.all(axis=1)
    t = tri[cross]
    p = pos[cross]
    ea, eb = [], []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        ea.append(t[:, i])
        eb.append(t[:, j])
    ea, eb = np.stack(ea, 1), np.stack(eb, 1)                      # (k, 3) edges
    ecross = np.stack([p[:, 0] != p[:, 1], p[:, 1] != p[:, 2], p[:, 2] != p[:, 0]], 1)
    k = len(t)
    which = np.nonzero(ecross)[1].reshape(k, 2)                     # exactly two edges cross
    a = np.take_along_axis(ea, which, 1)
    b = np.take_along_axis(eb, which, 1)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    return lo, hi


def _chain(lo: np.ndarray, hi: np.ndarray, nv: int) -> List[np.ndarray]:
    """Chains the segments (each joins two edges lo-hi) into ordered lists of edge keys lo * nv + hi (open
    chains where the plane leaves the mesh, closed ones around a hump)."""
    keys = lo.astype(np.int64) * nv + hi                            # (k, 2) edge keys
    uniq, inv = np.unique(keys.ravel(), return_inverse=True)
    inv = inv.reshape(-1, 2)
    # each edge is shared by at most two segments on a manifold: list them
    owners = -np.ones((len(uniq), 2), dtype=np.int64)
    seg = np.repeat(np.arange(len(keys)), 2)
    order = np.argsort(inv.ravel(), kind="stable")
    e_sorted, s_sorted = inv.ravel()[order], seg[order]
    first = np.r_[True, e_sorted[1:] != e_sorted[:-1]]
    owners[e_sorted[first], 0] = s_sorted[first]
    second = ~first
    owners[e_sorted[second], 1] = s_sorted[second]
    used = np.zeros(len(keys), dtype=bool)
    degree = (owners >= 0).sum(axis=1)
    chains: List[np.ndarray] = []
    starts = list(np.flatnonzero(degree == 1)) + list(range(len(uniq)))  # open chains first, then loops
    for e0 in starts:
        if not (owners[e0] >= 0).any() or used[owners[e0][owners[e0] >= 0]].all():
            continue
        e, path = e0, [e0]
        while True:
            nxt = [s for s in owners[e] if s >= 0 and not used[s]]
            if not nxt:
                break
            s = nxt[0]
            used[s] = True
            e = inv[s, 1] if inv[s, 0] == e else inv[s, 0]
            path.append(e)
        if len(path) > 1:
            chains.append(uniq[np.asarray(path)])
    return chains


def _simplify(pts: np.ndarray, tol: float) -> np.ndarray:
    """Douglas-Peucker: indices of the polyline's vertices kept so that every dropped one lies within `tol`
    of the chord between its kept neighbours."""
    keep = np.zeros(len(pts), dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, len(pts) - 1)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        a, b = pts[i], pts[j]
        ab = b - a
        L2 = float(ab @ ab)
        q = pts[i + 1:j] - a
        if L2 > 0:
            u = np.clip(q @ ab / L2, 0.0, 1.0)
            d = np.linalg.norm(q - u[:, None] * ab, axis=1)
        else:
            d = np.linalg.norm(q, axis=1)
        k = int(np.argmax(d))
        if d[k] > tol:
            m = i + 1 + k
            keep[m] = True
            stack += [(i, m), (m, j)]
    return np.flatnonzero(keep)


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)


class _Polyline:
    """A cut polyline: vertices on the mesh edges with their interpolated normals, and arc length."""

    def __init__(self, pts: np.ndarray, nrm: np.ndarray) -> None:
        self.pts, self.nrm = pts, nrm
        self.s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]

    def at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points and normals at arc lengths `s` (linear along each piece: on the mesh, eq. 3.5)."""
        i = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2)
        L = self.s[i + 1] - self.s[i]
        u = np.where(L > 0, (s - self.s[i]) / np.where(L > 0, L, 1.0), 0.0)[:, None]
        p = self.pts[i] * (1 - u) + self.pts[i + 1] * u
        n = _normalize(self.nrm[i] * (1 - u) + self.nrm[i + 1] * u)
        return p, n


def _sample(poly: _Polyline, chord_tol: float, forward_step: float, max_angle: float) -> np.ndarray:
    """Arc lengths of the CC points along one polyline."""
    s = poly.s[_simplify(poly.pts, chord_tol)]
    # forward step: split each gap evenly
    gaps = np.diff(s)
    cnt = np.maximum(1, np.ceil(gaps / forward_step - 1e-9)).astype(int)
    j = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    s = np.r_[np.repeat(s[:-1], cnt) + np.repeat(gaps / cnt, cnt) * j, s[-1]]
    # normal change: halve the gaps whose normals differ too much (a few rounds)
    for _ in range(12):
        _, n = poly.at(s)
        ang = np.arccos(np.clip(np.einsum("ij,ij->i", n[:-1], n[1:]), -1.0, 1.0))
        bad = np.flatnonzero((ang > max_angle) & (np.diff(s) > 1e-6))
        if bad.size == 0:
            break
        s = np.sort(np.r_[s, 0.5 * (s[bad] + s[bad + 1])])
    return s


def local_frames(normals: np.ndarray, tangents: np.ndarray, plane_m: np.ndarray) -> np.ndarray:
    """(n, 3, 3) LCS rows (LX, LY, LZ): LZ the normal, LX the drive plane's line in the tangent plane
    (m x n, turned along `tangents`), LY = LZ x LX. Where the normal lies across the plane (m x n ~ 0) LX is
    the path tangent projected on the tangent plane."""
    lz = _normalize(normals)
    lx = np.cross(plane_m[None, :], lz)
    weak = np.linalg.norm(lx, axis=1) < 1e-6
    if weak.any():
        t = tangents[weak]
        lx[weak] = t - np.einsum("ij,ij->i", t, lz[weak])[:, None] * lz[weak]
    lx = _normalize(lx)
    flip = np.einsum("ij,ij->i", lx, tangents) < 0
    lx[flip] *= -1
    ly = np.cross(lz, lx)
    return np.stack([lx, ly, lz], axis=1)


def cc_paths(mesh: TriMesh, direction: Sequence[float], offsets: np.ndarray, forward_step: float,
             chord_tolerance: float, max_normal_angle_deg: float = 5.0,
             vertex_normals: Optional[np.ndarray] = None, min_length: float = 0.0) -> List[CCPath]:
    """CC paths of the drive planes at `offsets` (along plane_normal(direction)), in plane order and, within
    a plane, in feed order (each path runs along `direction`). `vertex_normals` (n, 3): default MWA
    (mesh.vertex_normals("angle")). Paths shorter than `min_length` mm are left out."""
    for name, v in (("forward step", forward_step), ("chord tolerance", chord_tolerance),
                    ("normal angle limit", max_normal_angle_deg)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise TmmError(f"{name} must be a positive number, got {v!r}")
    d = _unit_xy(direction)
    m = plane_normal(direction)
    vn = mesh.vertex_normals("angle") if vertex_normals is None else np.asarray(vertex_normals, dtype=float)
    if vn.shape != mesh.vertices.shape:
        raise TmmError(f"vertex normals must have shape {mesh.vertices.shape}, got {vn.shape}")
    V = mesh.vertices
    s_all = V @ m
    scale = max(1.0, float(np.abs(V).max()))
    out: List[CCPath] = []
    for ip, off in enumerate(np.asarray(offsets, dtype=float).reshape(-1)):
        f = s_all - off
        f = np.where(np.abs(f) <= 1e-12 * scale, 1e-12 * scale, f)    # a vertex on the plane counts as above
        if not ((f > 0).any() and (f < 0).any()):
            continue
        lo, hi = _plane_segments(mesh, f)
        if len(lo) == 0:
            continue
        pieces = []
        nv = len(V)
        for keys in _chain(lo, hi, nv):
            a, b = keys // nv, keys % nv
            t = (f[a] / (f[a] - f[b]))[:, None]                        # crossing on edge a-b
            pts = V[a] + t * (V[b] - V[a])
            nrm = _normalize(vn[a] + t * (vn[b] - vn[a]))              # eq. 3.5
            if (pts[-1] - pts[0]) @ d < 0:
                pts, nrm = pts[::-1], nrm[::-1]
            poly = _Polyline(pts, nrm)
            if poly.s[-1] <= max(min_length, 1e-9):
                continue
            s = _sample(poly, chord_tolerance, forward_step, math.radians(max_normal_angle_deg))
            p, n = poly.at(s)
            tang = np.gradient(p, axis=0) if len(p) > 1 else np.tile(d, (len(p), 1))
            pieces.append(CCPath(ip, float(off), p, n, local_frames(n, tang, m)))
        pieces.sort(key=lambda c: float(c.points[0] @ d))
        out.extend(pieces)
    return out
