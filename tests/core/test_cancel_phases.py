"""Cancel reaches the Python phases that call no kernel batch with a progress of their own: the section rule of
constant-cusp spacing, the 3D offset's field and heights, the raster's gouge refinement and the simulation's
design heights poll the strategy's callback (core.cancel), so a False answer stops them where they are."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled
from tmm_workbench.core.footprint.raster import sample_segment
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import raster_drop, raster_refine
from tmm_workbench.core.strategies.raster_drop import CUSP, OFFSET3D, SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

BUMPS = grid_mesh(lambda x, y: 3.0 * np.sin(x / 4) * np.cos(y / 5), 60, 60, (0, 0, 30, 30), "bumps")
BALL = Cutter.ball(6.0)


class Recorder:
    """A progress callback that says stop from its `stop_at`-th question on, and keeps what it was asked."""

    def __init__(self, stop_at: int) -> None:
        self.asked: list[float] = []
        self.stop_at = stop_at

    def __call__(self, fraction: float) -> bool:
        self.asked.append(fraction)
        return len(self.asked) < self.stop_at


@pytest.mark.parametrize("mode", [CUSP, OFFSET3D])
def test_the_spacing_phase_is_asked_before_any_drop_reports(mode):
    """The placement (the section rule, the 3D offset's field) reports nothing of its own; the callback is still
    asked there with the fraction so far (0; the drop after it reports from 0.5 on), and its False stops it."""
    params = SurfaceParams(boundary=(0, 0, 30, 30), stepover_mode=mode, cusp=0.005, sample_step=0.5)
    stop = Recorder(stop_at=1)
    with pytest.raises(Cancelled):
        raster_drop.compute(BUMPS, BALL, params, stop)
    assert stop.asked == [0.0]


def test_the_gouge_refinement_is_stopped_where_it_is():
    runs = [(False, sample_segment(np.array([0.0, y]), np.array([30.0, y]), 2.0)) for y in np.arange(0.0, 30.0, 0.5)]
    surface = DropSurface(BUMPS)

    def drop(xy):
        return surface.drop(BALL, xy, -10.0), np.zeros(len(xy), dtype=bool)
    xy = np.concatenate([r for _, r in runs])
    z, air = drop(xy)
    out = raster_refine.refine(runs, z, air, drop, 0.0005, chained=False)
    assert out[3]["inserted"] > 0   # there is work to stop
    with cancel.watching(Recorder(stop_at=1)):
        with pytest.raises(Cancelled):
            raster_refine.refine(runs, z, air, drop, 0.0005, chained=False)


def test_design_heights_report_in_blocks_and_stop():
    grid = Grid.covering(0, 0, 30, 30, 0.02)   # 1500 x 1500 cells: 9 blocks of 250k
    seen = Recorder(stop_at=10**9)
    z = mesh_heights(BUMPS, grid, progress=seen)
    assert np.isfinite(z).all() and seen.asked == sorted(seen.asked) and seen.asked[-1] == pytest.approx(1.0)
    stop = Recorder(stop_at=1)
    with pytest.raises(Cancelled):
        mesh_heights(BUMPS, grid, progress=stop)
    assert max(stop.asked) < 0.2   # the first block's first answer ends it
