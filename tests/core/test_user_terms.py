"""The core's side of failing in the user's terms: the cusp rule's instance window against every instance (a
slow reference), a cusp below a machine's resolution refused by name in bounded memory, numpy scalars as numbers,
a loop crossing itself and sideways faces named, a one-cell-wide grid's slope, and cancel polled from deep loops."""
from __future__ import annotations

import math
import time
import tracemalloc

import numpy as np
import pytest

from tmm_workbench.core import cancel, limits, polygons
from tmm_workbench.core.errors import Cancelled, TmmError, WorkLimitError
from tmm_workbench.core.footprint import cusp, region
from tmm_workbench.core.strategies.surface import variable_step
from tmm_workbench.core.params import Spec, check
from tmm_workbench.core.sim.compare import slope_deg
from tmm_workbench.core.strategies.raster_drop import ADAPTIVE, SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

CUTTERS = [Cutter.ball(6.0), Cutter.flat(6.0), Cutter.bull(10.0, 2.0), Cutter(10, 2, 5, 3, 20)]


def every_instance_cusp(cutter: Cutter, stepover: float, slope_deg: float) -> float:
    """plane_cusp by its definition: every instance within the tool's reach, on a fine grid of one period."""
    r_max = cutter.native.max_radius
    t = math.tan(math.radians(slope_deg))
    u = np.linspace(-r_max, r_max, 200_001)
    base = float((cusp.profile_height(cutter, u) - u * t).min())
    y = np.linspace(0.0, stepover, 4001)
    k = np.arange(math.floor(-r_max / stepover) - 1, math.ceil((stepover + r_max) / stepover) + 2)
    du = y[:, None] - k[None, :] * stepover
    left = (cusp.profile_height(cutter, du) - du * t - base).min(axis=1)
    return float(left.max()) * math.cos(math.radians(slope_deg))


@pytest.mark.parametrize("cutter", CUTTERS, ids=lambda c: c.kind)
@pytest.mark.parametrize("stepover, slope", [(0.05, 0.0), (0.3, 30.0), (1.0, 45.0), (2.5, 10.0), (0.2, 75.0)])
def test_the_instance_window_leaves_the_cusp_of_every_instance(cutter, stepover, slope):
    fast, slow = cusp.plane_cusp(cutter, stepover, slope), every_instance_cusp(cutter, stepover, slope)
    # the reference's grids bound its own error (a sample of 1/4000 of the period, of 1/100000 of the profile)
    assert fast == pytest.approx(slow, abs=2e-4 + 0.01 * slow)


def test_a_cusp_below_a_machines_resolution_is_refused_by_name():
    spec = SurfaceParams.__dataclass_fields__["cusp"].metadata["spec"]
    with pytest.raises(TmmError, match=r"cusp height must be >= 0.0001 mm, got 1e-08"):
        check(spec, 1e-8)
    with pytest.raises(TmmError, match=r"cusp height must be in \[0.0001, 3\] mm"):
        cusp.check_cusp(Cutter.ball(6.0), 5e-5)


