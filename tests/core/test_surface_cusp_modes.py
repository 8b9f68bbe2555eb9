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
from tmm_workbench.core.sim.compare import slope_deg
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
    dense = compute_surface_toolpath(mesh, ball, SurfaceParams(boundary=(0, -4, 20, 16), stepover=0.02,
                                                               sample_step=0.25),
                                     LinkPolicy(safe_height=10, clearance_height=12))
    envelope = simulate(dense, ball, grid, box_heights(grid, 5)).heights
    cusp = (cut - envelope) * np.cos(np.radians(slope_deg(envelope, grid.cell)))
    assert cusp.max() <= 1.05 * 0.01 and cusp.min() >= -2e-3
    r = compute(mesh, ball, params)
    gaps = np.diff(pass_offsets(r))
    assert len(gaps) + 1 < 0.95 * (12.0 / gaps[:-1].min() + 1)
    assert r.diagnostics["cusp_limited"] == 0 and r.diagnostics["cusps"].max() <= 0.01


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
