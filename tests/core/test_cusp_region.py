"""The cusp mode in a region (a circle over sphere_on_plate's flank, ball D6): the section rule counts the flank's
crossings where the slope runs along the passes (a section's envelope stands above the design there by the tool's
rise on that slope, which is no sign of being out of reach), so the cusp holds by the simulated check, which
measures the region itself, not its box's corners the passes never cut."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import SHARED_STL
from tmm_workbench.core import polygons
from tmm_workbench.core.geometry.mesh import load_stl
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter


@pytest.fixture(scope="module")
def flank():
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    w, h = hi[0] - lo[0], hi[1] - lo[1]
    region = [polygons.circle((lo[0] + 0.65 * w, lo[1] + 0.5 * h), 0.15 * min(w, h))]
    return mesh, DropSurface(mesh), region


def test_cusp_holds_in_a_circle_on_a_flank(flank):
    mesh, surface, region = flank
    params = SurfaceParams(boundary=polygons.bounds(region), region=region, sample_step=0.5, stepover_mode="cusp",
                           cusp=0.04, cusp_check="on")
    out = raster_drop.compute(mesh, Cutter.ball(6.0), params, surface=surface)
    check = out.diagnostics["cusp_check"]
    assert check["measured"] > 5000 and check["exceeding"] == 0, check   # was 251 cells, 0.064 mm, at 0.96 mm
    assert check["max_cusp"] <= 0.04 and out.diagnostics["stepover"] < 0.8


def test_points_inside_agrees_with_the_grid():
    shape = polygons.union([polygons.circle((0, 0), 5.0), polygons.rectangle(3, -1, 9, 1)])
    shape = polygons.difference(shape, [polygons.circle((-1, 0), 2.0)])   # a hole
    xs, ys = np.linspace(-6, 10, 81), np.linspace(-6, 6, 61)
    X, Y = np.meshgrid(xs, ys)
    grid = polygons.grid_inside(shape, xs, ys)
    assert grid.any() and not grid.all()
    assert np.array_equal(polygons.points_inside(shape, np.column_stack([X.ravel(), Y.ravel()])).reshape(X.shape),
                          grid)
