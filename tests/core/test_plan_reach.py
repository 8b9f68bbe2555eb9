"""The planner's reach tests between the grid's positions (core.footprint.reach.nearest_reach, profile_distance) and
beyond the model's box (reach_envelope: an open sheet's rim), and the left check that uses them."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.footprint.rest import tool_envelope
from tmm_workbench.core.footprint import reach
from tmm_workbench.core.plan import analysis
from tmm_workbench.core.plan.left_check import left_in_reach
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.tools.cutter import Cutter

STEEP = math.tan(math.radians(80.0))


def wall():
    """A floor, an 80 deg wall 6 mm high from x 10 (a sharp concave foot), a plateau."""
    return grid_mesh(lambda x, y: np.clip((x - 10.0) * STEEP, 0.0, 6.0), 400, 20, (0, 0, 20, 4), "wall")


def test_profile_distance_of_ball_bull_and_flat() -> None:
    tip = np.array([0.0])
    xy = np.array([[0.0, 0.0]])
    below = np.array([[0.0, 0.0, -0.2]])
    beside = np.array([[3.0, 0.0, 5.0]])     # beside the flutes, above the corner
    for cutter in (Cutter.ball(2.0), Cutter.bull(4.0, 0.5), Cutter.flat(4.0)):
        assert reach.profile_distance(cutter, below, xy, tip)[0] == pytest.approx(0.2)
        assert reach.profile_distance(cutter, beside, xy, tip)[0] == pytest.approx(3.0 - cutter.radius)
    # a point level with the ball's centre, 0.3 mm out: 0.3 mm from the sphere; below a bull's corner, from its torus
    assert reach.profile_distance(Cutter.ball(2.0), np.array([[1.3, 0.0, 1.0]]), xy, tip)[0] == pytest.approx(0.3)
    corner = reach.profile_distance(Cutter.bull(4.0, 0.5), np.array([[2.0, 0.0, 0.0]]), xy, tip)[0]
    assert corner == pytest.approx(math.hypot(0.5, 0.5) - 0.5)


def test_nearest_reach_tells_a_steep_wall_the_grid_cannot() -> None:
    # on an 80 deg wall a D1's grid positions lie 1.15 mm apart along it: its envelope stands up to 0.3 mm above
    # the wall between them, yet dropped between them it touches every point of the wall; the sharp foot it
    # cannot reach (a ball leaves a fillet of its radius in a 100 deg corner)
    mesh = wall()
    cell = 0.2
    grid = Grid.covering(0, 0, 20, 4, cell)
    surface = DropSurface(mesh)
    design = mesh_heights(mesh, grid, surface)
    ball = Cutter.ball(1.0)
    envelope = tool_envelope(mesh, ball, grid, surface)
    row = grid.ny // 2
    xs = grid.xs()
    on_wall = np.flatnonzero((xs > 10.1) & (xs < 10.0 + 5.5 / STEEP))
    cos = math.cos(math.radians(80.0))
    assert np.max((envelope - design)[row, on_wall]) * cos > 0.01        # the grid's envelope: not within it
    near = reach.nearest_reach(mesh, ball, grid, design, np.column_stack([np.full(len(on_wall), row), on_wall]),
                                  surface)
    assert np.all(near < 0.003)
    foot = int(np.argmin(np.abs(xs - 9.9)))      # 0.1 mm off the foot: 0.094 mm under the fillet the ball leaves
    floor = reach.nearest_reach(mesh, ball, grid, design, np.array([[row, foot], [row, 5]]), surface)
    assert floor[0] == pytest.approx(math.hypot(0.5 / math.tan(math.radians(50.0)) - 0.1, 0.5) - 0.5, abs=0.003)
    assert floor[1] < 1e-6                      # mid-floor: the tip touches it


def test_left_check_judges_a_steep_wall_where_the_tool_reaches_it() -> None:
    # 0.05 mm along the normal left on a band of the 80 deg wall: the D1 reaches it (dropped between the grid's
    # positions), so it counts; the same left in the floor's cell beside the sharp foot does not (out of reach)
    mesh = wall()
    grid = Grid.covering(0, 0, 20, 4, 0.2)
    design = mesh_heights(mesh, grid)
    x, _ = np.meshgrid(grid.xs(), grid.ys())
    deviation = np.zeros_like(design)
    band = (x > 10.3) & (x < 10.7)
    deviation[band] = 0.05 / math.cos(math.radians(80.0))
    foot = (x > 9.8) & (x < 10.0)
    deviation[foot] = 0.05
    got = left_in_reach(mesh, grid, design, deviation, "B1", Cutter.ball(1.0), 0.01)
    assert got["left_above_tolerance_mm2"] == pytest.approx(band.sum() * 0.04, rel=0.05)
    assert got["most_left_mm"] == pytest.approx(0.05, rel=0.05)
    assert got["out_of_reach_mm2"] >= foot.sum() * 0.04


def test_an_open_sheets_rim_is_reached_from_beyond_the_models_box() -> None:
    # a sheet sloping down to its rim at the box's edge: a ball touches a slope uphill of its axis, so the rim is
    # reached only from positions beyond the box (they touch its edge); from the box's own positions it is not
    mesh = grid_mesh(lambda x, y: 10.0 - 0.5 * x, 40, 20, (0, 0, 20, 10), "sheet")
    an = analysis.analyse(mesh, 0.5, [("ball D6", Cutter.ball(6.0))], 0.01)
    assert an.reach["ball D6"].unreached_area == 0.0
    surface = DropSurface(mesh)
    inside = tool_envelope(mesh, Cutter.ball(6.0), an.grid, surface)
    assert np.nanmax(inside[:, -1] - an.design[:, -1]) > 0.1            # the box's positions alone: a rim left
    grown = analysis.reach_envelope(mesh, Cutter.ball(6.0), an.grid, surface)
    assert grown.shape == an.design.shape
    assert np.nanmax(grown - an.design) < 0.01
