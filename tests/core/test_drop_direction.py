"""Drop along any direction with any cutter axis, through the binding, on a real mesh: the -Z case equals
the fast drop-cutter, tilted drops touch without gouging (checked by an independent numpy reference:
dense samples of the nearby triangles against the cutter solid in the tool frame), errors, cancel."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SHARED_STL
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_direction import DirectionalDrop, drop_along
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.geometry.mesh import load_stl

STL = SHARED_STL / "sphere_on_plate.stl"


@pytest.fixture(scope="module")
def mesh():
    assert STL.exists(), f"{STL} missing: the shared benchmark files are part of the test set-up"
    return load_stl(STL)


def _starts(mesh, n, rng, lift=20.0):
    lo, hi = mesh.bounds
    xy = rng.uniform(lo[:2] + 5, hi[:2] - 5, size=(n, 2))
    return np.column_stack([xy, np.full(n, hi[2] + lift)])


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _frame(axis):
    """Tool frame rows (e1, e2, a); any orthonormal completion works for a solid of revolution."""
    a = _unit(axis)
    ref = np.array([1.0, 0, 0]) if abs(a[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = _unit(ref - ref.dot(a) * a)
    return np.array([e1, np.cross(a, e1), a])


def _clearance(ncut, q):
    """G(q) <= 0 exactly inside the cutter solid {h(rho) <= z <= L_C, rho <= max_radius} (tool frame)."""
    rho = np.hypot(q[:, 0], q[:, 1])
    rr = np.minimum(rho, ncut.max_radius)
    return np.maximum.reduce([ncut.height(rr) - q[:, 2], q[:, 2] - ncut.cutting_length, rho - ncut.max_radius])


def _triangle_samples(corners, n=24):
    """Barycentric grid of each (m, 3, 3) triangle: (m * k, 3) points, corners and edges included."""
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    u, v = (i[keep] / n)[:, None], (j[keep] / n)[:, None]
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return (a[:, None] + (b - a)[:, None] * u[None] + (c - a)[:, None] * v[None]).reshape(-1, 3)


def _plane_samples(tri, centre, radius, step):
    """Points of a large triangle within `radius` of `centre`: a square grid of `step` in its plane, plus
    its corners and points along its edges."""
    a, b, c = tri
    n = _unit(np.cross(b - a, c - a))
    e1 = _unit(b - a)
    e2 = np.cross(n, e1)
    foot = centre - n * n.dot(centre - a)
    k = np.arange(-radius, radius + step, step)
    U, W = np.meshgrid(k, k)
    p = foot + U.reshape(-1, 1) * e1 + W.reshape(-1, 1) * e2
    # Barycentric inside test.
    v0, v1, v2 = b - a, c - a, p - a
    d00, d01, d11 = v0 @ v0, v0 @ v1, v1 @ v1
    d20, d21 = v2 @ v0, v2 @ v1
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    s = np.linspace(0, 1, 501)[:, None]
    edges = np.concatenate([a + (b - a) * s, b + (c - b) * s, c + (a - c) * s])
    return np.concatenate([p[inside], edges])


def _check_touch_no_gouge(mesh, ncut, tips, axis, reach, touch_tol):
    corners = mesh.vertices[mesh.triangles]
    centres = corners.mean(axis=1)
    sizes = np.linalg.norm(corners - centres[:, None], axis=2).max(axis=1)
    fr = _frame(axis)
    for tip in tips:
        centre = tip + fr[2] * ncut.cutting_length / 2
        near = np.flatnonzero(np.linalg.norm(centres - centre, axis=1) <= reach + sizes)
        small, large = near[sizes[near] <= 2.0], near[sizes[near] > 2.0]
        # Coarse pass over everything near, then a fine pass about the least-clearance sample.
        pts = np.concatenate([_triangle_samples(corners[small], 12)] +
                             [_plane_samples(corners[k], centre, reach, 0.5) for k in large])
        g = _clearance(ncut, (pts - tip) @ fr.T)
        focus = pts[np.argmin(g)]
        close = near[np.linalg.norm(centres[near] - focus, axis=1) <= 1.0 + sizes[near]]
        fine = [_triangle_samples(corners[close[sizes[close] <= 2.0]], 40)] + \
               [_plane_samples(corners[k], focus, 1.0, 0.02) for k in close[sizes[close] > 2.0]]
        g = np.concatenate([g, _clearance(ncut, (np.concatenate(fine) - tip) @ fr.T)])
        assert g.min() >= -1e-9, f"gouge {g.min():.3g} at tip {tip}"
        # Vertices are samples, so touching a vertex gives 0; an edge or facet contact lies between samples.
        assert g.min() <= touch_tol, f"no touch ({g.min():.3g}) at tip {tip}"


def test_minus_z_equals_fast_path(mesh):
    rng = np.random.default_rng(1)
    starts = _starts(mesh, 2000, rng)
    surface = DropSurface(mesh)
    dd = DirectionalDrop(mesh, [0, 0, -1])
    for cutter in (Cutter.ball(6), Cutter.bull(10, 2), Cutter.flat(4), Cutter.vbit(6, 90)):
        z = surface.drop(cutter, starts[:, :2], floor_z=-1e6)
        travel, tips = dd.drop(cutter, starts, [0, 0, 1])
        np.testing.assert_allclose(starts[:, 2] - travel, z, rtol=0, atol=1e-12)
        np.testing.assert_allclose(tips[:, 2], z, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(tips[:, :2], starts[:, :2])


def test_tilted_axis_vertical_drop_touches_without_gouge(mesh):
    """3+2: the axis tilted 25 degrees, dropped along -Z."""
    rng = np.random.default_rng(2)
    starts = _starts(mesh, 25, rng)
    tilt = math.radians(25)
    axis = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    cutter = Cutter(6, 3, cutting_length=15)
    travel, tips = drop_along(mesh, cutter, starts, axis, [0, 0, -1])
    assert np.isfinite(travel).all()
    ncut = native.Cutter.apt(3, 3, 15, 0, 0)
    _check_touch_no_gouge(mesh, ncut, tips, axis, reach=math.hypot(3, 15), touch_tol=0.05)


def test_tilted_direction_and_axis_touch_without_gouge(mesh):
    """Clean-up style: the cutter translated along an oblique V with another axis; several cutter kinds."""
    rng = np.random.default_rng(3)
    V = _unit([0.3, -0.2, -1.0])
    axis = _unit([-0.2, 0.35, 1.0])
    dd = DirectionalDrop(mesh, V)
    cases = [
        (Cutter(8, 2, cutting_length=20), native.Cutter.apt(4, 2, 20, 0, 0)),
        (Cutter(6, 0, cutting_length=12), native.Cutter.apt(3, 0, 12, 0, 0)),
        (Cutter.vbit(6, 60), None),
        (Cutter(10, 1.5, bottom_angle_deg=10, taper_angle_deg=8, cutting_length=16), None),
    ]
    for cutter, ncut in cases:
        ncut = ncut or cutter.native
        starts = _starts(mesh, 15, rng, lift=40.0)
        travel, tips = dd.drop(cutter, starts, axis)
        hit = np.isfinite(travel)
        assert hit.mean() >= 0.5, cutter.describe()  # an oblique path may leave the plate
        np.testing.assert_allclose(tips[hit], starts[hit] + travel[hit, None] * V, atol=1e-12)
        assert np.isnan(tips[~hit]).all()
        _check_touch_no_gouge(mesh, ncut, tips[hit], axis, reach=math.hypot(ncut.max_radius, ncut.cutting_length),
                              touch_tol=0.05)
        # The batch equals the minimum over the triangles near each start of the one-triangle query.
        corners = mesh.vertices[mesh.triangles]
        centres = corners.mean(axis=1)
        sizes = np.linalg.norm(corners - centres[:, None], axis=2).max(axis=1)
        for s, t in zip(starts[:5], travel[:5]):
            d = np.cross(centres - s, V)  # distance of each triangle from the tip's path
            near = np.flatnonzero(np.linalg.norm(d, axis=1) < 30 + sizes)
            ref = min(native.drop_along_triangle(ncut, s, axis, V, corners[k]) for k in near)
            assert ref == pytest.approx(t, abs=1e-9)


def test_axis_per_point_and_max_travel(mesh):
    rng = np.random.default_rng(4)
    starts = _starts(mesh, 50, rng)
    dd = DirectionalDrop(mesh, [0, 0, -1])
    axes = np.array([_unit([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 1]) for _ in range(50)])
    cutter = Cutter(6, 3, cutting_length=15)
    travel, _ = dd.drop(cutter, starts, axes)
    for k in range(0, 50, 10):
        t1, _ = dd.drop(cutter, starts[k:k + 1], axes[k])
        assert t1[0] == pytest.approx(travel[k], abs=1e-9)
    capped, tips = dd.drop(cutter, starts, axes, max_travel=1.0)
    assert np.all(capped <= 1.0) and np.isfinite(tips).all()


def test_threads_and_progress(mesh):
    rng = np.random.default_rng(5)
    starts = _starts(mesh, 3000, rng)
    dd = DirectionalDrop(mesh, _unit([0.1, 0.2, -1]))
    axis = _unit([0, -0.3, 1])
    cutter = Cutter(6, 3, cutting_length=15)
    t1, _ = dd.drop(cutter, starts, axis, threads=1)
    seen = []
    t2, _ = dd.drop(cutter, starts, axis, threads=2, progress=lambda f: seen.append(f) or True)
    np.testing.assert_allclose(t1, t2, rtol=0, atol=1e-9)
    assert seen and seen[-1] == 1.0 and all(b >= a for a, b in zip(seen, seen[1:]))


def test_errors(mesh):
    starts = np.array([[10.0, 10.0, 50.0]])
    cutter = Cutter(6, 3, cutting_length=15)
    with pytest.raises(TmmError, match="zero"):
        DirectionalDrop(mesh, [0, 0, 0])
    with pytest.raises(TmmError, match="unit"):
        DirectionalDrop(mesh, [0, 0, -2])
    with pytest.raises(TmmError, match="non-finite"):
        DirectionalDrop(mesh, [0, float("nan"), -1])
    with pytest.raises(TmmError, match="3 components"):
        DirectionalDrop(mesh, [0, -1])
    dd = DirectionalDrop(mesh, [0, 0, -1])
    with pytest.raises(TmmError, match="unit"):
        dd.drop(cutter, starts, [0, 0.5, 0.5])
    with pytest.raises(TmmError, match="non-finite"):
        dd.drop(cutter, np.array([[1.0, float("nan"), 2.0]]), [0, 0, 1])
    with pytest.raises(TmmError, match="shape"):
        dd.drop(cutter, np.zeros((3, 2)), [0, 0, 1])
    with pytest.raises(TmmError, match="axes must have shape"):
        dd.drop(cutter, starts, np.array([[0, 0, 1.0], [0, 0, 1.0]]))
    with pytest.raises(TmmError, match="max_travel"):
        dd.drop(cutter, starts, [0, 0, 1], max_travel=float("nan"))
    # A tilted drop needs the cutting length (the shank is not modelled); along the axis it does not.
    with pytest.raises(TmmError, match="cutting length"):
        dd.drop(Cutter.ball(6), starts, _unit([0, 0.3, 1]))
    dd.drop(Cutter.ball(6), starts, [0, 0, 1])
    with pytest.raises(TmmError):
        Cutter(6, 4)  # corner radius above the radius: impossible cutter


def test_cancel_raises_cancelled(mesh):
    dd = DirectionalDrop(mesh, [0, 0, -1])
    starts = np.tile([[40.0, 40.0, 60.0]], (400_000, 1))
    with pytest.raises(Cancelled):
        dd.drop(Cutter(6, 3, cutting_length=15), starts, _unit([0.2, 0, 1]), progress=lambda f: False)
