"""The 5-axis stock simulation with a flat end mill (the bull-nose solid with corner radius 0) against the
closed forms of a tilted disc swept along a line, and against a bull-nose whose corner shrinks to nothing."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate, sub_step
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter

R, LAM, TOL = 5.0, math.radians(12.0), 0.01


def swept(tool: Cutter, start, end, axis, max_step=None) -> tuple[Grid, np.ndarray]:
    grid = Grid.covering(-12, -12, 12, 12, 0.1)
    tp = Toolpath()
    tp.add(MoveKind.FEED, *start, axis=axis)
    tp.add(MoveKind.FEED, *end, axis=axis)
    r = simulate(tp, tool, grid, np.full((grid.ny, grid.nx), 10.0), tolerance=TOL, max_step=max_step)
    return grid, r.heights


def centres(grid: Grid) -> tuple[np.ndarray, np.ndarray]:
    return np.meshgrid(grid.xs(), grid.ys())


def test_a_flat_end_tilted_across_its_travel_leaves_its_bottoms_plane():
    # axis tilted about Y, travel along Y: every vertical line through the track meets the tilted bottom
    # disc, whose plane is z = -(x - cx) tan(lambda) (the tip at the origin); beyond its low side nothing (the
    # shank leans over the high side)
    axis = (math.sin(LAM), 0.0, math.cos(LAM))
    grid, h = swept(Cutter.flat(2 * R), (0, -6, 0), (0, 6, 0), axis)
    X, Y = centres(grid)
    inside = (np.abs(X) < R * math.cos(LAM) - 0.05) & (np.abs(Y) < 5.0)
    np.testing.assert_allclose(h[inside], -X[inside] * math.tan(LAM), atol=1e-9)
    assert (h[X < -R * math.cos(LAM) - 0.05] == 10.0).all()


def test_a_flat_end_tilted_along_its_travel_leaves_its_rims_track_within_the_sub_step_bound():
    # axis tilted about Y, travel along X: the lowest rim point traces z = -sin(lambda) sqrt(R^2 - y^2); the
    # tilted bottom between instances leaves a sawtooth s tan(lambda), s the sub-step: at most TOL / 10 above
    axis = (math.sin(LAM), 0.0, math.cos(LAM))
    grid, h = swept(Cutter.flat(2 * R), (-6, 0, 0), (6, 0, 0), axis)
    X, Y = centres(grid)
    # the lowest rim point leads, R cos(lambda) ahead of the tip: it passes x = -1.1 .. 10.9
    inside = (X > 0.0) & (X < 4.0) & (np.abs(Y) < R - 0.05)
    exact = -math.sin(LAM) * np.sqrt(R * R - Y[inside] ** 2)
    over = h[inside] - exact
    assert over.min() >= -1e-9 and over.max() <= 0.1 * TOL + 1e-9
    assert sub_step(Cutter.flat(2 * R), TOL, LAM) == pytest.approx(0.1 * TOL / math.tan(LAM))
    # a coarse step leaves the sawtooth, as the bound says
    _, coarse = swept(Cutter.flat(2 * R), (-6, 0, 0), (6, 0, 0), axis, max_step=0.5)
    assert (coarse[inside] - exact).max() > 0.05 * math.tan(LAM)


def test_the_flat_end_is_the_limit_of_the_bull_nose():
    axis = (math.sin(LAM) * math.cos(0.4), math.sin(LAM) * math.sin(0.4), math.cos(LAM))
    args = ((-6, -3, 0), (6, 3, 1), axis, 0.005)
    _, flat = swept(Cutter.flat(2 * R), *args)
    _, bull = swept(Cutter.bull(2 * R, 1e-4), *args)
    np.testing.assert_allclose(flat, bull, atol=2e-4)


def test_a_flat_end_is_no_round_insert():
    grid = Grid.covering(0, 0, 1, 1, 0.5)
    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0, axis=(0.1, 0, 0.99))
    tp.add(MoveKind.FEED, 1, 0, 0, axis=(0.1, 0, 0.99))
    with pytest.raises(TmmError, match="minor radius Ri = 0 must be a bull-nose"):
        simulate(tp, Cutter.flat(2.0), grid, np.zeros((grid.ny, grid.nx)), shape="round_insert")
