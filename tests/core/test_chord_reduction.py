"""Points a longer straight move represents are left out (core.strategies.raster_drop.reduce_chords, issue
14 item 2's reduction): a move that replaces points passes at most chord_tol above them and never below
one, so a ramp becomes one move, a concave stretch a few, a convex one none (a chord below it would gouge);
and on a model of flats and 30 deg ramps the reduced path's simulated stock differs from the full one's by
at most the tolerance (core.sim)."""
from __future__ import annotations

import math

import numpy as np

from tests.conftest import grid_mesh
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath, reduce_chords
from tmm_workbench.core.tools.cutter import Cutter


def pass_of(z):
    x = np.linspace(0, 10, len(z))
    return np.column_stack([x, np.full_like(x, 2.0), z])


def chord_offsets(kept: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """z of the reduced polyline minus z of every original point."""
    return np.interp(pts[:, 0], kept[:, 0], kept[:, 2]) - pts[:, 2]


def test_ramp_concave_convex():
    x = np.linspace(0, 10, 101)
    ramp = pass_of(0.3 * x + 1)
    assert len(reduce_chords(ramp, 0.001)) == 2
    concave = pass_of(0.05 * (x - 5) ** 2)
    kept = reduce_chords(concave, 0.001)
    d = chord_offsets(kept, concave)
    assert 2 < len(kept) < 60 and d.min() >= -1e-7 and d.max() <= 0.001 + 1e-12
    convex = pass_of(-0.05 * (x - 5) ** 2)
    assert len(reduce_chords(convex, 0.001)) == len(convex)   # any chord would pass below a point
    assert len(reduce_chords(concave, 0.0)) == len(concave)   # 0: only exact straight lines go


def test_reduced_path_cuts_the_same_within_the_tolerance():
    # flats and 30 deg ramps: z = clip(tan30 * |x - 20| - 4, 0, 6)
    mesh = grid_mesh(lambda x, y: np.clip(math.tan(math.radians(30)) * np.abs(x - 20) - 4, 0, 6), 80, 4,
                     (0, 0, 40, 10))
    cutter = Cutter.ball(4.0)
    grid = Grid.covering(2, 2, 38, 8, 0.05)
    stock = box_heights(grid, 8.0)
    paths = {}
    for tol in (0.0, 0.001):
        params = SurfaceParams(boundary=(0, 0, 40, 10), stepover=0.5, sample_step=0.1, chord_tol=tol)
        paths[tol] = compute_surface_toolpath(mesh, cutter, params, LinkPolicy(12.0, 15.0))
    assert len(paths[0.0]) > 2.5 * len(paths[0.001])   # 2232 -> 755 moves when written
    full = simulate(paths[0.0], cutter, grid, stock).heights
    lean = simulate(paths[0.001], cutter, grid, stock).heights
    assert (lean - full).max() <= 0.001 + 1e-9 and (lean - full).min() >= -1e-7
