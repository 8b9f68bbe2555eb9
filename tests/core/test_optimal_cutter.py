"""The optimal cutter (core.plan.optimal_cutter, seed 003 section 4.2): on a plane, a bull-nose whose flat
bottom is wider than the step-over leaves nothing while a ball leaves its cusp everywhere, so the bull ranks
first; on a steep ramp (45 deg) the ball leaves less than the bull (seed 003: ball better above about 40 deg)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.plan.optimal_cutter import compare_cutters
from tmm_workbench.core.tools.cutter import Cutter

CANDIDATES = [("ball D6", Cutter.ball(6.0)), ("bull D6 r1", Cutter.bull(6.0, 1.0))]


def test_on_a_plane_the_bull_nose_wins():
    plane = grid_mesh(lambda x, y: 0 * x, 8, 8, (0, 0, 40, 40))
    out = compare_cutters(plane, CANDIDATES, stepover=1.0, sample_step=0.5, cell=0.1, margin=8.0)
    assert [s.label for s in out.scores] == ["bull D6 r1", "ball D6"]
    ball = out.scores[1]
    # the cusp R - sqrt(R^2 - s^2/4), seen at cell centres at most half a cell (0.05 mm) off the cusp line
    assert 3 - math.sqrt(9 - 0.45 ** 2) - 1e-9 <= ball.max_left <= 3 - math.sqrt(9 - 0.25) + 1e-9
    assert out.scores[0].max_left < 1e-9
    assert out.reasons[0].startswith("1. bull D6 r1") and len(out.reasons) == 2
    assert out.best_cell.shape == (out.grid.ny, out.grid.nx) and set(np.unique(out.best_cell)) <= {0, 1}


def test_on_a_45_degree_ramp_the_ball_leaves_less():
    ramp = grid_mesh(lambda x, y: x, 8, 8, (0, 0, 40, 40))  # z = x: 45 deg; passes along x (up the slope)...
    out = compare_cutters(ramp, CANDIDATES, stepover=1.0, sample_step=0.25, cell=0.1, margin=8.0, angle_deg=0.0)
    by = {s.label: s for s in out.scores}
    band = (40.0, 60.0)
    assert by["ball D6"].by_slope[band] < by["bull D6 r1"].by_slope[band]


def test_no_candidates():
    with pytest.raises(TmmError, match="no candidate cutters"):
        compare_cutters(grid_mesh(lambda x, y: 0 * x, 2, 2, (0, 0, 10, 10)), [], stepover=1.0, sample_step=0.5)


def test_cycle_times_at_the_machines_rapids():
    """The machine's rapid rates (the job's machine.rapid) time the rasters' retracts and hops; the ranking by the
    volume left is the same."""
    bump = grid_mesh(lambda x, y: 3.0 * np.exp(-((x - 20) ** 2 + (y - 20) ** 2) / 60.0), 24, 24, (0, 0, 40, 40))
    args = dict(stepover=2.0, sample_step=0.5, cell=0.2, margin=4.0)
    default = compare_cutters(bump, CANDIDATES, **args)
    slow = compare_cutters(bump, CANDIDATES, rapid=(500 / 60, 200 / 60), **args)
    fast = compare_cutters(bump, CANDIDATES, rapid=(20000 / 60, 20000 / 60), **args)
    for a, b, c in zip(slow.scores, default.scores, fast.scores):
        assert a.label == b.label == c.label and a.remaining_volume == b.remaining_volume
        assert a.cycle_seconds > b.cycle_seconds > c.cycle_seconds
