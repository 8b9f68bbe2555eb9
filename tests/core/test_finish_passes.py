"""Multi-pass finishing, final depth, start point and % step-over of the 3-axis raster (issue 15 item 6): the
pass sets leave stock_to_leave + k * step-down ... stock_to_leave in order, and the simulated stock after all
of them is the single finishing pass's (earlier sets never cut below the finish); the defaults give
raster_drop's tool path unchanged; the start point picks the end of the raster nearest it; bad input by name."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.test_adaptive_raster import BOX, bump
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.strategies.finish_passes import (FinishParams, compute_finish_toolpath, reverse_path,
                                                         start_order, stepover_of_percent)
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute, compute_surface_toolpath
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter

POLICY = LinkPolicy(safe_height=10, clearance_height=12)
BALL = Cutter.ball(6)


def test_pass_sets_leave_the_stated_stock_in_order():
    plane = grid_mesh(lambda x, y: 0.0 * x, 4, 4, (-20, -20, 40, 40))
    params = SurfaceParams(boundary=BOX, stepover=2.0, sample_step=1.0, stock_to_leave=0.2)
    path = compute_finish_toolpath(plane, BALL, params, FinishParams(passes=3, step_down=0.5), POLICY)
    cut_z = [m.z for m in path if m.kind is MoveKind.FEED]
    levels = [z for i, z in enumerate(cut_z) if i == 0 or abs(z - cut_z[i - 1]) > 1e-9]
    assert levels == pytest.approx([1.2, 0.7, 0.2])          # semi-finish passes first, the finish last
    single = compute_surface_toolpath(plane, BALL, params, POLICY)
    assert sum(m.kind is MoveKind.FEED for m in path) == 3 * sum(m.kind is MoveKind.FEED for m in single)


def test_earlier_passes_never_cut_below_the_finish_simulated():
    mesh = bump()
    params = SurfaceParams(boundary=BOX, stepover=1.0, sample_step=0.5, stock_to_leave=0.1)
    grid = Grid.covering(4, 3.5, 16, 8.5, 0.05)
    multi = compute_finish_toolpath(mesh, BALL, params, FinishParams(passes=3, step_down=0.4), POLICY)
    one = compute_surface_toolpath(mesh, BALL, params, POLICY)
    after_multi = simulate(multi, BALL, grid, box_heights(grid, 5)).heights
    after_one = simulate(one, BALL, grid, box_heights(grid, 5)).heights
    assert np.abs(after_multi - after_one).max() < 1e-9
    # the semi-finish passes alone leave at least 0.4 mm more everywhere
    semi = compute_finish_toolpath(mesh, BALL, SurfaceParams(boundary=BOX, stepover=1.0, sample_step=0.5,
                                                             stock_to_leave=0.5),
                                   FinishParams(passes=2, step_down=0.4), POLICY)
    after_semi = simulate(semi, BALL, grid, box_heights(grid, 5)).heights
    assert (after_semi - after_one).min() > 0.4 - 1e-6


def test_defaults_are_the_raster_unchanged():
    mesh = bump()
    params = SurfaceParams(boundary=BOX, stepover=1.5, sample_step=0.5)
    a = compute_surface_toolpath(mesh, BALL, params, POLICY).points()
    b = compute_finish_toolpath(mesh, BALL, params, FinishParams(), POLICY).points()
    assert a.shape == b.shape and np.array_equal(a, b)


def test_final_depth_holds_every_tip():
    mesh = bump()
    params = SurfaceParams(boundary=BOX, stepover=1.5, sample_step=0.5)
    path = compute_finish_toolpath(mesh, BALL, params, FinishParams(final_depth=1.0), POLICY)
    z = path.cutting_points()[:, 2]
    assert z.min() == pytest.approx(1.0) and z.max() > 1.5  # the bump's top still followed


@pytest.mark.parametrize("stepover", [2.0, 2.4])  # 7 and 6 passes across the 12 mm
@pytest.mark.parametrize("pattern", ["zigzag", "oneway"])
@pytest.mark.parametrize("corner", [(0, 0), (20, 12), (20, 0), (0, 12), (5, -3)])
def test_start_point_picks_the_nearest_pass(pattern, corner, stepover):
    mesh = bump()
    params = SurfaceParams(boundary=BOX, stepover=stepover, sample_step=0.5, pattern=pattern)
    path = compute_finish_toolpath(mesh, BALL, params, FinishParams(start_xy=corner), POLICY)
    first = path.cutting_points()[0]
    near_y = 0.0 if corner[1] <= 6 else 12.0
    assert first[1] == pytest.approx(near_y, abs=1e-9)                # the pass nearest the start point first
    near_x = 0.0 if corner[0] <= 10 else 20.0
    odd_zigzag = pattern == "zigzag" and stepover == 2.0
    if not odd_zigzag or (near_x == 0.0) == (near_y == 0.0):  # an odd zig-zag reaches two corners only
        assert first[0] == pytest.approx(near_x, abs=1e-9)            # at its end nearest the start point
    # the same points are cut, in another order
    plain = compute_surface_toolpath(mesh, BALL, params, POLICY).cutting_points()
    got = path.cutting_points()
    assert len(got) == len(plain)
    assert np.allclose(np.sort(got[:, 2]), np.sort(plain[:, 2]), atol=1e-6)


@pytest.mark.parametrize("corner", [(0.0, 0.0), (20.0, 12.0)])
def test_arcs_kept_when_the_pass_set_runs_backwards(corner):
    """ArcFitting with two pass sets and a start point (the sets begun at the corner nearest it, run backwards
    for the far corner): every arc the raster fitted reaches the path, in the sense of the way it is run, and the
    finishing set's moves, arcs as circles, stay within the chord tolerance of the exact CL path."""
    from tests.core.test_raster_lean import arcs_of
    from tmm_workbench.core.query.drop import DropSurface

    mesh, tol = bump(), 0.001
    params = SurfaceParams(boundary=BOX, stepover=2.0, sample_step=0.5, forward_step="tolerance", chord_tol=tol,
                           arcs=True)
    finish = FinishParams(passes=2, step_down=0.5, start_xy=corner)
    path = compute_finish_toolpath(mesh, BALL, params, finish, POLICY)
    fitted = sum(len(arcs_of(compute(mesh, BALL, params if k else replace(params, stock_to_leave=0.5)).segments))
                 for k in (0, 1))
    assert len(path.arcs) == fitted > 20
    assert {a.clockwise for a in path.arcs.values()} == {True, False}
    # the finishing set: the moves after the last retract
    tp = path.chorded(1e-6)
    p = tp.points()
    last_rapid = max(i for i, m in enumerate(tp.moves) if m.kind is MoveKind.RAPID and i < len(tp.moves) - 3)
    feed = [i for i in range(last_rapid + 1, len(p)) if tp.moves[i].kind is MoveKind.FEED and i > 0]
    pts = np.vstack([p[i - 1] + np.linspace(0, 1, 20)[:, None] * (p[i] - p[i - 1]) for i in feed])
    exact = DropSurface(mesh).drop(BALL, pts[:, :2], float(mesh.bounds[0][2]))
    assert len(feed) > 100 and np.abs(pts[:, 2] - exact).max() <= tol + 1e-6


