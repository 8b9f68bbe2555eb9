"""Tensor-product Bézier patches of any degree, evaluated with numpy, and their tessellation into meshes.

A patch is its control net: an array of shape (m+1, n+1, 3) for degree m in u and n in v, with
S(u, v) = sum_ij B_i^m(u) B_j^n(v) P[i, j] over the unit square.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tmm_workbench.core.errors import TmmError

if TYPE_CHECKING:  # mesh.py loads the native kernel; evaluation alone must not need it
    from tmm_workbench.core.geometry.mesh import TriMesh

MAX_TESSELLATION_TRIANGLES = 20_000_000


def as_net(patch: np.ndarray) -> np.ndarray:
    """The control net as a float64 array of shape (m+1, n+1, 3), validated."""
    p = np.asarray(patch, dtype=np.float64)
    if p.ndim != 3 or p.shape[2] != 3 or p.shape[0] < 1 or p.shape[1] < 1:
        raise TmmError(f"Bezier control net must have shape (m+1, n+1, 3), got {p.shape}")
    if not np.isfinite(p).all():
        raise TmmError("Bezier control net has a non-finite coordinate")
    return p


def bernstein(degree: int, t: np.ndarray) -> np.ndarray:
    """Bernstein basis values B_i^degree(t), shape (len(t), degree+1)."""
    t = np.asarray(t, dtype=np.float64).reshape(-1, 1)
    i = np.arange(degree + 1)
    binom = np.array([math.comb(degree, k) for k in i], dtype=np.float64)
    # 0**0 == 1 in numpy, so the end points come out exact.
    return binom * t ** i * (1.0 - t) ** (degree - i)


def _hodograph(net: np.ndarray, axis: int) -> np.ndarray:
    """Control net of the partial derivative along `axis` (0: u, 1: v); degree drops by one."""
    k = net.shape[axis] - 1
    if k == 0:  # constant along this direction: the derivative is zero, degree 0
        shape = list(net.shape)
        shape[axis] = 1
        return np.zeros(shape)
    return k * np.diff(net, axis=axis)


def evaluate_grid(patch: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Points S(u_a, v_b) on the grid of parameters u (a,) x v (b,), shape (a, b, 3)."""
    net = as_net(patch)
    bu = bernstein(net.shape[0] - 1, u)
    bv = bernstein(net.shape[1] - 1, v)
    return np.einsum("ai,ijk,bj->abk", bu, net, bv, optimize=True)


def evaluate(patch: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Points S(u_k, v_k) for paired parameters (any matching shapes), shape u.shape + (3,)."""
    net = as_net(patch)
    uu, vv = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    bu = bernstein(net.shape[0] - 1, uu.ravel())
    bv = bernstein(net.shape[1] - 1, vv.ravel())
    pts = np.einsum("ki,ijc,kj->kc", bu, net, bv, optimize=True)
    return pts.reshape(uu.shape + (3,))


def derivatives(patch: np.ndarray, u: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """S and its first and second partial derivatives at paired parameters.

    Keys "S", "Su", "Sv", "Suu", "Suv", "Svv"; each of shape u.shape + (3,).
    """
    net = as_net(patch)
    nu = _hodograph(net, 0)
    nv = _hodograph(net, 1)
    nets = {"S": net, "Su": nu, "Sv": nv,
            "Suu": _hodograph(nu, 0), "Suv": _hodograph(nu, 1), "Svv": _hodograph(nv, 1)}
    return {k: evaluate(c, u, v) for k, c in nets.items()}


def normals(patch: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit normals Su x Sv (zero where the patch is degenerate), shape u.shape + (3,)."""
    d = derivatives(patch, u, v)
    n = np.cross(d["Su"], d["Sv"])
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def elevate_degree(patch: np.ndarray, axis: int) -> np.ndarray:
    """The same surface with the degree along `axis` (0: u, 1: v) raised by one."""
    net = np.moveaxis(as_net(patch), axis, 0)
    k = net.shape[0] - 1
    out = np.empty((k + 2,) + net.shape[1:])
    out[0], out[k + 1] = net[0], net[k]
    for i in range(1, k + 1):
        a = i / (k + 1)
        out[i] = a * net[i - 1] + (1 - a) * net[i]
    return np.moveaxis(out, 0, axis)


def second_derivative_bounds(patch: np.ndarray) -> tuple[float, float, float]:
    """Upper bounds of |Suu|, |Suv|, |Svv| over the patch: by the convex hull property the
    derivative nets' largest control vectors bound the derivatives everywhere."""
    net = as_net(patch)
    nu = _hodograph(net, 0)
    nv = _hodograph(net, 1)
    return tuple(float(np.linalg.norm(c, axis=-1).max())
                 for c in (_hodograph(nu, 0), _hodograph(nu, 1), _hodograph(nv, 1)))


def chordal_error_bound(patch: np.ndarray, nu: int, nv: int) -> float:
    """Upper bound (mm) of the distance between the patch and its tessellation into nu x nv cells.

    Linear interpolation over a triangle of a uv grid cell hu x hv deviates by at most
    (Muu hu^2 + 2 Muv hu hv + Mvv hv^2) / 8 (Taylor expansion at the point, barycentric weights).
    """
    muu, muv, mvv = second_derivative_bounds(patch)
    hu, hv = 1.0 / nu, 1.0 / nv
    return (muu * hu * hu + 2 * muv * hu * hv + mvv * hv * hv) / 8.0


def grid_for_tolerance(patch: np.ndarray, tol_mm: float) -> tuple[int, int]:
    """Cell counts (nu, nv) with the fewest cells whose tessellation stays within `tol_mm` of the
    patch, by `chordal_error_bound` (conservative)."""
    if not (isinstance(tol_mm, (int, float)) and math.isfinite(tol_mm) and tol_mm > 0):
        raise TmmError(f"chordal tolerance must be a positive length, got {tol_mm!r}")
    a, b, c = second_derivative_bounds(patch)
    t8 = 8.0 * tol_mm * (1 - 1e-12)  # margin so rounding never lands just above the tolerance
    # For each nu the smallest nv solves c hv^2 + 2 b hu hv + a hu^2 <= 8 tol for hv = 1/nv.
    nu_min = max(1, math.ceil(math.sqrt(a / t8) * (1 + 1e-12)))
    nu = np.arange(nu_min, 4 * nu_min + 64, dtype=np.float64)
    hu = 1.0 / nu
    slack = t8 - a * hu * hu
    with np.errstate(divide="ignore", invalid="ignore"):
        if c > 0:
            hv = (-b * hu + np.sqrt(b * b * hu * hu + c * slack)) / c
        elif b > 0:
            hv = slack / (2 * b * hu)
        else:
            hv = np.full_like(hu, np.inf)
    ok = slack > 0
    nv = np.where(ok, np.maximum(1.0, np.ceil(1.0 / np.where(ok, hv, 1.0) - 1e-9)), np.inf)
    cells = nu * nv
    best = int(np.argmin(cells + 1e-6 * np.abs(nu - nv)))  # ties: the more even grid
    if not np.isfinite(cells[best]) or 2 * cells[best] > MAX_TESSELLATION_TRIANGLES:
        raise TmmError(f"chordal tolerance {tol_mm:g} mm needs more than "
                       f"{MAX_TESSELLATION_TRIANGLES} triangles")
    return int(nu[best]), int(nv[best])


def grid_triangles(nu: int, nv: int) -> np.ndarray:
    """Triangles (2 nu nv, 3) of a (nu+1) x (nv+1) vertex grid indexed i*(nv+1)+j, counter-clockwise
    in (u, v) so the normals follow Su x Sv."""
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = (i * (nv + 1) + j).ravel()
    b, c, d = a + nv + 1, a + nv + 2, a + 1
    return np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int32)


