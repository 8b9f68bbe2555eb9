"""What a 5-axis finish leaves above the tolerance (core.strategies.mesh5.cleanup.left_above): the simulation of its
path, its instances as far apart as the lead tilt of each move allows (the tool's entries along its axis in short
pieces), finds an uncut strip between two passes outside the listed strips, as the fine simulation does."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.sim.simulate import sub_step, max_tilt
from tmm_workbench.core.strategies.mesh5 import cleanup
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter

SLOPE, TOL, RETRACT = 0.2, 0.05, 5.0


def _plane():
    """A plane rising along x (11.3 deg), x 0..40, y 0..30."""
    return grid_mesh(lambda x, y: SLOPE * x, 8, 6, (0, 0, 40, 30), "slope")


def _passes(ys) -> Toolpath:
    """Passes up the slope at `ys` (beyond both ends by a radius and more), the flat bottom lying on the plane
    (the axis its normal: 5-axis, no lead tilt), each entered and left along the axis from RETRACT above."""
    n = np.array([-SLOPE, 0.0, 1.0]) / math.hypot(SLOPE, 1.0)
    path = Toolpath()
    path.add(MoveKind.RAPID, -8.0, ys[0], 30.0, axis=tuple(n))
    for y in ys:
        xs = np.linspace(-7.0, 47.0, 28)
        ends = [np.array([xs[0], y, SLOPE * xs[0]]), np.array([xs[-1], y, SLOPE * xs[-1]])]
        path.add(MoveKind.RAPID, *(ends[0] + RETRACT * n), axis=tuple(n))
        for x in xs:
            path.add(MoveKind.FEED, x, y, SLOPE * x, axis=tuple(n))
        path.add(MoveKind.FEED, *(ends[1] + RETRACT * n), axis=tuple(n))
        path.add(MoveKind.RAPID, xs[-1], y, 30.0, axis=tuple(n))
    return path


def test_an_uncut_strip_between_passes_is_found_outside_the_listed_strips():
    mesh, cutter = _plane(), Cutter.flat(10.0)
    path = _passes([4.0, 12.0, 28.0])          # the pass at y = 20 left out: y 17..23 stays uncut
    left = cleanup.left_above(mesh, cutter, path, TOL)
    pts = left.points(left.outside)
    assert len(pts) and 17.0 - 0.3 <= pts[:, 1].min() and pts[:, 1].max() <= 23.0 + 0.3
    assert pts[:, 0].min() < 1.0 and pts[:, 0].max() > 39.0          # all along the feed
    assert left.outside_area > 0.8 * 6.0 * 40.0
    assert "outside the strips, within x" in left.summary()
    # listed as a strip (its XY corners), it is no longer outside them
    strip = np.array([[0.0, 17.0], [40.0, 17.0], [40.0, 23.0], [0.0, 23.0]])
    listed = cleanup.left_above(mesh, cutter, path, TOL, strips=[strip])
    assert listed.above.sum() == left.above.sum() and not listed.outside.any()


def test_the_lead_tilt_sets_the_instances_apart_and_finds_what_the_fine_simulation_finds():
    mesh, cutter = _plane(), Cutter.flat(10.0)
    path = _passes([4.0, 12.0, 28.0])
    fine = sub_step(cutter, TOL, max_tilt(path))             # the simulation's own: by the tilt from vertical
    dense = cleanup.sim_path(path, cutter.radius, TOL)
    # the bottom slides in its own plane along the passes: those moves stay whole (instances MAX_STEP apart);
    # the entries and exits along the axis are split into pieces a tenth of the tolerance's sawtooth long
    along = len(path) - 1 - 6                                 # the moves but the entries and exits
    pieces = 6 * RETRACT * math.hypot(SLOPE, 1.0) / (0.1 * TOL)
    assert len(dense) - 1 - along == pytest.approx(pieces, rel=0.05) and cleanup.MAX_STEP >= 4 * fine
    grid = cleanup.cleanup_grid(mesh)
    design, coarse = cleanup.material_left(mesh, cutter, path, grid, TOL)
    stock = np.where(np.isnan(design), float(mesh.bounds[0][2]) - 1.0, design + cleanup.STOCK_ABOVE)
    exact = cleanup.simulate(path, cutter, grid, stock, max_step=fine).heights
    on = np.isfinite(design)
    assert np.array_equal((coarse - design > TOL) & on, (exact - design > TOL) & on)
    assert np.abs(coarse - exact)[on].max() < 0.1 * TOL
