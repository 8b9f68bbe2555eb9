"""Bézier patches: evaluation against independent formulas, derivatives, tessellation, the seed 001 patches."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SEED_JSON
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.errors import TmmError

DEGREES = [(1, 1), (2, 3), (3, 3), (5, 2), (0, 4)]


def random_net(m: int, n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed + 31 * m + n)
    i, j = np.meshgrid(np.arange(m + 1), np.arange(n + 1), indexing="ij")
    net = np.stack([10.0 * i, 12.0 * j, np.zeros_like(i, dtype=float)], axis=-1)
    return net + rng.normal(scale=4.0, size=net.shape)


def de_casteljau(net: np.ndarray, u: float, v: float) -> np.ndarray:
    """Repeated linear interpolation: rows in u first, then the resulting curve in v."""
    pts = np.array(net, dtype=float)
    while pts.shape[0] > 1:
        pts = (1 - u) * pts[:-1] + u * pts[1:]
    curve = pts[0]
    while curve.shape[0] > 1:
        curve = (1 - v) * curve[:-1] + v * curve[1:]
    return curve[0]


def bernstein_sum(net: np.ndarray, u: float, v: float) -> np.ndarray:
    m, n = net.shape[0] - 1, net.shape[1] - 1
    s = np.zeros(3)
    for i in range(m + 1):
        for j in range(n + 1):
            b = math.comb(m, i) * u ** i * (1 - u) ** (m - i) * math.comb(n, j) * v ** j * (1 - v) ** (n - j)
            s += b * net[i, j]
    return s


@pytest.fixture
def seed_json() -> Path:
    assert SEED_JSON.is_file(), f"shared benchmark data not found at {SEED_JSON}"
    return SEED_JSON


def test_bernstein_is_a_partition_of_unity() -> None:
    t = np.linspace(0, 1, 101)
    for deg in range(7):
        b = bezier.bernstein(deg, t)
        assert b.shape == (101, deg + 1)
        assert (b >= 0).all()
        np.testing.assert_allclose(b.sum(axis=1), 1.0, atol=1e-14)


@pytest.mark.parametrize("m,n", DEGREES)
def test_evaluate_matches_de_casteljau_and_bernstein_sums(m: int, n: int) -> None:
    net = random_net(m, n)
    rng = np.random.default_rng(1)
    u, v = rng.random(40), rng.random(40)
    got = bezier.evaluate(net, u, v)
    assert got.shape == (40, 3)
    for k in range(40):
        np.testing.assert_allclose(got[k], de_casteljau(net, u[k], v[k]), atol=1e-10)
        np.testing.assert_allclose(got[k], bernstein_sum(net, u[k], v[k]), atol=1e-10)


def test_evaluate_grid_matches_paired_evaluation() -> None:
    net = random_net(3, 2)
    u, v = np.linspace(0, 1, 7), np.linspace(0, 1, 5)
    grid = bezier.evaluate_grid(net, u, v)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    np.testing.assert_allclose(grid, bezier.evaluate(net, uu, vv), atol=1e-12)
    assert grid.shape == (7, 5, 3)


@pytest.mark.parametrize("m,n", DEGREES)
def test_patch_interpolates_corners_and_boundary_curves(m: int, n: int) -> None:
    net = random_net(m, n)
    corners = bezier.evaluate(net, np.array([0, 1, 0, 1]), np.array([0, 0, 1, 1]))
    np.testing.assert_allclose(corners, [net[0, 0], net[m, 0], net[0, n], net[m, n]], atol=1e-12)
    # The boundary v = 0 is the Bézier curve of the first column of the net.
    t = np.linspace(0, 1, 9)
    curve = bezier.bernstein(m, t) @ net[:, 0]
    np.testing.assert_allclose(bezier.evaluate(net, t, np.zeros_like(t)), curve, atol=1e-12)


@pytest.mark.parametrize("m,n", DEGREES)
def test_derivatives_match_finite_differences(m: int, n: int) -> None:
    net = random_net(m, n)
    rng = np.random.default_rng(2)
    u, v = 0.1 + 0.8 * rng.random(15), 0.1 + 0.8 * rng.random(15)
    d = bezier.derivatives(net, u, v)
    h = 1e-4
    S = lambda du, dv: bezier.evaluate(net, u + du, v + dv)  # noqa: E731
    np.testing.assert_allclose(d["S"], S(0, 0), atol=1e-12)
    np.testing.assert_allclose(d["Su"], (S(h, 0) - S(-h, 0)) / (2 * h), atol=1e-5)
    np.testing.assert_allclose(d["Sv"], (S(0, h) - S(0, -h)) / (2 * h), atol=1e-5)
    h = 1e-3
    np.testing.assert_allclose(d["Suu"], (S(h, 0) - 2 * S(0, 0) + S(-h, 0)) / h ** 2, atol=1e-3)
    np.testing.assert_allclose(d["Svv"], (S(0, h) - 2 * S(0, 0) + S(0, -h)) / h ** 2, atol=1e-3)
    np.testing.assert_allclose(d["Suv"], (S(h, h) - S(h, -h) - S(-h, h) + S(-h, -h)) / (4 * h * h), atol=1e-3)


def test_corner_tangents_are_scaled_net_edges() -> None:
    net = random_net(3, 2)
    d = bezier.derivatives(net, np.array([0.0]), np.array([0.0]))
    np.testing.assert_allclose(d["Su"][0], 3 * (net[1, 0] - net[0, 0]), atol=1e-12)
    np.testing.assert_allclose(d["Sv"][0], 2 * (net[0, 1] - net[0, 0]), atol=1e-12)
    nrm = bezier.normals(net, np.array([0.0]), np.array([0.0]))[0]
    expect = np.cross(d["Su"][0], d["Sv"][0])
    np.testing.assert_allclose(nrm, expect / np.linalg.norm(expect), atol=1e-12)


@pytest.mark.parametrize("axis", [0, 1])
def test_degree_elevation_keeps_the_surface(axis: int) -> None:
    net = random_net(3, 2)
    up = bezier.elevate_degree(net, axis)
    assert up.shape[axis] == net.shape[axis] + 1
    twice = bezier.elevate_degree(bezier.elevate_degree(up, 1 - axis), axis)
    u, v = np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 1, 9), indexing="ij")
    ref = bezier.evaluate(net, u, v)
    np.testing.assert_allclose(bezier.evaluate(up, u, v), ref, atol=1e-10)
    np.testing.assert_allclose(bezier.evaluate(twice, u, v), ref, atol=1e-10)
    d0, d1 = bezier.derivatives(net, u, v), bezier.derivatives(twice, u, v)
    for k in ("Su", "Svv", "Suv"):
        np.testing.assert_allclose(d1[k], d0[k], atol=1e-8)


def test_bad_nets_are_rejected() -> None:
    with pytest.raises(TmmError):
        bezier.as_net(np.zeros((3, 3)))
    with pytest.raises(TmmError):
        bezier.as_net(np.full((2, 2, 3), np.nan))
    with pytest.raises(TmmError):
        bezier.grid_for_tolerance(random_net(2, 2), 0.0)


def test_flat_bilinear_patch_needs_one_cell() -> None:
    net = np.array([[[0, 0, 0], [0, 10, 0]], [[10, 0, 0], [10, 10, 0]]], dtype=float)
    assert bezier.grid_for_tolerance(net, 1e-6) == (1, 1)


def test_seed_patches_follow_the_table(seed_json: Path) -> None:
    convex = bezier.load_seed_patch(seed_json, "convex")
    concave = bezier.load_seed_patch(seed_json, "concave")
    assert convex.shape == concave.shape == (4, 4, 3)
    np.testing.assert_array_equal(convex[:, :, 0], 50.0 * np.arange(4)[:, None] * np.ones((1, 4)))
    np.testing.assert_array_equal(convex[:, :, 1], 50.0 * np.arange(4)[None, :] * np.ones((4, 1)))
    assert convex[0, 1, 2] == 90 and convex[1, 1, 2] == 105 and concave[1, 1, 2] == 55  # P01, P11
    # Centre height from the cubic Bernstein weights at 1/2: (1, 3, 3, 1) / 8 each way.
    w = np.array([1, 3, 3, 1]) / 8
    centre = bezier.evaluate(convex, np.array([0.5]), np.array([0.5]))[0]
    np.testing.assert_allclose(centre, [75, 75, w @ convex[:, :, 2] @ w], atol=1e-12)
    assert centre[2] > 80 > bezier.evaluate(concave, np.array([0.5]), np.array([0.5]))[0, 2]
    saddle = bezier.load_seed_patch(seed_json, "saddle")  # seed 001 table 1: P01 65, P11 85, P33 85
    np.testing.assert_array_equal(saddle[:, :, :2], convex[:, :, :2])
    assert (saddle[0, 1, 2], saddle[1, 1, 2], saddle[3, 3, 2]) == (65, 85, 85)
    with pytest.raises(TmmError, match="'convex', 'concave' or 'saddle', got 'flat'"):
        bezier.load_seed_patch(seed_json, "flat")


def test_tessellation_counts_bounds_and_orientation(seed_json: Path) -> None:
    net = bezier.load_seed_patch(seed_json, "convex")
    mesh = bezier.tessellate(net, 12, 7)
    assert len(mesh.triangles) == 2 * 12 * 7
    assert len(mesh.vertices) == 13 * 8
    lo, hi = mesh.bounds
    np.testing.assert_allclose(lo[:2], [0, 0], atol=1e-12)
    np.testing.assert_allclose(hi[:2], [150, 150], atol=1e-12)
    assert net[:, :, 2].min() <= lo[2] and hi[2] <= net[:, :, 2].max()  # convex hull property
    c = mesh.vertices[mesh.triangles]
    nz = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])[:, 2]
    assert (nz > 0).all()  # facets face up, like Su x Sv
    with pytest.raises(TmmError):
        bezier.tessellate(net, 0, 5)


@pytest.mark.parametrize("tol", [0.5, 0.05, 0.01])
def test_tessellation_meets_its_chordal_tolerance(seed_json: Path, tol: float) -> None:
    net = bezier.load_seed_patch(seed_json, "concave")
    nu, nv = bezier.grid_for_tolerance(net, tol)
    mesh = bezier.tessellate_to_tolerance(net, tol)
    assert len(mesh.triangles) == 2 * nu * nv
    assert bezier.chordal_error_bound(net, nu, nv) <= tol
    # Measure: random barycentric points of every triangle against the surface at the same (u, v).
    uv = np.stack(np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nv + 1), indexing="ij"),
                  axis=-1).reshape(-1, 2)
    rng = np.random.default_rng(3)
    w = rng.dirichlet(np.ones(3), size=len(mesh.triangles))
    w[:8] = 1 / 3  # centroids too
    flat = np.einsum("tk,tkc->tc", w, mesh.vertices[mesh.triangles])
    par = np.einsum("tk,tkc->tc", w, uv[mesh.triangles])
    err = np.linalg.norm(bezier.evaluate(net, par[:, 0], par[:, 1]) - flat, axis=1).max()
    assert err <= tol
    assert err >= tol / 10  # the bound is conservative but not wildly so
