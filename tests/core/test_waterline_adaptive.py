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