def tessellate(patch: np.ndarray, nu: int, nv: int, name: str = "bezier") -> "TriMesh":
    """The patch sampled on a regular (nu+1) x (nv+1) parameter grid, each cell split in two triangles."""
    from tmm_workbench.core.geometry.mesh import TriMesh  # here, not at the top: see TYPE_CHECKING above

    if not (isinstance(nu, (int, np.integer)) and isinstance(nv, (int, np.integer)) and nu >= 1 and nv >= 1):
        raise TmmError(f"tessellation needs at least one cell each way, got nu={nu!r}, nv={nv!r}")
    if 2 * nu * nv > MAX_TESSELLATION_TRIANGLES:
        raise TmmError(f"tessellation {nu} x {nv} gives more than {MAX_TESSELLATION_TRIANGLES} triangles")
    pts = evaluate_grid(patch, np.linspace(0.0, 1.0, nu + 1), np.linspace(0.0, 1.0, nv + 1))
    return TriMesh(pts.reshape(-1, 3), grid_triangles(int(nu), int(nv)), name=name)


def tessellate_to_tolerance(patch: np.ndarray, tol_mm: float, name: str = "bezier") -> "TriMesh":
    """The patch tessellated finely enough that every triangle is within `tol_mm` of the surface."""
    nu, nv = grid_for_tolerance(patch, tol_mm)
    return tessellate(patch, nu, nv, name=name)


# Seed 001 Table 1's saddle heights, P00 P01 .. P33 (benchmarks/seed_surfaces.json holds the convex and
# concave patches only).
SEED_001_SADDLE_Z = (80, 65, 90, 85, 80, 85, 90, 95, 100, 105, 95, 100, 90, 100, 100, 85)


def _seed_net(z: np.ndarray) -> np.ndarray:
    i, j = np.meshgrid(np.arange(4), np.arange(4), indexing="ij")  # row order P00 P01 .. P33
    return np.stack([50.0 * i, 50.0 * j, np.asarray(z, dtype=np.float64).reshape(4, 4)], axis=-1)


def load_seed_patch(json_path: str | Path, which: str = "convex") -> np.ndarray:
    """Control net (4, 4, 3) in mm of seed 001's convex, concave (section `singh2020_bezier` of
    benchmarks/seed_surfaces.json) or saddle (Table 1, SEED_001_SADDLE_Z) bicubic patch:
    P[i][j] = (50 i, 50 j, z_ij)."""
    p = Path(json_path)
    if which == "saddle":
        return _seed_net(np.array(SEED_001_SADDLE_Z))
    if which not in ("convex", "concave"):
        raise TmmError(f"seed patch must be 'convex', 'concave' or 'saddle', got {which!r}")
    try:
        section = json.loads(p.read_text())["singh2020_bezier"]
        z = np.asarray(section["z"][which], dtype=np.float64)
    except (OSError, ValueError, KeyError) as exc:
        raise TmmError(f"{p}: cannot read singh2020_bezier/z/{which}: {exc}") from exc
    if section.get("units", "mm") != "mm":
        raise TmmError(f"{p}: singh2020_bezier units are {section.get('units')!r}, expected 'mm'")
    if z.shape != (16,):
        raise TmmError(f"{p}: singh2020_bezier/z/{which} must hold 16 heights, got {z.size}")
    return _seed_net(z)