@pytest.mark.parametrize("cutter", CUTTERS, ids=lambda c: c.kind)
def test_the_finest_cusp_is_found_in_bounded_memory(cutter):
    tracemalloc.start()
    try:
        step = cusp.stepover_for_cusp(cutter, cusp.MIN_CUSP, 75.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert 0 < step and cusp.plane_cusp(cutter, step, 75.0) <= cusp.MIN_CUSP * (1 + 1e-6)
    assert peak < 50e6   # every instance in reach took 4.4 GB at a cusp of 1e-8 mm


def test_a_fine_verification_is_refused_by_the_cusp_before_any_work():
    p = SurfaceParams(boundary=(0, 0, 80, 80), stepover_mode=ADAPTIVE, cusp=1e-4, verify_cusp=True)
    tracemalloc.start()
    try:
        with pytest.raises(WorkLimitError, match=r"verify cusp: cusp height 0.0001 mm measured on 0.02 mm cells"):
            variable_step.estimate_params(Cutter.ball(6.0), p)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 50e6


def test_the_verification_estimate_counts_the_dense_raster_and_the_cells():
    old = limits.set_limits(max_points=10**12)
    try:
        p = SurfaceParams(boundary=(0, 0, 40, 30), stepover_mode=ADAPTIVE, cusp=0.01, verify_cusp=True)
        ball = Cutter.ball(6.0)
        cell = variable_step.measure_cell(ball, 0.01)
        count = variable_step.estimate_params(ball, p)
    finally:
        limits.set_limits(max_points=old.max_points)
    # at least one CL point per cell of the grown box both ways, and the measured cells again
    assert count >= (40 / cell) * (36 / cell) + (34 / cell) * (24 / cell) * 0.99


def test_numpy_scalars_are_numbers_and_their_nan_is_not():
    length = Spec("diameter", "mm", low=0, low_open=True, kind="length")
    check(length, np.float32(6))
    check(Spec("passes", integer=True, low=1), np.int64(3))
    with pytest.raises(TmmError, match="diameter must be a positive length, got nan"):
        check(length, np.float32("nan"))
    with pytest.raises(TmmError):
        check(length, np.bool_(True))


def test_a_loop_crossing_itself_is_named_and_a_simple_one_is_not():
    bow_tie = np.array([[0, 0], [10, 10], [10, 0], [0, 10]], dtype=float)
    assert polygons.crosses_itself(bow_tie)
    assert not polygons.crosses_itself(np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float))
    assert not polygons.crosses_itself(polygons.circle((0, 0), 5.0))
    with pytest.raises(TmmError, match="loop 1 crosses itself seen from above"):
        region.loops_region([bow_tie], "Region 'Sketch'")


def test_faces_that_face_sideways_are_named():
    wall = np.array([[[0, 0], [10, 0], [5, 0]], [[0, 0], [0, 5], [0, 9]]], dtype=float)
    with pytest.raises(TmmError, match=r"cover no area \(vertical faces only\?\)"):
        region.triangles_region(wall, "Region 'Faces'")


def test_a_grid_one_cell_wide_has_a_slope_along_it_only():
    design = np.array([[0.0, 1.0, 2.0]])            # one row: rising 1 mm per 1 mm cell along x
    assert slope_deg(design, 1.0) == pytest.approx(np.full((1, 3), 45.0))
    assert slope_deg(np.array([[3.0]]), 1.0) == pytest.approx(np.zeros((1, 1)))


def test_poll_asks_the_innermost_callback_and_cancels():
    asked = []
    with cancel.watching(lambda f: asked.append(("outer", f)) or True) as outer:
        outer(0.4)
        cancel.poll()
        with cancel.watching(lambda f: asked.append(("inner", f)) or False):
            with pytest.raises(Cancelled):
                cancel.poll()
        time.sleep(cancel.POLL_S * 1.5)
        cancel.poll()
    cancel.poll()   # nothing watched: nothing asked
    assert asked == [("outer", 0.4), ("outer", 0.4), ("inner", 0.0), ("outer", 0.4)]


def test_a_work_refusal_names_the_setting_to_raise():
    """Headless, the environment variables; once the App names its preferences, those (never a Python call)."""
    old = limits.set_limits(max_points=1000, max_positions=1000)
    try:
        with pytest.raises(WorkLimitError, match=r"environment variables TMM_MAX_POINTS and TMM_MAX_MEMORY_GB"):
            limits.check_work("CL points", 2000, 8, "sample step 0.001 mm")
        limits.name_settings("the TMM preferences", {"max_points": "MaxPoints", "max_positions": "MaxPositions",
                                                     "max_memory_bytes": "MaxMemoryGB"})
        with pytest.raises(WorkLimitError) as refused:
            limits.check_work("positions", 2000, 8, "side step 0.01 mm", limit="max_positions")
        assert "TMM preferences MaxPositions and MaxMemoryGB" in str(refused.value)
        assert "set_limits" not in str(refused.value) and "TMM_MAX" not in str(refused.value)
    finally:
        limits.set_limits(max_points=old.max_points, max_positions=old.max_positions)
        limits.name_settings(*limits.ENV_SETTINGS)
