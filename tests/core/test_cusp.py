"""Step-over from a cusp height (core.footprint.cusp): the closed forms where they exist (ball, bull-nose on a
level plane, a flat end mill's sawtooth on a slope), the inverse, and, independently, the cusp a real raster of
dropped CL points leaves in the simulated stock (core.sim) over inclined planes, for ball, bull-nose, flat and a
V-bit."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import plane_cusp, steepest_crossing_deg, stepover_for_cusp
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.compare import compare
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter


@pytest.mark.parametrize("slope", [0.0, 20.0, 45.0])
def test_ball_on_a_slope_is_the_classic_formula(slope):
    R, s = 3.0, 1.2
    # the ridge lies on the sphere below the equator for these slopes: R - sqrt(R^2 - (s / 2 cos a)^2)
    exact = R - math.sqrt(R * R - (s / (2 * math.cos(math.radians(slope)))) ** 2)
    assert plane_cusp(Cutter.ball(2 * R), s, slope) == pytest.approx(exact, abs=1e-12)


def test_bull_nose_on_a_level_plane_and_the_inverse():
    R, r, h = 5.0, 2.0, 0.01
    bull = Cutter.bull(2 * R, r)
    s = stepover_for_cusp(bull, h)
    assert s == pytest.approx(2 * (R - r) + 2 * math.sqrt(2 * r * h - h * h), abs=1e-9)
    assert plane_cusp(bull, s) == pytest.approx(h, abs=1e-12)
    assert plane_cusp(bull, 2 * (R - r)) == 0.0                        # the flat bottoms overlap


@pytest.mark.parametrize("slope", [10.0, 30.0])
def test_flat_end_mill_leaves_a_sawtooth_on_a_slope(slope):
    flat = Cutter.flat(10)
    assert plane_cusp(flat, 2.0, slope) == pytest.approx(2.0 * math.sin(math.radians(slope)), abs=1e-12)
    s = stepover_for_cusp(flat, 0.05, slope)
    assert s == pytest.approx(0.05 / math.sin(math.radians(slope)), rel=1e-9)
    assert stepover_for_cusp(flat, 0.05, 0.0) == 10.0                 # no cusp on a level plane: the diameter


@pytest.mark.parametrize("cutter", [Cutter.ball(6), Cutter.bull(10, 2), Cutter.vbit(10, 90, 1)],
                         ids=["ball", "bull", "vbit"])
@pytest.mark.parametrize("cusp", [0.005, 0.05])
def test_inverse_holds_on_slopes(cutter, cusp):
    for slope in (0.0, 25.0, 50.0):
        s = stepover_for_cusp(cutter, cusp, slope)
        assert plane_cusp(cutter, s, slope) == pytest.approx(cusp, rel=1e-6)
        assert plane_cusp(cutter, s * 1.01, slope) > cusp                # the largest such step-over
    # steeper crossings need closer passes
    assert stepover_for_cusp(cutter, cusp, 50.0) < stepover_for_cusp(cutter, cusp, 0.0)


@pytest.mark.parametrize("cutter,step,slope", [
    (Cutter.ball(6), 1.2, 30.0), (Cutter.ball(6), 1.2, 70.0), (Cutter.bull(10, 2), 7.0, 20.0),
    (Cutter.flat(6), 1.0, 15.0), (Cutter.vbit(10, 90, 1), 1.5, 10.0)], ids=["ball30", "ball70", "bull", "flat", "vbit"])
def test_a_dropped_raster_leaves_the_predicted_cusp_in_the_simulated_stock(cutter, step, slope):
    """Independent of the formula: real CL points dropped on an inclined plane mesh, cut into a z-map by the
    kernel's exact sweep, compared with the plane; the largest vertical remainder times cos(slope)."""
    t = math.tan(math.radians(slope))
    plane = grid_mesh(lambda x, y: y * t, 4, 4, (-20, -20, 20, 20))
    surface = DropSurface(plane)
    ys = np.arange(-4, 5) * step
    xs = np.linspace(-12, 12, 97)                                   # zig-zag links far from the strip
    tp = Toolpath()
    tp.add(MoveKind.RAPID, xs[0], ys[0], 40)
    for k, y in enumerate(ys):
        xy = np.column_stack([xs if k % 2 == 0 else xs[::-1], np.full(len(xs), y)])
        z = surface.drop(cutter, xy, -100.0)
        for p, zz in zip(xy, z):
            tp.add(MoveKind.FEED, p[0], p[1], zz)
    cell = 0.004
    grid = Grid.covering(-0.5, -step, 0.5, step, cell)             # two periods in the middle of the passes
    design = mesh_heights(plane, grid)
    result = simulate(tp, cutter, grid, box_heights(grid, 30.0))
    vertical = compare(result, design, tolerance=1.0).overall.max_left
    predicted = plane_cusp(cutter, step, slope) / math.cos(math.radians(slope))
    # cells sample the ridge: never above the supremum, below it by at most the surface's rise over half a
    # cell (its slope there is below 1/cell-steep: a loose bound, the tool wall's side of the ridge)
    assert vertical <= predicted + 1e-9
    assert vertical >= predicted - 3 * cell


def test_steepest_crossing_of_a_tilted_plane_depends_on_the_raster_angle():
    t = math.tan(math.radians(25.0))
    plane = grid_mesh(lambda x, y: y * t, 4, 4, (-10, -10, 10, 10))
    box = (-5, -5, 5, 5)
    assert steepest_crossing_deg(plane, box, 0.0) == pytest.approx(25.0, abs=1e-9)   # passes along X
    assert steepest_crossing_deg(plane, box, 90.0) == pytest.approx(0.0, abs=1e-9)   # along the slope
    assert steepest_crossing_deg(plane, (50, 50, 60, 60), 0.0) == 0.0                # no triangle there


def test_bad_input_is_named():
    ball = Cutter.ball(6)
    with pytest.raises(TmmError, match=r"cusp height must be in \(0, 3\] mm \(the tool radius\), got 0"):
        stepover_for_cusp(ball, 0.0)
    with pytest.raises(TmmError, match="cusp height .* got 4"):
        stepover_for_cusp(ball, 4.0)
    with pytest.raises(TmmError, match="cusp height .* got nan"):
        stepover_for_cusp(ball, math.nan)
    with pytest.raises(TmmError, match=r"slope must be in \[0, 90\) deg, got 90"):
        plane_cusp(ball, 1.0, 90.0)
    assert plane_cusp(ball, 6.0) == math.inf                            # a strip left uncut between passes
