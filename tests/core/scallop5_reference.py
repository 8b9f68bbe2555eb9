"""Slow, independent reference for 5-axis flat-end cuts on a mesh: the material left at surface points by a
tool swept through given CL positions (tip, axis), measured along each point's normal by intersecting the
normal line with the solid tool (a finite cylinder) at every position, the moves between CL points
subdivided (tip linear, axis slerp). Shares no code with the profile, the C-space or the drop."""
from __future__ import annotations

import numpy as np

from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.geometry.mesh import TriMesh


def swept_positions(tips: np.ndarray, axes: np.ndarray, sub: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """The CL positions of one pass with `sub` - 1 positions between each two (tip linear, axis slerp)."""
    out_t, out_a = [tips[:1]], [axes[:1]]
    s = np.arange(1, sub + 1) / sub
    for i in range(len(tips) - 1):
        out_t.append(tips[i] + s[:, None] * (tips[i + 1] - tips[i]))
        out_a.append(slerp(axes[i], axes[i + 1], s))
    return np.concatenate(out_t), np.concatenate(out_a)


def cylinder_entry(q: np.ndarray, n: np.ndarray, tips: np.ndarray, axes: np.ndarray, radius: float,
                   length: float) -> np.ndarray:
    """(k,) for one line q + t n: the least t inside each solid cylinder (tip, axis, radius, length), inf
    where the line misses it. Negative: q lies inside the tool, or the tool under it (a gouge)."""
    w = q[None, :] - tips
    na = axes @ n
    bax = np.einsum("ij,ij->i", w, axes)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_a = np.stack([(0.0 - bax) / na, (length - bax) / na], 1)
    lo_a = np.where(np.abs(na) > 1e-15, t_a.min(1), np.where((bax >= 0) & (bax <= length), -np.inf, np.inf))
    hi_a = np.where(np.abs(na) > 1e-15, t_a.max(1), np.where((bax >= 0) & (bax <= length), np.inf, -np.inf))
    wp = w - bax[:, None] * axes
    npp = n[None, :] - na[:, None] * axes
    A = np.einsum("ij,ij->i", npp, npp)
    B = np.einsum("ij,ij->i", wp, npp)
    C = np.einsum("ij,ij->i", wp, wp) - radius * radius
    disc = B * B - A * C
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.maximum(disc, 0.0))
        r0, r1 = (-B - root) / A, (-B + root) / A
    par = A < 1e-15
    lo_r = np.where(par, np.where(C <= 0, -np.inf, np.inf), np.where(disc >= 0, r0, np.inf))
    hi_r = np.where(par, np.where(C <= 0, np.inf, -np.inf), np.where(disc >= 0, r1, -np.inf))
    t0, t1 = np.maximum(lo_a, lo_r), np.minimum(hi_a, hi_r)
    return np.where(t0 <= t1, t0, np.inf)


def remaining(points: np.ndarray, normals: np.ndarray, tips: np.ndarray, axes: np.ndarray, radius: float,
              length: float) -> np.ndarray:
    """(m,) material left at each surface point along its normal by the tool at all positions (the least
    entry; negative = gouge depth)."""
    out = np.empty(len(points))
    for i, (q, n) in enumerate(zip(points, normals)):
        near = np.linalg.norm(tips - q, axis=1) <= radius + length
        out[i] = cylinder_entry(q, n, tips[near], axes[near], radius, length).min(initial=np.inf)
    return out


def surface_samples(mesh: TriMesh, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points on the mesh above (x, y) (the highest triangle, brute force), their facet normals (up), and a
    mask of the samples that hit the mesh."""
    c = mesh.vertices[mesh.triangles]
    a, b, cc = c[:, 0], c[:, 1], c[:, 2]
    det = (b[:, 0] - a[:, 0]) * (cc[:, 1] - a[:, 1]) - (cc[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    fn = np.cross(b - a, cc - a)
    fn /= np.linalg.norm(fn, axis=1, keepdims=True)
    fn[fn[:, 2] < 0] *= -1
    pts, nrm, hit = np.zeros((len(xy), 3)), np.zeros((len(xy), 3)), np.zeros(len(xy), dtype=bool)
    for s in range(0, len(xy), 500):
        o = xy[s:s + 500]
        px, py = o[:, None, 0] - a[None, :, 0], o[:, None, 1] - a[None, :, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = (px * (cc[:, 1] - a[:, 1]) - (cc[:, 0] - a[:, 0]) * py) / det
            v = ((b[:, 0] - a[:, 0]) * py - px * (b[:, 1] - a[:, 1])) / det
        z = a[:, 2] + u * (b[:, 2] - a[:, 2]) + v * (cc[:, 2] - a[:, 2])
        z = np.where((u >= -1e-12) & (v >= -1e-12) & (u + v <= 1 + 1e-12), z, -np.inf)
        k = z.argmax(axis=1)
        zz = z[np.arange(len(o)), k]
        ok = np.isfinite(zz)
        hit[s:s + 500] = ok
        pts[s:s + 500] = np.column_stack([o, np.where(ok, zz, 0.0)])
        nrm[s:s + 500] = fn[k]
    return pts, nrm, hit
