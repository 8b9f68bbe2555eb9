"""Every registered strategy tells its work with one signature (core.work): estimate_work(params, cutter, bounds)."""
from __future__ import annotations

import inspect

import pytest

from tmm_workbench.core.errors import WorkLimitError
from tmm_workbench.core.strategies import multipoint, raster_drop, waterline, zlevel_rough
from tmm_workbench.core.strategies.multipoint import MultipointParams
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.strategies.waterline import WaterlineParams
from tmm_workbench.core.strategies.zlevel_rough import RoughingParams
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Work

BOX = (0.0, 0.0, 0.0, 60.0, 40.0, 20.0)


@pytest.mark.parametrize("strategy", [raster_drop, waterline, zlevel_rough, multipoint])
def test_one_signature(strategy) -> None:
    params = inspect.signature(strategy.estimate_work).parameters
    assert list(params)[:3] == ["params", "cutter", "bounds"]
    assert all(p.default is not inspect.Parameter.empty for p in list(params.values())[3:])  # what a caller may add


@pytest.mark.parametrize("strategy, params", [
    (raster_drop, SurfaceParams(boundary=(0, 0, 60, 40), stepover=0.5)),
    (waterline, WaterlineParams(boundary=(0, 0, 60, 40))),
    (zlevel_rough, RoughingParams(stock_box=BOX)),
    (multipoint, MultipointParams()),
])
def test_the_work_of_each_strategy(strategy, params) -> None:
    work = strategy.estimate_work(params, Cutter.ball(6), BOX)
    assert isinstance(work, Work) and work.count > 0 and work.cut_length > 0
    assert work.paces and all(units > 0 for _, units in work.paces)


def test_the_surface_counts_its_spacing_and_its_checks() -> None:
    ball = Cutter.ball(6)
    coarse = raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 60, 40), stepover=1.0), ball, BOX)
    fine = raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 60, 40), stepover=0.5), ball, BOX)
    assert fine.count == pytest.approx(2 * coarse.count, rel=0.05) and fine.passes > coarse.passes
    verified = raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 60, 40), stepover=0.5, cusp=0.01,
                                                       verify_cusp=True), ball, BOX)
    assert [p for p, _ in verified.paces] == ["surface", "verify"] and "verification" in verified.note
    offset = raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 60, 40), stepover_mode="offset3d",
                                                     cusp=0.01), ball, BOX)
    assert offset.paces[0][0] == "offset3d"
    big = raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 60, 40), stepover=0.5), Cutter.ball(12), BOX)
    assert big.paces[0][1] == pytest.approx(4 * fine.paces[0][1], rel=0.05)   # a 12 mm tool covers 4x the triangles


def test_work_above_the_limits_is_refused_before_anything_is_made() -> None:
    with pytest.raises(WorkLimitError, match="CL points"):
        raster_drop.estimate_work(SurfaceParams(boundary=(0, 0, 6000, 4000), stepover=0.01, sample_step=0.01),
                                  Cutter.ball(6), BOX)
