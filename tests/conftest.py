"""Shared test helpers: small analytic meshes built from arrays (no file I/O)."""
from __future__ import annotations

from typing import Callable

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.shared_data import SIBLING, shared_dir

# The shared benchmark files (seed surfaces, STL files), wherever core.shared_data finds them. Absent, only
# the tests that read them fail (each names the missing path), not the collection of every test.
try:
    SHARED = shared_dir()
except TmmError:
    SHARED = SIBLING
SHARED_STL = SHARED / "benchmarks" / "stl"
SEED_JSON = SHARED / "benchmarks" / "seed_surfaces.json"


def grid_mesh(height: Callable[[np.ndarray, np.ndarray], np.ndarray], nx: int, ny: int,
              extent: tuple[float, float, float, float], name: str = "grid") -> TriMesh:
    """The height field z = height(x, y) over extent (xmin, ymin, xmax, ymax) as 2 nx ny triangles."""
    xmin, ymin, xmax, ymax = extent
    xs, ys = np.meshgrid(np.linspace(xmin, xmax, nx + 1), np.linspace(ymin, ymax, ny + 1), indexing="ij")
    v = np.column_stack([xs.ravel(), ys.ravel(), height(xs, ys).ravel()])
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
    a = (i * (ny + 1) + j).ravel()
    b, c, d = a + ny + 1, a + 1, a + ny + 2
    f = np.vstack([np.column_stack([a, b, c]), np.column_stack([c, b, d])])
    return TriMesh(v, f, name)


def closest_distances(points: np.ndarray, mesh: TriMesh) -> np.ndarray:
    """Exact distance from each point to the mesh (min over all triangles, brute force, vectorised)."""
    v = mesh.vertices[mesh.triangles]          # (m, 3, 3)
    a, b, c = v[:, 0], v[:, 1], v[:, 2]
    out = np.empty(len(points))
    for k, p in enumerate(points):
        out[k] = np.sqrt(_point_triangle_sq(p, a, b, c).min())
    return out


def _point_triangle_sq(p, a, b, c):
    """Squared distance from p to each triangle (a, b, c): (m,). Ericson's closest-point regions."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp = p - b
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    cp = p - c
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v_ = vb / denom
        w_ = vc / denom
        q = a + ab * v_[:, None] + ac * w_[:, None]                      # interior
        t_ab = np.clip(d1 / (d1 - d3), 0, 1)
        t_ac = np.clip(d2 / (d2 - d6), 0, 1)
        t_bc = np.clip((d4 - d3) / ((d4 - d3) + (d5 - d6)), 0, 1)
    e_ab = a + ab * t_ab[:, None]
    e_ac = a + ac * t_ac[:, None]
    e_bc = b + (c - b) * t_bc[:, None]
    cand = np.stack([a, b, c, e_ab, e_ac, e_bc], axis=0)
    best = ((cand - p) ** 2).sum(2).min(0)
    inside = (va >= 0) & (vb >= 0) & (vc >= 0) & np.isfinite(v_) & np.isfinite(w_)
    qi = ((q - p) ** 2).sum(1)
    return np.where(inside, np.minimum(best, qi), best)


@pytest.fixture
def wavy_mesh() -> TriMesh:
    return grid_mesh(lambda x, y: 3 * np.sin(x / 6) * np.cos(y / 5) + 0.05 * x, 40, 30, (0, 0, 40, 30), "wavy")


def random_net(seed: int) -> np.ndarray:
    """A random bicubic control net: 4 x 4 poles 50 mm apart, z uniform in 70-100 mm (the 5-axis tests' faces)."""
    rng = np.random.default_rng(seed)
    net = np.zeros((4, 4, 3))
    net[..., 0] = 50.0 * np.arange(4)[:, None]
    net[..., 1] = 50.0 * np.arange(4)[None, :]
    net[..., 2] = rng.uniform(70.0, 100.0, (4, 4))
    return net
