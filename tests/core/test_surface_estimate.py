"""The Surface's told passes and cutting length (core.strategies.surface.estimate) over a region and with the
model's coarse height sample (core.query.height_sample): slopes and bends read from the sample, the region's
area, the spacing each mode takes, the climbs the passes make."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core import polygons
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.height_sample import sample_heights
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

BALL = Cutter.ball(6.0)
BOX = (0.0, 0.0, 60.0, 40.0)
TILT = 0.5   # the plane's slope along Y (tan)


@pytest.fixture(scope="module")
def tilted():
    mesh = grid_mesh(lambda x, y: TILT * y, 30, 20, (-10.0, -10.0, 70.0, 50.0), "tilted plane")
    return mesh, sample_heights(DropSurface(mesh), BALL, BOX, -50.0)


@pytest.fixture(scope="module")
def trough():
    """A cylindrical trough of radius 20 along X (concave across Y): the ball's tip surface is a cylinder of
    radius 17 about the same axis."""
    mesh = grid_mesh(lambda x, y: 20.0 - np.sqrt(np.maximum(400.0 - (y - 20.0) ** 2, 0.0)), 40, 160,
                     (-10.0, 5.0, 70.0, 35.0), "trough")
    return mesh, sample_heights(DropSurface(mesh), BALL, (0.0, 12.0, 60.0, 28.0), -50.0)


def test_the_sample_reads_the_slopes_along_and_across(tilted) -> None:
    _, sample = tilted
    along, across = sample.slopes(0.0)   # passes along X: the plane climbs across them
    assert np.allclose(along, 0.0, atol=1e-9) and np.allclose(across, TILT, atol=1e-9)
    along, across = sample.slopes(90.0)  # passes along Y: they climb it
    assert np.allclose(along, TILT, atol=1e-9) and np.allclose(across, 0.0, atol=1e-9)
    assert np.allclose(sample.curvature(0.0), 0.0, atol=1e-9)


def test_the_sample_reads_a_concave_bend(trough) -> None:
    _, sample = trough
    k = sample.curvature(0.0)[:, 5:-5]   # across the trough, away from the sample's ends
    middle = k[len(sample.ys) // 2]
    assert np.allclose(middle, 1.0 / 17.0, rtol=0.05), middle   # the tip surface's radius: 20 - 3
    assert (sample.curvature(90.0) == pytest.approx(0.0, abs=1e-6))


def test_the_region_counts_its_area_not_its_box() -> None:
    circle = [polygons.circle((30.0, 20.0), 15.0)]
    box = raster_drop.estimate_work(SurfaceParams(boundary=polygons.bounds(circle), stepover=1.0), BALL, (0,) * 6)
    region = raster_drop.estimate_work(SurfaceParams(boundary=polygons.bounds(circle), region=circle, stepover=1.0),
                                       BALL, (0,) * 6)
    assert region.cut_length == pytest.approx(box.cut_length * math.pi / 4, rel=0.01)
    assert region.count == box.count   # the limits' bound stays the box's


def test_the_passes_climb_the_sample(tilted) -> None:
    _, sample = tilted
    along_x = raster_drop.estimate_work(SurfaceParams(boundary=BOX, stepover=1.0), BALL, (0,) * 6, sample)
    along_y = raster_drop.estimate_work(SurfaceParams(boundary=BOX, stepover=1.0, angle_deg=90.0), BALL, (0,) * 6,
                                        sample)
    area = 60.0 * 40.0
    assert along_x.cut_length == pytest.approx(area, rel=1e-6)   # level passes
    assert along_y.cut_length == pytest.approx(area * math.hypot(1.0, TILT), rel=1e-6)
    assert sum(mm for _, mm in along_y.climbs) == pytest.approx(along_y.cut_length)
    assert all(t >= TILT for t, _ in along_y.climbs)   # each bin's upper end
    assert along_x.passes == 41 and along_y.passes == 61


def test_the_cusp_modes_space_by_the_sampled_slope(tilted) -> None:
    _, sample = tilted
    step = stepover_for_cusp(BALL, 0.01, math.degrees(math.atan(TILT)))
    for mode in ("cusp", "adaptive"):
        work = raster_drop.estimate_work(SurfaceParams(boundary=BOX, stepover_mode=mode, cusp=0.01), BALL, (0,) * 6,
                                         sample)
        # the step table's rows lie up to half a row apart in slope: within a few per cent of the planar rule
        assert work.cut_length == pytest.approx(60.0 * 40.0 / step, rel=0.06), mode
    level = stepover_for_cusp(BALL, 0.01, 0.0)
    along = raster_drop.estimate_work(SurfaceParams(boundary=BOX, stepover_mode="adaptive", cusp=0.01, angle_deg=90.0),
                                      BALL, (0,) * 6, sample)
    assert along.cut_length == pytest.approx(60.0 * 40.0 * math.hypot(1.0, TILT) / level, rel=1e-6)


def test_a_concave_bend_narrows_the_cusp_spacing(trough) -> None:
    mesh, sample = trough
    box = (0.0, 12.0, 60.0, 28.0)
    bent = raster_drop.estimate_work(SurfaceParams(boundary=box, stepover_mode="adaptive", cusp=0.01,
                                                   max_slope_deg=80.0), BALL, (0,) * 6, sample)
    flat = raster_drop.estimate_work(SurfaceParams(boundary=box, stepover_mode="adaptive", cusp=0.01,
                                                   max_slope_deg=80.0), BALL, (0,) * 6,
                                     sample_heights(DropSurface(grid_mesh(lambda x, y: 0 * x, 4, 4, (-10, 0, 70, 40))),
                                                    BALL, box, -50.0))
    assert bent.cut_length > 1.05 * flat.cut_length   # the trough's walls and its bend (20 / 17) both narrow it