def test_reverse_path_keeps_joins():
    mesh = bump()
    segs = compute(mesh, BALL, SurfaceParams(boundary=BOX, stepover=2.0, sample_step=0.5)).segments
    back = reverse_path(segs)
    assert [s.joined for s in back] == [False] + [s.joined for s in reversed(segs)][:-1]
    assert np.array_equal(back[0].tips, segs[-1].tips[::-1])
    assert reverse_path(back)[3].tips.tolist() == segs[3].tips.tolist()
    assert start_order(segs, None) is segs


def test_bad_input_is_named():
    mesh = bump()
    params = SurfaceParams(boundary=BOX, stepover=2.0, sample_step=0.5)
    with pytest.raises(TmmError, match="finishing passes must be a whole number in \\[1, 50\\], got 0"):
        compute_finish_toolpath(mesh, BALL, params, FinishParams(passes=0), POLICY)
    with pytest.raises(TmmError, match="finishing step-down must be a positive length, got -1"):
        compute_finish_toolpath(mesh, BALL, params, FinishParams(passes=2, step_down=-1.0), POLICY)
    with pytest.raises(TmmError, match="start point"):
        compute_finish_toolpath(mesh, BALL, params, FinishParams(start_xy=(float("nan"), 0.0)), POLICY)
    with pytest.raises(TmmError, match=r"step-over must be in \(0, 100\] % of the tool diameter, got 0 %"):
        stepover_of_percent(0.0, BALL)
    assert stepover_of_percent(25.0, BALL) == pytest.approx(1.5)
    with pytest.raises(TmmError, match="CL points"):  # all the pass sets counted before any is dropped
        compute_finish_toolpath(mesh, BALL, SurfaceParams(boundary=BOX, stepover=1e-3, sample_step=1e-3),
                                FinishParams(passes=50, step_down=0.1), POLICY)


def test_reverse_path_reverses_the_arcs():
    """Each move of the reversed path is the same circle run the other way: the arc into tip i of a segment ends,
    reversed, at its tip i - 1, and the arc into a joined segment's first tip moves to the segment before."""
    from tmm_workbench.core.arcs import Arc
    from tmm_workbench.core.segments import CutSegment

    def arc(x: float) -> Arc:
        return Arc((x, 0.0, -5.0), True, "XZ")

    a = CutSegment(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), arcs=(None, arc(0.5), None))
    b = CutSegment(np.array([[3.0, 0, 0], [4, 0, 0]]), joined=True, arcs=(arc(2.5), arc(3.5)))
    back = reverse_path([a, b])
    assert back[0].tips[:, 0].tolist() == [4, 3] and back[0].arcs == (None, arc(3.5).reversed())
    assert back[1].joined and back[1].tips[:, 0].tolist() == [2, 1, 0]
    assert back[1].arcs == (arc(2.5).reversed(), None, arc(0.5).reversed())
    assert arc(0.5).reversed().clockwise is False
