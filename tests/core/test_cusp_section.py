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
    with pytest.raises(TmmError, match=r"cusp height must be in \[0.0001, 3\] mm"):
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


# A sheet that ends in a free border just above the floor (seed 000's whole convex surface, where the rule failed:
# the cells above the cusp lay on the last 0.2 mm of the sheet at its lowest corner, cut by the flanks of the
# passes that had rolled over the edge onto the floor beyond it). The sheet falls at 23 deg across the passes
# towards the border and 4 deg along them; the border runs 3 deg off the passes, so that the passes meet it at
# every phase along its length; its lowest corner is the model's lowest point (the raster's floor).
SHEET_SLOPE, SHEET_ALONG, SHEET_SLANT = math.tan(math.radians(23.0)), math.tan(math.radians(4.0)), 0.05
SHEET_BOX = (-10.0, -10.0, 10.0, 6.0)


def sheet_border(x):
    return 2.0 - SHEET_SLANT * x


def sheet_height(x, y, slope=SHEET_SLOPE):
    return -slope * y - SHEET_ALONG * x


def sheet(slope=SHEET_SLOPE):
    """The sheet (falling `slope` across the passes) over x in [-12, 12], y from -12 up to its border, as a face-up
    triangle grid."""
    from tmm_workbench.core.geometry.mesh import TriMesh

    u, v = np.meshgrid(np.linspace(-12, 12, 49), np.linspace(0, 1, 61), indexing="ij")
    y = -12 + v * (sheet_border(u) + 12)
    points = np.column_stack([u.ravel(), y.ravel(), sheet_height(u, y, slope).ravel()])
    i, j = np.meshgrid(np.arange(u.shape[0] - 1), np.arange(u.shape[1] - 1), indexing="ij")
    a = (i * u.shape[1] + j).ravel()
    b, c, d = a + u.shape[1], a + 1, a + u.shape[1] + 1
    triangles = np.vstack([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    e1, e2 = points[triangles[:, 1]] - points[triangles[:, 0]], points[triangles[:, 2]] - points[triangles[:, 0]]
    down = (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) < 0
    triangles[down] = triangles[down][:, ::-1]
    return TriMesh(points, triangles, "sheet with a low free border")


@pytest.mark.parametrize("across_deg", [23.0, 30.0], ids=["23deg", "30deg"])
def test_section_rule_holds_the_cusp_at_a_low_free_border(across_deg):
    """The old search (4 rounds on the pairs worst at the planar step) returned a step it knew to leave 0.0147 mm
    (`limited`): at a free border the worst pair moves with the step. Measured by the stock simulation on 0.01 mm
    cells along the border (core.sim.cusp_field: the path against a dense raster, where the tool reaches).
    At 30 deg the 2D section's tools missed the swept tool's reach beyond the border (0.0158 mm simulated): the
    rule drops them along the pass there too."""
    from tmm_workbench.core.strategies.surface.reference import cusp_field

    slope = math.tan(math.radians(across_deg))
    mesh, cutter = sheet(slope), Cutter.ball(6)
    floor = float(mesh.bounds[0][2])
    assert floor == pytest.approx(sheet_height(12.0, sheet_border(12.0), slope))  # the border's low end: the floor
    planar = stepover_for_cusp(cutter, CUSP, steepest_crossing_deg(mesh, SHEET_BOX, 0.0))
    step = section_stepover(mesh, cutter, SHEET_BOX, 0.0, CUSP, floor, planar=planar)
    assert not step.limited and step.cusp <= CUSP and step.stepover < planar
    result = compute(mesh, cutter, SurfaceParams(boundary=SHEET_BOX, sample_step=0.25, stepover_mode="cusp",
                                                 cusp=CUSP))
    assert result.diagnostics["stepover"] == pytest.approx(step.stepover)
    path = link(result.segments, LinkPolicy(safe_height=20, clearance_height=25))
    x0, x1 = SHEET_BOX[0] + cutter.radius, SHEET_BOX[2] - cutter.radius
    strip = Grid.covering(x0, sheet_border(x1) - 1.5, x1, sheet_border(x0) + 0.5, 0.01)  # the border's last 1.5 mm
    field = cusp_field(mesh, cutter, SHEET_BOX, CUSP, 0.01, grid=strip)
    assert field.measured.sum() > 0.9 * np.isfinite(field.design).sum()       # the border is within reach
    assert field.max_cusp(field.cut(path, cutter)) <= CUSP
