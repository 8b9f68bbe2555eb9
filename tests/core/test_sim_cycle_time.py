"""Cycle time of a 3-axis path (core.sim.cycle_time): each move the longer of its slowest axis at the rapid
rate and its length at its feed, summed; checked against the sums written out by hand."""
from __future__ import annotations

import math

import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.sim.cycle_time import DEFAULT_RAPID_MM_S, three_axis_time, toolpath_feeds
from tmm_workbench.core.toolpath import MoveKind, Toolpath


def test_hand_sums():
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 50)
    tp.add(MoveKind.RAPID, 30, 40, 50)      # XY rapid: X 30, Y 40 at 100 mm/s -> 0.4 s (Y the slowest)
    tp.add(MoveKind.RAPID, 30, 40, 5)       # Z rapid 45 mm at 50 mm/s -> 0.9 s
    tp.add(MoveKind.PLUNGE, 30, 40, 0)      # 5 mm at 2 mm/s -> 2.5 s
    tp.add(MoveKind.FEED, 60, 80, 0)        # 50 mm at 20 mm/s -> 2.5 s
    tp.add(MoveKind.FEED, 60, 80, -1)       # 1 mm down at the horizontal feed -> 0.05 s
    t = three_axis_time(tp.points(), toolpath_feeds(tp, 20.0, 2.0), horiz_rapid=100.0, vert_rapid=50.0)
    assert t.rapid_seconds == pytest.approx(0.4 + 0.9)
    assert t.cutting_seconds == pytest.approx(2.5 + 2.5 + 0.05)
    assert t.seconds == pytest.approx(6.35)
    assert t.cutting_length == pytest.approx(56.0) and t.rapid_length == pytest.approx(95.0)
    assert t.hms() == "00:00:06"
    # a slow rapid axis rules a fast feed: 50 mm at 1e6 mm/s still takes the joints' 30 / 100 s
    fast = three_axis_time(tp.points()[3:5], [None, 1e6], horiz_rapid=100.0)
    assert fast.seconds == pytest.approx(40 / 100.0)


def test_default_rapid_and_bad_feeds():
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 0)
    tp.add(MoveKind.RAPID, 100, 0, 0)
    assert three_axis_time(tp.points(), [None, None]).seconds == pytest.approx(100 / DEFAULT_RAPID_MM_S)
    with pytest.raises(TmmError, match="move 1 has the feed 0.0"):
        three_axis_time(tp.points(), [None, 0.0])
    with pytest.raises(TmmError, match="move 1 has the feed nan"):
        three_axis_time(tp.points(), [None, math.nan])
    with pytest.raises(TmmError, match="1 feeds for 2 points"):
        three_axis_time(tp.points(), [None])
