"""Waterline loops (core.query.waterline) against closed forms and independent references:
  - a ball over a sphere mesh: the circle of the offset sphere (within the mesh's faceting bound);
  - a flat end mill on a box: the rectangle offset by R, round corners;
  - every loop point's drop height (DropSurface.drop, one call per point set) is z, or the point is free and
    blocked material lies within 1e-6 mm on its left;
  - a dense reference: a 4x denser grid of drops classified blocked/free agrees with the loops' inside
    (even-odd over all loops of the level) everywhere but within the chord tolerance of a loop;
  - OpenCAMLib's Waterline on a real STL: the largest distance between their points and our polylines, and
    the loop count;
  - bad input by name, work refused before allocating, cancel."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SHARED_STL, grid_mesh
from tmm_workbench.core import limits
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.waterline import WaterlineLoop, waterline_loops
from tmm_workbench.core.tools.cutter import Cutter


def uv_sphere(radius: float, centre: tuple[float, float, float], n: int) -> TriMesh:
    """Vertices on the sphere (inscribed facets): n bands, 2n sectors."""
    cx, cy, cz = centre
    m = 2 * n
    th = np.pi * np.arange(1, n) / n
    ph = 2 * np.pi * np.arange(m) / m
    T, P = np.meshgrid(th, ph, indexing="ij")
    ring = np.column_stack([cx + radius * (np.sin(T) * np.cos(P)).ravel(), cy + radius * (np.sin(T) * np.sin(P)).ravel(),
                            cz + radius * np.cos(T).ravel()])
    v = np.vstack([[cx, cy, cz + radius], ring, [cx, cy, cz - radius]])
    last = len(v) - 1

    def idx(i, j):
        return 1 + (i - 1) * m + (j % m)

    f = [[0, idx(1, j), idx(1, j + 1)] for j in range(m)]
    for i in range(1, n - 1):
        for j in range(m):
            f += [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)], [idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]]
    f += [[idx(n - 1, j), last, idx(n - 1, j + 1)] for j in range(m)]
    return TriMesh(v, np.array(f), "sphere")


def box_mesh(x0, y0, x1, y1, top) -> TriMesh:
    v = np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0],
                  [x0, y0, top], [x1, y0, top], [x1, y1, top], [x0, y1, top]], float)
    f = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7],
         [2, 7, 6], [3, 0, 4], [3, 4, 7]]
    return TriMesh(v, np.array(f), "box")


def segments_of(level: list[WaterlineLoop]) -> tuple[np.ndarray, np.ndarray]:
    a = np.vstack([lp.xy for lp in level])
    b = np.vstack([np.roll(lp.xy, -1, axis=0) for lp in level])
    return a, b


def distance_to_polylines(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point to the nearest of the segments a[k] -> b[k] (brute force, chunked)."""
    out = np.empty(len(pts))
    d = b - a
    dd = np.maximum((d * d).sum(1), 1e-300)
    for s in range(0, len(pts), 2000):
        p = pts[s:s + 2000, None, :]
        t = np.clip(((p - a) * d).sum(2) / dd, 0.0, 1.0)
        q = a + t[..., None] * d
        out[s:s + 2000] = np.sqrt(((p - q) ** 2).sum(2)).min(1)
    return out


