"""The one linker: vertical retracts (3-axis), retracts along the tool axis (5-axis), joined segments kept
down, the entry table, empty input; and the tool model's transit geometry it relies on."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import ALONG_AXIS, ENTRIES, LinkPolicy, link
from tmm_workbench.core.segments import CutSegment, SegmentKind
from tmm_workbench.core.toolpath import MoveKind, Z_AXIS
from tmm_workbench.core.tools.cutter import Cutter
from tests.core.zmap_reference import ZTool


def seg(points, joined=False, kind=SegmentKind.PASS, axes=None):
    return CutSegment(np.array(points, dtype=float), kind, axes=axes, joined=joined)


def kinds(tp):
    return [m.kind for m in tp]


def test_vertical_retract_between_detached_segments():
    a = seg([(0, 0, 1), (10, 0, 1)])
    b = seg([(10, 5, 2), (0, 5, 2)])
    tp = link([a, b], LinkPolicy(safe_height=8.0, clearance_height=12.0))
    R, P, F = MoveKind.RAPID, MoveKind.PLUNGE, MoveKind.FEED
    assert kinds(tp) == [R, R, P, F, R, R, P, F, R]
    z = [m.z for m in tp]
    assert z == [12.0, 8.0, 1.0, 1.0, 8.0, 8.0, 2.0, 2.0, 12.0]
    # lift straight up from the end of a, cross at the safe height to above b's start, plunge
    assert (tp.moves[4].x, tp.moves[4].y) == (10.0, 0.0) and (tp.moves[5].x, tp.moves[5].y) == (10.0, 5.0)


def test_joined_segments_keep_the_tool_down():
    a = seg([(0, 0, 1), (10, 0, 1)])
    link_ = seg([(10, 2.5, 1.5)], joined=True, kind=SegmentKind.LINK)
    b = seg([(10, 5, 2), (0, 5, 2)], joined=True)
    tp = link([a, link_, b], LinkPolicy(8.0, 12.0))
    assert kinds(tp).count(MoveKind.PLUNGE) == 1
    cut = tp.cutting_points()
    np.testing.assert_array_equal(cut, np.vstack([a.tips, link_.tips, b.tips]))


def test_arcs_of_the_segments_are_the_feed_moves_arcs():
    """The linker makes a segment's arcs arc moves (Move.arc): the move into a joined segment's first tip too,
    never the entry into a segment it enters from above."""
    from tmm_workbench.core.arcs import Arc

    up, down = Arc((5.0, 0.0, -4.0), False, "XZ"), Arc((5.0, 5.0, -4.0), True, "XZ")
    a = CutSegment(np.array([(0, 0, 1), (10, 0, 1)], dtype=float), arcs=(down, up))
    b = CutSegment(np.array([(10, 5, 1), (0, 5, 1)], dtype=float), joined=True, arcs=(up, None))
    c = CutSegment(np.array([(0, 10, 1), (10, 10, 1)], dtype=float), arcs=(down, up))
    tp = link([a, b, c], LinkPolicy(8.0, 12.0))
    feeds = [m for m in tp if m.kind is MoveKind.FEED]
    assert [m.arc for m in feeds] == [up, up, None, up]  # a's and c's first tips are plunged onto
    assert all(m.arc is None for m in tp if m.kind is not MoveKind.FEED)
    assert tp.arcs == {i: m.arc for i, m in enumerate(tp.moves) if m.arc is not None} and len(tp.arcs) == 3


def test_along_axis_retract_and_transit_height():
    tool = Cutter.torus(6.7, 6.0)
    t = math.radians(20)
    axis = np.array([math.sin(t), 0.0, math.cos(t)])
    a = seg([(0, 0, 0), (0, 10, 0)], axes=[axis, axis])
    b = seg([(20, 10, 0), (20, 0, 0)], axes=[axis, axis])
    policy = LinkPolicy(10.0, 15.0, ALONG_AXIS, 5.0, lowest_below_tip=tool.lowest_below_tip)
    tp = link([a, b], policy)
    m = tp.moves
    assert m[0].axis == Z_AXIS and m[-1].axis == Z_AXIS        # upright at start and end
    assert m[0].z == m[1].z >= 15.0 and m[-1].z >= 15.0
    drop = tool.lowest_below_tip(tuple(axis))
    assert drop == pytest.approx(6.0 * (1 - math.cos(t)) + 6.7 * math.sin(t))
    firsts = {(0.0, 0.0, 0.0), (20.0, 10.0, 0.0)}
    entries = [i for i, mv in enumerate(m) if mv.kind is MoveKind.PLUNGE and (mv.x, mv.y, mv.z) in firsts]
    assert len(entries) == 2
    for i in entries:                    # entered along its axis from axis_retract above, at the feed
        d = np.subtract((m[i].x, m[i].y, m[i].z), (m[i - 1].x, m[i - 1].y, m[i - 1].z))
        np.testing.assert_allclose(-d / np.linalg.norm(d), axis, atol=1e-12)
        assert np.linalg.norm(d) == pytest.approx(5.0)
        assert m[i - 1].kind is MoveKind.PLUNGE                      # fed down from the transit height too
        assert m[i - 2].kind is MoveKind.RAPID and m[i - 2].z == pytest.approx(max(m[i].z + 5 * axis[2], 10.0 + drop))
    # rapids stay above the safe height (the tilted tool's lowest point at both ends), but for straight up
    # out of the tool's own column (as the 3-axis retract: under the tool all is cut already)
    for i in range(1, len(m)):
        up = (m[i].x, m[i].y, m[i].axis) == (m[i - 1].x, m[i - 1].y, m[i - 1].axis) and m[i].z > m[i - 1].z
        if m[i].kind is MoveKind.RAPID and not up:
            for p in (m[i - 1], m[i]):
                assert p.z - tool.lowest_below_tip(p.axis) >= 10.0 - 1e-9, (i, p)
    assert kinds(tp).count(MoveKind.PLUNGE) == 6  # per segment: down to the entry point, the entry, the exit


def test_along_axis_needs_the_tool_geometry():
    with pytest.raises(TmmError, match="lowest_below_tip"):
        link([seg([(0, 0, 0)])], LinkPolicy(10.0, 15.0, ALONG_AXIS))


def test_policy_is_checked():
    with pytest.raises(TmmError, match="clearance height 5 mm is below the safe height 10 mm"):
        link([seg([(0, 0, 0)])], LinkPolicy(10.0, 5.0))
    with pytest.raises(TmmError, match="entry must be one of plunge, helix, ramp"):
        link([seg([(0, 0, 0)])], LinkPolicy(10.0, 15.0, entry="spiral"))
    assert set(ENTRIES) == {"plunge", "helix", "ramp"}


def test_no_segments_no_path():
    assert len(link([], LinkPolicy(10.0, 15.0))) == 0
    assert len(link([seg(np.zeros((0, 3)))], LinkPolicy(10.0, 15.0))) == 0


def test_one_tool_model_views():
    bull = Cutter.bull(12.0, 2.0)
    assert bull.torus_radii == (4.0, 2.0)
    assert Cutter.ball(6.0).torus_radii == (0.0, 3.0)
    with pytest.raises(TmmError, match="flat end mill"):
        Cutter.flat(6.0).torus_radii
    z = ZTool.of(bull, "bull_nose")
    assert (z.Ro, z.Ri, z.shape) == (4.0, 2.0, "bull_nose")
    assert bull.lowest_below_tip((0.0, 0.0, 1.0)) == 0.0
    assert bull.lowest_below_tip((1.0, 0.0, 0.0)) == pytest.approx(2.0 + 4.0)
