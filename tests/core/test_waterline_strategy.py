"""Waterline finishing (core.strategies.waterline): the levels (top-down, the last exactly at the bottom),
closed passes at their heights, nearest-first order, climb and conventional senses, pieces at the boundary's
edge left out, bad input by name, work refused, and the path verified by the stock simulation (core.sim):
no cell cut below the model plus the stock to leave by more than 1e-3 mm, no rapid through material."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SHARED_STL, grid_mesh
from tmm_workbench.core import limits
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import SegmentKind
from tmm_workbench.core.sim.compare import compare, slope_deg
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies.waterline import WaterlineParams, compute, estimate_work, levels
from tmm_workbench.core.tools.cutter import Cutter


def bumps() -> TriMesh:
    """Two bumps on a plane at z 0: two islands at mid heights, one around both lower down."""
    return grid_mesh(lambda x, y: 8 * np.exp(-((x - 12) ** 2 + (y - 15) ** 2) / 30)
                     + 6 * np.exp(-((x - 28) ** 2 + (y - 15) ** 2) / 30), 50, 40, (0, 0, 40, 30))


def signed_area(xy: np.ndarray) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def test_levels_run_top_down_to_the_bottom_exactly():
    assert levels(10.0, 0.0, 3.0) == [7.0, 4.0, 1.0, 0.0]
    assert levels(10.0, 0.0, 2.5) == [7.5, 5.0, 2.5, 0.0]
    assert levels(1.0, 0.5, 2.0) == [0.5]
    with pytest.raises(TmmError, match="top 1 mm must be above bottom 2 mm"):
        levels(1.0, 2.0, 0.5)


def test_passes_are_closed_at_their_levels_below_the_loops_above_and_nearest_first():
    mesh = bumps()
    p = WaterlineParams(boundary=(-5, -5, 45, 35), step_down=1.0, bottom_z=0.5, chord_tol=0.005)
    result = compute(mesh, Cutter.ball(4), p)
    top = float(mesh.bounds[1][2])
    zs = levels(top, 0.5, 1.0)
    d = result.diagnostics
    assert d["levels"] == len(zs) and d["points"] == sum(len(s) for s in result.segments)
    assert d["top"] == pytest.approx(zs[0]) and d["loops"] >= len(zs)
    seen = [float(s.tips[0, 2]) for s in result.segments]
    assert set(seen) == set(zs)
    # a loop only after every loop of the level above within a tool diameter of it (region_order)
    for k, seg in enumerate(result.segments):
        for above in result.segments[k + 1:]:
            if above.pass_index == seg.pass_index - 1:
                gap = np.hypot(*(seg.tips[:, None, :2] - above.tips[None, :, :2]).T).min()
                assert gap > 4.0
    counts = {z: seen.count(z) for z in zs}
    assert max(counts.values()) == 2 and counts[zs[-1]] == 1   # two islands high up, one round both below
    surface = DropSurface(mesh)
    for seg in result.segments:
        assert seg.kind is SegmentKind.PASS     # joined to the one above or not: test_loops_below_reached_...
        assert np.array_equal(seg.tips[0], seg.tips[-1])          # closed: the first tip repeated
        assert np.all(seg.tips[:, 2] == seg.tips[0, 2])
        assert signed_area(seg.tips[:-1, :2]) < 0                  # climb: islands clockwise
        h = surface.drop(Cutter.ball(4), seg.tips[:, :2], -100.0)
        assert h.max() <= seg.tips[0, 2] + 1e-9                    # every tip free: entries from above too
    # nearest-first: within a level each pass starts at the loop point nearest the previous pass's end
    for a, b in zip(result.segments, result.segments[1:]):
        if a.tips[0, 2] != b.tips[0, 2]:
            continue
        start = np.hypot(*(b.tips[0, :2] - a.tips[-1, :2]))
        assert start == pytest.approx(np.hypot(*(b.tips[:, :2] - a.tips[-1, :2]).T).min())
    conventional = compute(mesh, Cutter.ball(4), WaterlineParams(**{**p.__dict__, "direction": "conventional"}))
    assert all(signed_area(s.tips[:-1, :2]) > 0 for s in conventional.segments)


def test_a_pocket_runs_counter_clockwise_when_climbing():
    # a pit in a plane: the loop at z -1 goes round the free pit inside the blocked plane
    mesh = grid_mesh(lambda x, y: -5 * np.exp(-((x - 15) ** 2 + (y - 15) ** 2) / 40), 40, 40, (0, 0, 30, 30))
    result = compute(mesh, Cutter.flat(4), WaterlineParams(boundary=(0, 0, 30, 30), top_z=0.0, bottom_z=-2.0,
                                                           step_down=1.0))
    closed = [s for s in result.segments if np.array_equal(s.tips[0], s.tips[-1])]
    assert closed and all(signed_area(s.tips[:-1, :2]) > 0 for s in closed)
    # the plane runs past the boundary: its loop along the boundary's edge is not cut at all
    assert all(s.tips[:, :2].min() > 0 and s.tips[:, :2].max() < 30 for s in result.segments)


def test_boundary_cutting_through_the_model_splits_loops_into_open_passes():
    mesh = bumps()
    result = compute(mesh, Cutter.ball(4), WaterlineParams(boundary=(12, -5, 45, 35), bottom_z=2.0))
    opened = [s for s in result.segments if not np.array_equal(s.tips[0], s.tips[-1])]
    assert opened
    for s in opened:
        assert s.tips[:, 0].min() >= 12 - 1e-9
        assert np.isclose(s.tips[[0, -1], 0], 12.0, atol=1.0).any()  # they end near the boundary x = 12


def test_bad_input_is_refused_by_name():
    mesh = bumps()
    ball = Cutter.ball(4)
    for kwargs, message in [({"step_down": 0.0}, "step-down must be a positive length, got 0"),
                            ({"step_down": math.nan}, "step-down must be a positive length, got nan"),
                            ({"chord_tol": 2.0}, r"chord tolerance must be in \[0.0001, 1\] mm, got 2"),
                            ({"direction": "up"}, "direction must be 'climb' or 'conventional', got 'up'"),
                            ({"sample_step": -1.0}, "sample step must be > 0 mm, got -1"),
                            ({"stock_to_leave": -0.1}, "stock to leave must be >= 0 mm, got -0.1"),
                            ({"top_z": 1.0, "bottom_z": 2.0}, "top 1 mm must be above bottom 2 mm"),
                            ({"boundary": (0, 0, 0, 10)}, "boundary is empty"),
                            ({"boundary": (0, 0, math.inf, 10)}, "boundary .* must be finite"),
                            ({"boundary": (100, 100, 120, 120)}, "lies outside the model")]:
        params = WaterlineParams(**{"boundary": (0, 0, 40, 30), **kwargs})
        with pytest.raises(TmmError, match=message):
            compute(mesh, ball, params)
    with pytest.raises(TmmError, match="stock to leave is not supported with the APT"):
        compute(mesh, Cutter.vbit(6, 90), WaterlineParams(boundary=(0, 0, 40, 30), stock_to_leave=0.2))
    with pytest.raises(TmmError, match="no waterline loop"):
        compute(mesh, ball, WaterlineParams(boundary=(0, 0, 40, 30), top_z=30.0, bottom_z=20.0))


def test_work_is_refused_before_anything_is_computed():
    mesh = bumps()
    p = WaterlineParams(boundary=(0, 0, 40, 30), sample_step=0.002, step_down=0.1)
    old = limits.set_limits(max_points=10_000_000)
    try:
        with pytest.raises(TmmError, match=r"sample step 0.002 mm over a 40 x 30 mm boundary and 80 waterline"):
            estimate_work(p, Cutter.ball(4), (0.0, 0.0, 0.0, 40.0, 30.0, 8.0))   # the model's box: levels 8..0
        with pytest.raises(TmmError, match="sample step 0.002 mm"):
            compute(mesh, Cutter.ball(4), p)
    finally:
        limits.set_limits(max_points=old.max_points)
    work = estimate_work(WaterlineParams(boundary=(0, 0, 40, 30)), Cutter.ball(4), (0.0, 0.0, 0.0, 40.0, 30.0, 8.0))
    assert work.count > 0 and work.passes == len(levels(8.0, 0.0, 1.0))
    ranged = estimate_work(WaterlineParams(boundary=(0, 0, 40, 30), top_z=4.0, bottom_z=2.0), Cutter.ball(4),
                           (0.0, 0.0, 0.0, 40.0, 30.0, 8.0))
    assert ranged.passes == len(levels(4.0, 2.0, 1.0)) < work.passes   # the Z range, not the box, when given


def test_a_tiny_step_down_is_refused_at_once_by_name():
    """1e-6 mm: 8e6 levels; counted, not made (making them took 1.86 GB before the refusal)."""
    import time
    import tracemalloc

    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(TmmError, match=r"8.0\d+e\+06 waterline levels \(step-down 1e-06 mm from 8.00118 to"):
            compute(bumps(), Cutter.ball(4), WaterlineParams(boundary=(0, 0, 40, 30), step_down=1e-6))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert time.perf_counter() - t0 < 1.0 and peak < 200e6


def test_levels_stay_within_the_stock():
    mesh = bumps()
    ball = Cutter.ball(4)
    far = WaterlineParams(boundary=(0, 0, 40, 30), top_z=-100.0, bottom_z=-200.0, stock_z=(-2.0, 10.0))
    with pytest.raises(TmmError, match="bottom -200 mm is below the stock's bottom -2 mm"):
        compute(mesh, ball, far)
    with pytest.raises(TmmError, match=r"bottom 2.7\d+e-05 mm \(the model's lowest point\) is below the stock's bottom 1 mm"):
        compute(mesh, ball, WaterlineParams(boundary=(0, 0, 40, 30), stock_z=(1.0, 10.0)))
    # a top above the stock's: the levels start a step-down below the stock's top (none in the air above it)
    high = compute(mesh, ball, WaterlineParams(boundary=(0, 0, 40, 30), top_z=30.0, bottom_z=2.0, step_down=1.0,
                                               stock_z=(0.0, 6.0)))
    assert high.diagnostics["top"] == pytest.approx(5.0)


def test_loops_below_reached_with_the_tool_down_without_gouging():
    """On the bumps, a loop starting within a tool radius below the end of the previous one is joined to it;
    every such straight move stays above the drop height."""
    from tmm_workbench.core.verify.linear_moves import deepest_cut

    mesh = bumps()
    ball = Cutter.ball(4)
    res = compute(mesh, ball, WaterlineParams(boundary=(0, 0, 40, 30), step_down=0.5))
    joined = [k for k, seg in enumerate(res.segments) if seg.joined]
    assert len(joined) == res.diagnostics["joined"] >= 5
    surface = DropSurface(mesh)
    for k in joined:
        a, b = res.segments[k - 1].tips[-1], res.segments[k].tips[0]
        assert np.hypot(*(b[:2] - a[:2])) <= ball.radius and b[2] <= a[2]
        assert deepest_cut(surface, ball, np.vstack([a, b]), np.array([False, True]), step=0.01)[0] <= 1e-4


@pytest.mark.parametrize("cutter", [Cutter.ball(6), Cutter.flat(6), Cutter.bull(8, 1.5)], ids=lambda c: c.kind)
@pytest.mark.parametrize("stock", [0.0, 0.4])
def test_simulated_waterline_does_not_gouge(cutter, stock):
    """sphere_on_plate.stl cut by the waterline path from a box of stock: nothing below the model plus the
    stock to leave by more than 1e-3 mm (along the surface normal, from the vertical deviation and the slope;
    vertically on slopes up to 60 degrees), no rapid through material, and the levels cut material."""
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    p = WaterlineParams(boundary=(lo[0], lo[1], hi[0], hi[1]), step_down=2.5, bottom_z=1.0, chord_tol=5e-4,
                        stock_to_leave=stock)
    result = compute(mesh, cutter, p)
    path = link(result.segments, LinkPolicy(safe_height=hi[2] + 5, clearance_height=hi[2] + 10))
    grid = Grid.covering(lo[0], lo[1], hi[0], hi[1], 0.25)
    design = mesh_heights(mesh, grid)
    if stock > 0:  # the model offset by the stock: the top of a ball of radius `stock` dropped on it
        top = DropSurface(mesh).drop(Cutter.ball(2 * stock), grid.centres(), lo[2] - 10.0) + stock
        design = np.where(np.isfinite(design), top.reshape(design.shape), np.nan)
    sim = simulate(path, cutter, grid, box_heights(grid, hi[2] + 1.0))
    cmp = compare(sim, design, tolerance=1e-3)
    dev = cmp.deviation
    slope = slope_deg(design, grid.cell)
    ok = np.isfinite(dev)
    normal = dev[ok] * np.cos(np.radians(slope[ok]))
    assert normal.min() >= -1e-3
    gentle = ok & (slope <= 60)
    assert dev[gentle].min() >= -1e-3
    assert len(sim.collisions) == 0
    assert sim.removed_volume > 0
    # the passes reach the offset model somewhere: cells beside a contact line
    assert normal.min() < 0.05


@pytest.mark.parametrize("cutter", [Cutter.ball(6), Cutter.bull(8, 1.5)], ids=lambda c: c.kind)
def test_default_chord_tolerance_does_not_gouge_steep_walls(cutter):
    """At the default chord tolerance (0.01 mm) the chords between exact loop points would cut into a convex wall
    (0.047 mm vertically on sphere_on_plate's steep sides before the loops were grown): nothing in the simulated
    stock lies below the model by more than 1e-3 mm vertically, on any slope, and the walls are left within
    the tolerance along the normal."""
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    p = WaterlineParams(boundary=(lo[0], lo[1], hi[0], hi[1]), step_down=0.5, bottom_z=2.0)
    assert p.chord_tol == 0.01
    path = link(compute(mesh, cutter, p).segments, LinkPolicy(safe_height=hi[2] + 5, clearance_height=hi[2] + 10))
    grid = Grid.covering(20, 20, 56, 56, 0.1)                     # the sphere, its steep sides included
    design = mesh_heights(mesh, grid)
    dev = compare(simulate(path, cutter, grid, box_heights(grid, hi[2] + 1.0)), design, tolerance=1e-3).deviation
    slope = slope_deg(design, grid.cell)
    ok = np.isfinite(dev)
    assert dev[ok].min() >= -1e-3
    assert (slope[ok] > 80).any()                                  # steep walls were there to gouge