def inside(pts: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Even-odd rule over all segments (a horizontal ray to +x)."""
    res = np.zeros(len(pts), dtype=bool)
    for s in range(0, len(pts), 2000):
        x, y = pts[s:s + 2000, :1], pts[s:s + 2000, 1:]
        crosses = (a[:, 1] > y) != (b[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        res[s:s + 2000] = (np.sum(crosses & (xc > x), axis=1) % 2) == 1
    return res


def expect_contacts(surface: DropSurface, cutter: Cutter, level: list[WaterlineLoop], exact: bool = False) -> None:
    """Every contact point free (h <= z, to the drops' rounding: the batch and the kernel's single-point drop
    may differ by ~1e-14); h = z within 1e-6, or blocked 1e-6 mm to its left."""
    for lp in level:
        xy = lp.xy[lp.contact]
        if not len(xy):
            continue  # a loop all along the bounds
        h = surface.drop(cutter, xy, lp.z - 100.0)
        assert h.max() <= lp.z + 1e-9, f"a loop point gouges by {h.max() - lp.z:g} mm"
        far = np.abs(h - lp.z) > 1e-6
        if exact:
            assert not far.any(), f"drop heights differ from z by up to {np.abs(h - lp.z).max():g} mm"
        prev = np.roll(lp.xy, 1, axis=0)[lp.contact]
        nxt = np.roll(lp.xy, -1, axis=0)[lp.contact]
        t = nxt - prev
        left = np.column_stack([-t[:, 1], t[:, 0]]) / np.hypot(*t.T)[:, None]
        beside = surface.drop(cutter, (xy + 1e-6 * left)[far], lp.z - 100.0)
        assert (beside > lp.z).all(), "a loop point is neither touching nor next to blocked material"


def test_ball_over_a_sphere_is_the_circle_of_the_offset_sphere():
    Rs, zc, R, n = 10.0, 1.0, 3.0, 96
    surface = DropSurface(uv_sphere(Rs, (5.0, -2.0, zc), n))
    ball = Cutter.ball(2 * R)
    zs = [zc + 7.0, zc - 1.0, zc + 3.0]          # any order: returned in the same order
    levels = waterline_loops(surface, ball, zs, (-15, -20, 25, 15), sample_step=0.6, chord_tol=1e-3)
    facet = Rs * (1 - math.cos(math.pi / n))      # facets lie inside the sphere by at most this
    for z, level in zip(zs, levels):
        assert len(level) == 1 and level[0].z == z
        lp = level[0]
        assert lp.island and lp.contact.all() and lp.area > 0
        dz = z + R - zc
        r = math.sqrt((Rs + R) ** 2 - dz * dz)
        rho = np.hypot(lp.xy[:, 0] - 5.0, lp.xy[:, 1] + 2.0)
        assert rho.max() <= r + 1e-6
        assert rho.min() >= r - facet * (Rs + R) / r - 1e-6
        expect_contacts(surface, ball, level, exact=True)


def test_flat_on_a_box_is_the_box_offset_with_round_corners():
    R = 3.0
    surface = DropSurface(box_mesh(0, 0, 20, 10, 5))
    flat = Cutter.flat(2 * R)
    (level,) = waterline_loops(surface, flat, [2.0], (-10, -10, 30, 20), sample_step=0.7, chord_tol=1e-4)
    assert len(level) == 1
    xy = level[0].xy
    dx = np.maximum.reduce([0 - xy[:, 0], xy[:, 0] - 20, np.zeros(len(xy))])
    dy = np.maximum.reduce([0 - xy[:, 1], xy[:, 1] - 10, np.zeros(len(xy))])
    assert np.abs(np.hypot(dx, dy) - R).max() < 1e-6
    exact = 200 + 2 * R * 30 + math.pi * R * R
    assert exact - 2 * math.pi * R * 1e-4 - 1e-4 <= level[0].area <= exact + 1e-4
    expect_contacts(surface, flat, level)


@pytest.mark.parametrize("cutter", [Cutter.ball(6), Cutter.flat(6), Cutter.bull(8, 1.5)], ids=lambda c: c.kind)
def test_loops_match_a_dense_drop_grid(cutter):
    """A relief of bumps and a pit: islands and a pocket; the reference classifies a 4x denser grid."""
    def relief(x, y):
        return (6 * np.exp(-((x - 15) ** 2 + (y - 15) ** 2) / 40) + 5 * np.exp(-((x - 32) ** 2 + (y - 22) ** 2) / 25)
                - 4 * np.exp(-((x - 22) ** 2 + (y - 32) ** 2) / 20))
    mesh = grid_mesh(relief, 60, 60, (0, 0, 45, 45))
    surface = DropSurface(mesh)
    step, tol = 0.8, 2e-3
    zs = [-2.0, 1.0, 3.0]
    levels = waterline_loops(surface, cutter, zs, (0, 0, 45, 45), sample_step=step, chord_tol=tol)
    g = np.arange(0.0, 45.0 + 1e-9, step / 4)
    nodes = np.column_stack([c.ravel() for c in np.meshgrid(g, g)])
    h = surface.drop(cutter, nodes, -100.0)
    kinds = set()
    for z, level in zip(zs, levels):
        assert level, f"no loop at z {z}"
        for lp in level:
            kinds.add(lp.island)
        expect_contacts(surface, cutter, level)
        a, b = segments_of(level)
        near = distance_to_polylines(nodes, a, b) <= tol + 1e-6
        disagree = (inside(nodes, a, b) != (h > z)) & ~near
        assert not disagree.any(), f"z {z}: {disagree.sum()} dense nodes disagree, e.g. {nodes[disagree][:3]}"
    assert kinds == {True, False}  # islands (the bumps) and a pocket (the pit below the plane at z -2)


def test_opencamlib_waterline_agrees_on_a_real_stl():
    ocl = pytest.importorskip("opencamlib").ocl  # the peer, where it is installed
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    surf = ocl.STLSurf()
    v = mesh.vertices
    for a, b, c in mesh.triangles:
        surf.addTriangle(ocl.Triangle(ocl.Point(*v[a]), ocl.Point(*v[b]), ocl.Point(*v[c])))
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    for cutter, peer in [(Cutter.ball(6), ocl.BallCutter(6.0, 50.0)), (Cutter.flat(6), ocl.CylCutter(6.0, 50.0)),
                         (Cutter.bull(10, 2), ocl.BullCutter(10.0, 2.0, 50.0))]:
        z, tol = 15.0, 1e-3
        (ours,) = waterline_loops(surface, cutter, [z], (lo[0] - 8, lo[1] - 8, hi[0] + 8, hi[1] + 8),
                                  sample_step=0.5, chord_tol=tol)
        w = ocl.Waterline()
        w.setSTL(surf)
        w.setCutter(peer)
        w.setZ(z)
        w.setSampling(0.5)
        w.run()
        theirs = [np.array([[p.x, p.y] for p in loop]) for loop in w.getLoops()]
        assert len(ours) == len(theirs) == 1
        a, b = segments_of(ours)
        assert distance_to_polylines(theirs[0], a, b).max() < 1.5 * tol
        ta, tb = theirs[0], np.roll(theirs[0], -1, axis=0)
        # their polyline's chords are as long as their sampling: our points lie on or beside them by its sagitta
        assert distance_to_polylines(ours[0].xy, ta, tb).max() < 0.02


def test_bad_input_is_refused_by_name_and_work_before_allocating():
    surface = DropSurface(box_mesh(0, 0, 20, 10, 5))
    ball = Cutter.ball(6)
    with pytest.raises(TmmError, match="bounds are empty"):
        waterline_loops(surface, ball, [1.0], (0, 0, 0, 10))
    with pytest.raises(TmmError, match="waterline level z must be a finite number, got nan"):
        waterline_loops(surface, ball, [1.0, math.nan], (0, 0, 10, 10))
    with pytest.raises(TmmError, match="waterline bounds xmax must be a finite number"):
        waterline_loops(surface, ball, [1.0], (0, 0, math.inf, 10))
    with pytest.raises(TmmError, match="sample step must be a positive length, got -1"):
        waterline_loops(surface, ball, [1.0], (0, 0, 10, 10), sample_step=-1)
    with pytest.raises(TmmError, match=r"chord tolerance must be in \(0, 1\] mm, got 0"):
        waterline_loops(surface, ball, [1.0], (0, 0, 10, 10), chord_tol=0)
    old = limits.set_limits(max_points=1_000_000)
    try:
        with pytest.raises(TmmError, match=r"sample step 0.01 mm over a 100 x 100 mm boundary and 3 waterline levels"):
            waterline_loops(surface, ball, [1.0, 2.0, 3.0], (0, 0, 100, 100), sample_step=0.01)
    finally:
        limits.set_limits(max_points=old.max_points)
    assert waterline_loops(surface, ball, [], (0, 0, 10, 10)) == []


def test_cancel_and_progress():
    surface = DropSurface(uv_sphere(10, (0, 0, 0), 48))
    seen = []

    def stop(fraction):
        seen.append(fraction)
        return False

    with pytest.raises(Cancelled):
        waterline_loops(surface, Cutter.ball(6), [0.0, 2.0, 4.0], (-15, -15, 15, 15), sample_step=0.02,
                        progress=stop)
    assert seen
    fractions = []
    waterline_loops(surface, Cutter.ball(6), [0.0, 2.0], (-15, -15, 15, 15), sample_step=0.5,
                    progress=lambda f: fractions.append(f) is None)
    assert fractions and fractions[-1] == pytest.approx(1.0) and fractions == sorted(fractions)
