"""The waterline's adaptive grid (waterline_loops(min_step=...)) against a uniform fine grid as the slow reference:
  - a real STL (sphere_on_plate.stl) and a relief with islands and a pocket, ball / flat / bull: the same loops
    (count and orientation), every reference loop within the fine step of one of ours, our points exact
    (drop height z within 1e-6 mm or blocked beside), the reference's points within the chord tolerance of our
    polylines;
  - a bump between the coarse nodes: missed by the coarse grid alone, found by the adaptive one;
  - results independent of the thread count; a bad minimum step refused by name."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import SHARED_STL, grid_mesh
from tests.core.test_waterline import distance_to_polylines, expect_contacts, segments_of
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.waterline import WaterlineLoop, waterline_loops
from tmm_workbench.core.tools.cutter import Cutter

CUTTERS = [Cutter.ball(6), Cutter.flat(6), Cutter.bull(8, 1.5)]


def expect_like_reference(level: list[WaterlineLoop], ref: list[WaterlineLoop], fine: float, tol: float) -> None:
    assert len(level) == len(ref), f"{len(level)} loops against the reference's {len(ref)}"
    assert sorted(lp.island for lp in level) == sorted(lp.island for lp in ref)
    for r in ref:  # each reference loop lies along one of ours of the same orientation
        d = min(distance_to_polylines(r.xy, *segments_of([lp])).max() for lp in level if lp.island == r.island)
        assert d <= fine, f"a reference loop of area {r.area:.4g} lies {d:.4g} mm from ours"
    a, b = segments_of(level)
    # the reference's points are exact crossings too: within the tolerance of our chords (probed at 3/4 of it at
    # the middles and quarters: 4/3 of that bounds a loop bending one way between two points, docs/waterline.md)
    assert distance_to_polylines(np.vstack([r.xy for r in ref]), a, b).max() <= tol + 1e-6


@pytest.mark.parametrize("cutter", CUTTERS, ids=lambda c: c.kind)
def test_adaptive_grid_matches_a_uniform_fine_grid_on_a_real_stl(cutter):
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    g = cutter.radius + 1.0
    bounds = (lo[0] - g, lo[1] - g, hi[0] + g, hi[1] + g)
    zs = [float(lo[2] + f * (hi[2] - lo[2])) for f in (0.37, 0.81)]
    tol, fine = 3e-3, 0.125
    levels = waterline_loops(surface, cutter, zs, bounds, sample_step=1.0, min_step=fine, chord_tol=tol)
    refs = waterline_loops(surface, cutter, zs, bounds, sample_step=fine, chord_tol=tol)
    for level, ref in zip(levels, refs):
        expect_like_reference(level, ref, fine, tol)
        expect_contacts(surface, cutter, level)


@pytest.mark.parametrize("cutter", CUTTERS, ids=lambda c: c.kind)
def test_adaptive_grid_matches_a_uniform_fine_grid_on_islands_and_a_pocket(cutter):
    def relief(x, y):
        return (6 * np.exp(-((x - 15) ** 2 + (y - 15) ** 2) / 40) + 5 * np.exp(-((x - 32) ** 2 + (y - 22) ** 2) / 25)
                - 4 * np.exp(-((x - 22) ** 2 + (y - 32) ** 2) / 20))
    surface = DropSurface(grid_mesh(relief, 60, 60, (0, 0, 45, 45)))
    zs = [-2.0, 1.0, 3.0, 4.9]
    tol, fine = 2e-3, 0.125
    levels = waterline_loops(surface, cutter, zs, (0, 0, 45, 45), sample_step=2.0, min_step=fine, chord_tol=tol)
    refs = waterline_loops(surface, cutter, zs, (0, 0, 45, 45), sample_step=fine, chord_tol=tol)
    for level, ref in zip(levels, refs):
        expect_like_reference(level, ref, fine, tol)
        expect_contacts(surface, cutter, level)


def spike_on_plane(apex: tuple[float, float], top: float, half_width: float) -> TriMesh:
    ax, ay = apex
    w = half_width
    v = np.array([[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0],
                  [ax - w, ay - w, 0], [ax + w, ay - w, 0], [ax + w, ay + w, 0], [ax - w, ay + w, 0], [ax, ay, top]],
                 float)
    f = [[0, 1, 2], [0, 2, 3], [4, 5, 8], [5, 6, 8], [6, 7, 8], [7, 4, 8]]
    return TriMesh(v, np.array(f), "spike")


def test_a_bump_between_the_coarse_nodes_is_found():
    ball = Cutter.ball(6)
    surface = DropSurface(spike_on_plane((0.5, 0.5), 1.0, 0.05))
    rho = 0.3  # the loop: the ball touching the apex at rho from its axis; its lift there is R - sqrt(R^2 - rho^2)
    z = 1.0 - (3.0 - np.sqrt(9.0 - rho * rho))
    bounds = (-5, -5, 5, 5)  # nodes at whole millimetres: the apex 0.71 mm from the nearest, below z there
    assert waterline_loops(surface, ball, [z], bounds, sample_step=1.0, chord_tol=1e-4) == [[]]
    (level,) = waterline_loops(surface, ball, [z], bounds, sample_step=1.0, min_step=0.05, chord_tol=1e-4)
    assert len(level) == 1 and level[0].island
    assert np.abs(np.hypot(level[0].xy[:, 0] - 0.5, level[0].xy[:, 1] - 0.5) - rho).max() < 1e-6
    expect_contacts(surface, ball, level, exact=True)
    (ref,) = waterline_loops(surface, ball, [z], bounds, sample_step=0.0625, chord_tol=1e-4)
    expect_like_reference(level, ref, 0.0625, 1e-4)


def test_threads_give_identical_loops_and_bad_minimum_step_is_refused():
    mesh = load_stl(SHARED_STL / "mount_rush.stl")
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    ball = Cutter.ball(6)
    bounds = (lo[0] - 4, lo[1] - 4, hi[0] + 4, hi[1] + 4)
    zs = [float(lo[2] + f * (hi[2] - lo[2])) for f in (0.62, 0.37)]
    one = waterline_loops(surface, ball, zs, bounds, sample_step=1.0, min_step=0.0625, chord_tol=3e-3, threads=1)
    two = waterline_loops(surface, ball, zs, bounds, sample_step=1.0, min_step=0.0625, chord_tol=3e-3, threads=2)
    for a, b in zip(one, two):
        assert len(a) == len(b)
        for p, q in zip(a, b):
            assert np.array_equal(p.xy, q.xy) and np.array_equal(p.contact, q.contact)
    for bad in (-0.1, 0.0, 2.0, 1e-3, float("nan")):
        with pytest.raises(TmmError, match="minimum step"):
            waterline_loops(surface, ball, zs, bounds, sample_step=1.0, min_step=bad)


# Features of the free side narrower than the finest square: the loop's tip is found by bisection on the drop
# along the feature's axis (the slow, independent reference), and our loop must pass within the chord tolerance
# of it; a uniform fine grid is the reference for the rest of the loop.

def tent(a: tuple[float, float], b: tuple[float, float], top: float, half_base: float) -> tuple[np.ndarray, list]:
    """A ridge along a -> b at height `top`, its two faces sloping to z 0 at `half_base` on either side."""
    a_, b_ = np.array(a, float), np.array(b, float)
    d = (b_ - a_) / np.linalg.norm(b_ - a_)
    n = np.array([-d[1], d[0]]) * half_base
    v = [[*a_, top], [*b_, top], [*(a_ + n), 0], [*(b_ + n), 0], [*(a_ - n), 0], [*(b_ - n), 0]]
    return np.array(v, float), [[0, 2, 3], [0, 3, 1], [0, 1, 5], [0, 5, 4], [0, 4, 2], [1, 3, 5]]


def pyramid(apex: tuple[float, float], top: float, half_base: float) -> tuple[np.ndarray, list]:
    ax, ay = apex
    w = half_base
    v = [[ax - w, ay - w, 0], [ax + w, ay - w, 0], [ax + w, ay + w, 0], [ax - w, ay + w, 0], [ax, ay, top]]
    return np.array(v, float), [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]


def on_plate(parts: list[tuple[np.ndarray, list]], half: float) -> TriMesh:
    v = [np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]], float)]
    f = [[0, 1, 2], [0, 2, 3]]
    for pv, pf in parts:
        base = sum(len(x) for x in v)
        v.append(pv)
        f += [[i + base for i in t] for t in pf]
    return TriMesh(np.vstack(v), np.array(f), "features")


def tip_along(surface: DropSurface, cutter: Cutter, z: float, origin, direction, t_blocked: float,
              t_free: float) -> np.ndarray:
    """The boundary between a blocked and a free point of the line origin + t direction (bisection on drops)."""
    o, d = np.array(origin, float), np.array(direction, float)
    def blocked(t: float) -> bool:
        return float(surface.drop(cutter, (o + t * d)[None, :], z - 100.0)[0]) > z
    assert blocked(t_blocked) and not blocked(t_free)
    for _ in range(60):
        t = 0.5 * (t_blocked + t_free)
        if blocked(t):
            t_blocked = t
        else:
            t_free = t
    return o + t_free * d


def test_the_tip_of_a_free_crack_narrower_than_the_finest_square_is_reached():
    """A ball between two ridges meeting at 16 degrees: a free crack narrowing to a point in the blocked region
    (mount_rush.stl's neck and pocket end); its last 0.1 mm are narrower than the finest square (1/32 mm). A
    uniform 1/16 mm grid stops 0.014 mm short of the tip, the 0.5 mm grid alone 0.1 mm."""
    ball = Cutter.ball(6)
    top, z = 1.0, 0.5
    turn, half = np.radians(30.0), np.radians(8.0)  # the crack's axis, its half angle
    apex = np.array([-9.27, -4.33])
    arms = [apex + 28 * np.array([np.cos(turn + s * half), np.sin(turn + s * half)]) for s in (-1, 1)]
    surface = DropSurface(on_plate([tent(apex, arm, top, 0.02) for arm in arms], 25))
    axis = np.array([np.cos(turn), np.sin(turn)])
    tip = tip_along(surface, ball, z, apex, axis, 1.0, 27.0)
    bounds = (-14, -14, 22, 22)
    tol = 3e-3
    (level,) = waterline_loops(surface, ball, [z], bounds, sample_step=0.5, min_step=0.05, chord_tol=tol)
    (ref,) = waterline_loops(surface, ball, [z], bounds, sample_step=0.0625, chord_tol=tol)
    assert len(level) == 1  # the V's island, the crack reaching into it
    d = distance_to_polylines(tip[None, :], *segments_of(level))[0]
    assert d <= tol + 1e-6, f"the crack's tip lies {d:.4g} mm from the loop"
    expect_like_reference(level, ref, 0.0625, tol)
    expect_contacts(surface, ball, level)


def test_the_notch_between_two_discs_of_a_flat_end_mill_is_reached():
    """A flat end mill round two thin spikes 5.9 mm apart: the union of two discs of radius 3 with a 16-degree
    notch on either side (mount_rush.stl's flat, between two of its discs)."""
    flat = Cutter.flat(6)
    top, z = 1.0, 0.9
    turn = np.radians(20.0)
    centre = np.array([0.37, -0.21])
    along = np.array([np.cos(turn), np.sin(turn)])
    normal = np.array([-along[1], along[0]])
    spikes = [centre + s * 2.95 * along for s in (-1, 1)]
    surface = DropSurface(on_plate([pyramid(tuple(p), top, 0.05) for p in spikes], 12))
    tips = [tip_along(surface, flat, z, centre, s * normal, 0.0, 2.0) for s in (-1, 1)]
    bounds = (-8, -8, 8, 8)
    tol = 3e-3
    (level,) = waterline_loops(surface, flat, [z], bounds, sample_step=0.5, min_step=0.05, chord_tol=tol)
    (ref,) = waterline_loops(surface, flat, [z], bounds, sample_step=0.0625, chord_tol=tol)
    assert len(level) == 1
    d = distance_to_polylines(np.array(tips), *segments_of(level))
    assert d.max() <= tol + 1e-6, f"the notches' tips lie {d} mm from the loop"
    expect_like_reference(level, ref, 0.0625, tol)
    expect_contacts(surface, flat, level)
