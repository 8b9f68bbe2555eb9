"""The 3-axis Surface strategy spaced by a cusp height (issue 14): constant mode on an inclined plane spaces the
passes by the closed form at its slope, adaptive mode on a bump keeps the cusp in the simulated stock of the
linked tool path (the strategy's real output) with fewer passes than a constant step-over at its tightest gap;
the default stays the step-over; bad input by name."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.test_adaptive_raster import BOX, bump
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.compare import slope_deg
from tmm_workbench.core.sim.cusp_field import grid_envelope
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute, compute_surface_toolpath
from tmm_workbench.core.tools.cutter import Cutter


def pass_offsets(result) -> np.ndarray:
    """The y of each pass (passes along X)."""
    return np.array(sorted({round(float(s.tips[0, 1]), 9) for s in result.segments if s.kind.value == "pass"}))


def test_constant_cusp_mode_spaces_by_the_steepest_crossing():
    t = math.tan(math.radians(20.0))
    plane = grid_mesh(lambda x, y: y * t, 4, 4, (-20, -20, 40, 40))
    ball = Cutter.ball(6)
    r = compute(plane, ball, SurfaceParams(boundary=BOX, stepover_mode="cusp", cusp=0.01, sample_step=1.0))
    s = stepover_for_cusp(ball, 0.01, 20.0)
    assert r.diagnostics["cusp_slope_deg"] == pytest.approx(20.0, abs=1e-9)
    # on a plane the section rule (core.footprint.cusp_section) is the planar rule at its aim, 3 % under the cusp
    aim = stepover_for_cusp(ball, 0.01 * 0.97, 20.0)
    assert r.diagnostics["stepover"] == pytest.approx(aim, rel=0.01)
    assert r.diagnostics["cusp_planar_stepover"] == pytest.approx(s)
    s = r.diagnostics["stepover"]
    gaps = np.diff(pass_offsets(r))
    assert gaps.max() <= s + 1e-9 and gaps.min() >= s * 0.9     # spread evenly, at most the cusp's step-over
    default = compute(plane, ball, SurfaceParams(boundary=BOX, sample_step=1.0))  # the step-over, 1 mm
    assert np.allclose(np.diff(pass_offsets(default)), 1.0)


def test_adaptive_mode_keeps_the_cusp_in_the_simulated_stock():
    mesh = bump()
    ball = Cutter.ball(6)
    params = SurfaceParams(boundary=BOX, stepover_mode="adaptive", cusp=0.01, sample_step=0.25)
    fractions = []
    path = compute_surface_toolpath(mesh, ball, params, LinkPolicy(safe_height=10, clearance_height=12),
                                    progress=lambda f: fractions.append(f) or True)
    assert fractions and all(b >= a - 1e-12 for a, b in zip(fractions, fractions[1:]))  # never backwards
    grid = Grid.covering(4, 3.5, 16, 8.5, 0.02)
    cut = simulate(path, ball, grid, box_heights(grid, 5)).heights
    # the envelope of a dense raster dropped at points 0.02 mm apart both ways (no move across a valley's chord
    # leaves material of its own: the cusp modes split theirs)
    envelope = grid_envelope(mesh, ball, BOX, grid, 0.0, DropSurface(mesh), 5.0)
    cusp = (cut - envelope) * np.cos(np.radians(slope_deg(envelope, grid.cell)))
    # (on the convex top the path's moves may pass below the exact drop height by the gouge tolerance, the
    # envelope's points a cell apart do not)
    assert cusp.max() <= 1.05 * 0.01 and cusp.min() >= -params.gouge_tol
    r = compute(mesh, ball, params)
    gaps = np.diff(pass_offsets(r))
    assert len(gaps) + 1 < 0.95 * (12.0 / gaps[:-1].min() + 1)
    assert r.diagnostics["cusp_limited"] == 0 and r.diagnostics["cusps"].max() <= 0.01


def _highest_move_over_the_drop(mesh, cutter, result) -> float:
    """How far the path's cutting moves pass above the exact drop height at 5 points between their ends."""
    tips = [s.tips for s in result.segments if s.kind.value == "pass"]
    a = np.vstack([t[:-1] for t in tips])
    b = np.vstack([t[1:] for t in tips])
    f = np.array([0.2, 0.4, 0.5, 0.6, 0.8])[None, :, None]
    samples = (a[:, None, :] + f * (b - a)[:, None, :]).reshape(-1, 3)
    exact = DropSurface(mesh).drop(cutter, samples[:, :2], -10.0)
    return float((samples[:, 2] - exact).max())


@pytest.mark.parametrize("mode", ["cusp", "adaptive", "offset3d"])
def test_cusp_modes_split_the_moves_that_leave_material_across_a_valley(mode):
    """A V valley crossing the passes at an angle: the ball's CL path kinks at its crease, and a move across the
    kink passes above the exact CL path, leaving material the spacing (computed on the CL points) does not count.
    The cusp modes split such moves until they pass at most a tenth of the cusp above it (plus the chord
    tolerance of the thinning); the step-over mode keeps them."""
    valley = grid_mesh(lambda x, y: 0.5 * np.abs(x - 10.0 - 0.3 * y), 200, 100, (-5, -5, 25, 15))
    ball = Cutter.ball(6)
    params = SurfaceParams(boundary=(0, 0, 20, 10), stepover_mode=mode, cusp=0.01, sample_step=0.25,
                           cusp_check="off")
    held = compute(valley, ball, params)
    assert _highest_move_over_the_drop(valley, ball, held) <= 0.1 * 0.01 + params.chord_tol + 1e-6
    assert held.diagnostics["between"]["inserted"] > 0
    plain = compute(valley, ball, SurfaceParams(boundary=(0, 0, 20, 10), stepover=0.5, sample_step=0.25))
    assert _highest_move_over_the_drop(valley, ball, plain) > 0.3 * 0.01


def test_bad_cusp_input_is_named():
    mesh = bump()
    with pytest.raises(TmmError, match=r"cusp height must be in \[0.0001, 3\] mm \(a machine's resolution to the tool radius\), got 4"):
        compute(mesh, Cutter.ball(6), SurfaceParams(boundary=BOX, stepover_mode="cusp", cusp=4.0))
    with pytest.raises(TmmError, match=r"cusp height must be >= 0.0001 mm, got 0"):
        compute(mesh, Cutter.ball(6), SurfaceParams(boundary=BOX, stepover_mode="adaptive", cusp=0.0))
    with pytest.raises(TmmError,
                       match="step-over mode must be 'stepover' or 'cusp' or 'adaptive' or 'offset3d', got 'x'"):
        compute(mesh, Cutter.ball(6), SurfaceParams(boundary=BOX, stepover_mode="x"))
    with pytest.raises(TmmError, match=r"cusp slope limit must be in \(0, 90\) deg, got 90"):
        compute(mesh, Cutter.ball(6), SurfaceParams(boundary=BOX, stepover_mode="cusp", max_slope_deg=90.0))
