"""Splitting a cut segment where it is not to be cut (core.strategies.segment_split), as the holder guard's
leave-out and the rest filter do: the kept runs, their entries, and a segment joined to one whose end was not kept
re-entered from above (a zig-zag link from a cut-off end would feed straight through the part)."""
from __future__ import annotations

import numpy as np

from tmm_workbench.core.linking import RAMP
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.strategies import rest_filter
from tmm_workbench.core.strategies.segment_split import keep_runs, keeps_end, move_samples
from tmm_workbench.core.tools.cutter import Cutter


def line(n: int, y: float = 0.0, joined: bool = False) -> CutSegment:
    return CutSegment(np.column_stack([np.arange(n, dtype=float), np.full(n, y), np.zeros(n)]), joined=joined,
                      entry="helix", helix_centre=(0.0, 1.0))


def test_runs_of_kept_tips_and_moves() -> None:
    seg = line(10, joined=True)
    ok_tip = np.array([1, 1, 1, 0, 1, 1, 1, 1, 0, 1], dtype=bool)
    ok_move = np.ones(10, dtype=bool)
    ok_move[6] = False                      # the move into tip 6
    pieces = keep_runs(seg, ok_tip, ok_move)
    assert [p.tips[:, 0].tolist() for p in pieces] == [[0, 1, 2], [4, 5], [6, 7]]
    assert pieces[0].joined and pieces[0].entry == "helix" and pieces[0].helix_centre == (0.0, 1.0)
    assert not pieces[1].joined and pieces[1].entry == RAMP and pieces[1].helix_centre is None
    assert not keep_runs(seg, ok_tip, ok_move, joined=False)[0].joined


def test_a_five_axis_segments_runs_keep_their_own_tool_axes() -> None:
    n = 6
    tilt = np.radians(np.arange(n) * 5.0)
    axes = np.column_stack([np.sin(tilt), np.zeros(n), np.cos(tilt)])
    seg = CutSegment(line(n).tips, axes=axes, pass_index=3)
    ok_move = np.ones(n, dtype=bool)
    ok_move[3] = False                      # the move into tip 3 left out
    pieces = keep_runs(seg, np.ones(n, dtype=bool), ok_move)
    assert [p.tips[:, 0].tolist() for p in pieces] == [[0, 1, 2], [3, 4, 5]]
    assert np.array_equal(pieces[1].axes, axes[3:]) and all(p.pass_index == 3 for p in pieces)


def test_move_samples_cover_every_move_at_the_step() -> None:
    seg = line(3)
    pts, move = move_samples(seg, 0.3)
    assert move.tolist() == [0, 1, 1, 1, 1, 2, 2, 2, 2]
    assert np.allclose(pts[-1], seg.tips[-1]) and np.diff(pts[:, 0]).max() <= 0.3 + 1e-12


def test_the_rest_filter_unjoins_a_pass_after_a_cut_off_end() -> None:
    grid = Grid.covering(-1.0, -1.0, 10.0, 3.0, 0.25)
    left = np.zeros((grid.ny, grid.nx))
    left[:, :12] = 1.0                       # rest material only at x < 2
    first, second = line(10, 0.0), line(10, 2.0, joined=True)
    second.tips = second.tips[::-1].copy()   # a zig-zag: the next pass comes back from x = 9
    out = rest_filter.apply(type("P", (), {"rest": rest_filter.RestStock(grid, left, 0.01)})(), Cutter.ball(1),
                            [first, second], diags := {})
    assert [p.tips[[0, -1], 0].tolist() for p in out] == [[0, 3], [3, 0]]   # the ball D1 reaches x < 2 from x = 3
    assert not out[1].joined                 # its start was cut off: entered from above, not fed across
    assert diags["rest"]["kept"] < diags["rest"]["moves"]


def test_the_end_is_kept_only_by_a_piece_that_ends_there() -> None:
    seg = line(10, joined=True)
    ok_move = np.ones(10, dtype=bool)
    ok_tip = np.ones(10, dtype=bool)
    ok_tip[8] = False                       # tip 9 alone: a run of one tip, no piece
    pieces = keep_runs(seg, ok_tip, ok_move)
    assert ok_tip[-1] and pieces[-1].tips[-1, 0] == 7.0
    assert not keeps_end(seg, pieces) and keeps_end(seg, keep_runs(seg, np.ones(10, dtype=bool), ok_move))
    assert not keeps_end(seg, [])
