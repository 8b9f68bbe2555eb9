"""The drop-cutter through the binding: exactness against an independent brute force, threads,
progress and cancel, and clear errors."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import closest_distances
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native


def test_ball_touches_and_never_gouges(wavy_mesh):
    """Ball centre at exactly the radius from the mesh: brute-force exact point-triangle distance."""
    rng = np.random.default_rng(1)
    xy = rng.uniform([5, 5], [35, 25], size=(300, 2))
    cutter = Cutter.ball(4.0)
    z = DropSurface(wavy_mesh).drop(cutter, xy, floor_z=-100)
    centres = np.column_stack([xy, z + cutter.radius])
    d = closest_distances(centres, wavy_mesh)
    np.testing.assert_allclose(d, cutter.radius, atol=1e-9)


def test_flat_and_bull_never_gouge_dense_cutter_sampling(wavy_mesh):
    """Dense sampling of the cutter's lower surface: no sample below the mesh (vertical ray test)."""
    surface = DropSurface(wavy_mesh)
    rng = np.random.default_rng(2)
    xy = rng.uniform([6, 6], [34, 24], size=(40, 2))
    for cutter in (Cutter.flat(5.0), Cutter.bull(8.0, 2.0)):
        z = surface.drop(cutter, xy, floor_z=-100)
        a, r = cutter.radius - cutter.corner_radius, cutter.corner_radius
        rho = np.linspace(0, cutter.radius, 40)
        th = np.linspace(0, 2 * np.pi, 72, endpoint=False)
        R, T = np.meshgrid(rho, th)
        h = np.where(R <= a, 0.0, r - np.sqrt(np.maximum(r * r - (R - a) ** 2, 0)))
        for (x, y), tip in zip(xy, z):
            qx, qy = x + R * np.cos(T), y + R * np.sin(T)
            # Mesh height under each sample by interpolating the grid (it is a height field).
            mz = _grid_height(wavy_mesh, qx.ravel(), qy.ravel())
            assert np.all(tip + h.ravel() >= mz - 1e-9), f"{cutter.describe()} gouges at {(x, y)}"
            assert np.min(tip + h.ravel() - mz) < 0.05, f"{cutter.describe()} does not touch at {(x, y)}"


def _grid_height(mesh, qx, qy, nx=40, ny=30):
    """Height of the grid mesh of `wavy_mesh` (unit cells from the origin, split as in grid_mesh) at
    (qx, qy), by locating the cell and interpolating on its triangle: independent of the kernel."""
    zg = mesh.vertices[:, 2].reshape(nx + 1, ny + 1)
    i = np.clip(np.floor(qx).astype(int), 0, nx - 1)
    j = np.clip(np.floor(qy).astype(int), 0, ny - 1)
    u, v = qx - i, qy - j
    za, zb, zc, zd = zg[i, j], zg[i + 1, j], zg[i, j + 1], zg[i + 1, j + 1]
    lower = za + u * (zb - za) + v * (zc - za)
    upper = zd + (1 - u) * (zc - zd) + (1 - v) * (zb - zd)
    z = np.where(u + v <= 1, lower, upper)
    outside = (qx < 0) | (qx > nx) | (qy < 0) | (qy > ny)
    return np.where(outside, -np.inf, z)


def test_threads_agree_and_progress_reports(wavy_mesh):
    surface = DropSurface(wavy_mesh)
    xs, ys = np.meshgrid(np.arange(0, 40, 0.1), np.arange(0, 30, 0.5))
    xy = np.column_stack([xs.ravel(), ys.ravel()])
    cutter = Cutter.bull(6, 1)
    seen = []
    z1 = surface.drop(cutter, xy, -50, threads=1)
    z2 = surface.drop(cutter, xy, -50, threads=2, progress=lambda f: seen.append(f) or True)
    z3 = surface.drop(cutter, xy, -50, threads=3)
    np.testing.assert_array_equal(z1, z2)  # deterministic: the same bits whatever the thread count
    np.testing.assert_array_equal(z1, z3)
    assert seen and seen[-1] == 1.0 and all(b >= a for a, b in zip(seen, seen[1:]))


def test_cancel_raises_cancelled(wavy_mesh):
    surface = DropSurface(wavy_mesh)
    xy = np.tile([[20.0, 15.0]], (3_000_000, 1))
    with pytest.raises(Cancelled):
        surface.drop(Cutter.ball(3), xy, -50, progress=lambda f: False)


def test_exception_in_progress_propagates(wavy_mesh):
    def boom(_f):
        raise KeyError("from callback")
    with pytest.raises(KeyError):
        DropSurface(wavy_mesh).drop(Cutter.ball(3), np.tile([[20.0, 15.0]], (2_000_000, 1)), -50, progress=boom)


def test_floor_where_nothing_is_under_the_cutter(wavy_mesh):
    z = DropSurface(wavy_mesh).drop(Cutter.ball(2), np.array([[100.0, 100.0], [20, 15]]), floor_z=-7.5)
    assert z[0] == -7.5 and z[1] > -7.5


def test_bad_inputs_give_clear_errors(wavy_mesh):
    surface = DropSurface(wavy_mesh)
    with pytest.raises(TmmError, match="non-finite"):
        surface.drop(Cutter.ball(2), np.array([[np.nan, 1.0]]), 0)
    with pytest.raises(TmmError, match="corner radius 4 mm is larger than the cutter radius 3 mm"):
        Cutter(6.0, 4.0)
    with pytest.raises(TmmError, match="diameter"):
        Cutter.ball(0.0)
    with pytest.raises(ValueError, match="corner radius"):
        native.Cutter(1.0, 2.0)
    with pytest.raises(TmmError, match="taper angle beta2 must be in"):
        Cutter(6.0, 0.0, 0.0, 95.0, 10.0)
    with pytest.raises(TmmError, match="stock to leave is not supported"):
        Cutter.vbit(6.0, 90.0).offset(0.2)
    with pytest.raises(ValueError, match="outside"):
        native.MeshIndex(np.zeros((3, 3)), np.array([[0, 1, 5]], dtype=np.int32))
    with pytest.raises(ValueError, match="non-finite"):
        native.MeshIndex(np.array([[0, 0, 0], [1, 0, np.inf], [0, 1, 0]], float),
                         np.array([[0, 1, 2]], dtype=np.int32))


def test_index_reports_size(wavy_mesh):
    idx = native.MeshIndex(wavy_mesh.vertices, wavy_mesh.triangles)
    assert idx.triangle_count == len(wavy_mesh)
    assert idx.memory_bytes < 200 * len(wavy_mesh)
    assert idx.zmax == pytest.approx(wavy_mesh.vertices[:, 2].max())
