"""Constant cusp mode on a curved surface (issue 14 item 1; core.footprint.cusp_section): on a concave cylinder
across the passes the planar rule at the steepest crossing leaves more than the cusp, the section rule does not.
Checked independently of both: the raster's real CL points cut into the stock simulation on fine cells, the cusp
of each cell measured exactly along the cylinder's normal (the radius minus the cell's distance from the axis)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.footprint.cusp import steepest_crossing_deg, stepover_for_cusp
from tmm_workbench.core.footprint.cusp_section import section_stepover
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute
from tmm_workbench.core.tools.cutter import Cutter

RHO = 12.0                      # the cylinder's radius; its axis along X at z = RHO
HALF = 8.0                      # |y| <= 8: slopes up to asin(8 / 12) = 41.8 deg, then tangent planes
BOX = (-5.0, -HALF - 3.0, 5.0, HALF + 3.0)   # the measured cells and the rule's ridges: clear of its edges by R
CUSP = 0.01


def section(y: np.ndarray) -> np.ndarray:
    yc = np.clip(y, -HALF, HALF)
    return RHO - np.sqrt(RHO * RHO - yc * yc) + (y - yc) * HALF / math.sqrt(RHO * RHO - HALF * HALF)


def cylinder():
    return grid_mesh(lambda x, y: section(y), 4, 1120, (-8, -14, 8, 14), "concave cylinder")


def simulated_cusp(cutter: Cutter, **params) -> tuple[float, int]:
    """The largest cusp (mm, along the normal) a raster over BOX leaves on the cylinder (|y| <= 7.9), and its
    passes."""
    mesh = cylinder()
    result = compute(mesh, cutter, SurfaceParams(boundary=BOX, sample_step=0.25, **params))
    path = link(result.segments, LinkPolicy(safe_height=20, clearance_height=25))
    grid = Grid.covering(-0.5, -7.9, 0.5, 7.9, 0.01)
    heights = simulate(path, cutter, grid, box_heights(grid, 15.0)).heights
    y = grid.ys()[:, None]
    cusp = RHO - np.sqrt(y * y + (RHO - heights) ** 2)
    # a bull's flat bridges the bottom (|y| < its radius): out of its reach, no cusp (the rule's `unreachable`)
    reach = np.abs(y[:, 0]) >= (cutter.radius - cutter.corner_radius) + 0.5
    return float(cusp[reach].max()), result.diagnostics["passes"]


@pytest.mark.parametrize("cutter", [Cutter.ball(6), Cutter.bull(6, 2.5)], ids=["ball", "bull"])
def test_section_rule_holds_the_cusp_where_the_planar_rule_does_not(cutter):
    mesh = cylinder()
    slope = steepest_crossing_deg(mesh, BOX, 0.0)
    assert slope == pytest.approx(math.degrees(math.asin(HALF / RHO)), abs=0.1)
    planar = stepover_for_cusp(cutter, CUSP, slope)
    step = section_stepover(mesh, cutter, BOX, 0.0, CUSP, float(mesh.bounds[0][2]), planar=planar)
    assert step.stepover < planar and not step.limited and step.cusp <= CUSP
    if cutter.kind == "ball":  # a bull's flat (radius 0.5) stands 0.0104 mm above the bottom: out of reach there
        assert step.creases == 0 and step.unreachable == 0
    new, passes = simulated_cusp(cutter, stepover_mode="cusp", cusp=CUSP)
    old, old_passes = simulated_cusp(cutter, stepover=planar)
    assert new <= CUSP                                  # the tolerance holds everywhere measured
    assert old_passes < passes
    if cutter.kind == "ball":                           # the planar rule leaves too much on the concave section
        assert old > 1.05 * CUSP


def test_on_a_plane_the_section_rule_is_the_planar_rule():
    t = math.tan(math.radians(30.0))
    plane = grid_mesh(lambda x, y: y * t, 4, 4, (-20, -20, 20, 20))
    for cutter in (Cutter.ball(6), Cutter.bull(10, 2)):  # (a flat on a slope: steps below the samples, not here)
        step = section_stepover(plane, cutter, (-10, -10, 10, 10), 0.0, CUSP, -20.0)
        assert step.stepover == pytest.approx(stepover_for_cusp(cutter, 0.97 * CUSP, 30.0), rel=0.02)
        # turned passes cross the plane less steeply: a larger step
        assert section_stepover(plane, cutter, (-10, -10, 10, 10), 60.0, CUSP, -20.0).stepover > step.stepover


def test_bad_input_names_the_parameter():
    from tmm_workbench.core.errors import TmmError

    plane = grid_mesh(lambda x, y: 0 * x, 2, 2, (-5, -5, 5, 5))
    with pytest.raises(TmmError, match=r"cusp height must be in \(0, 3\] mm"):
        section_stepover(plane, Cutter.ball(6), (-5, -5, 5, 5), 0.0, 4.0, -1.0)
    with pytest.raises(TmmError, match="cusp slope limit must be in"):
        section_stepover(plane, Cutter.ball(6), (-5, -5, 5, 5), 0.0, 0.01, -1.0, max_slope_deg=90.0)


def test_work_refused_before_the_samples_are_made():
    from tmm_workbench.core import limits

    plane = grid_mesh(lambda x, y: 0 * x, 2, 2, (-5, -5, 5, 5))
    old = limits.set_limits(max_points=100_000)
    try:
        from tmm_workbench.core.errors import TmmError

        with pytest.raises(TmmError, match=r"cusp height 0.01 mm \(samples .* apart across the passes\) over a 2e\+06"):
            section_stepover(plane, Cutter.ball(6), (-5, -1e6, 5, 1e6), 0.0, CUSP, -1.0)
    finally:
        limits.set_limits(max_points=old.max_points)
