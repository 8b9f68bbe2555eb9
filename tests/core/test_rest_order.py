"""The order of a rest's pieces (core.strategies.rest_order): a piece that may be cut either way is entered at its
nearer end; 2-opt undoes the long moves back a nearest-first order leaves; the loops keep their sense, a chain of
joined pieces stays together and in its order."""
from __future__ import annotations

import numpy as np

from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies import rest_order


def moves(segments: list[CutSegment]) -> float:
    """The sum of the cost of the moves between the chains as they come."""
    chains = rest_order.chains_of(segments)
    return float(sum(rest_order.cost(a[-1].tips[-1], b[0].tips[0]) for a, b in zip(chains[:-1], chains[1:])))


def test_passes_that_may_be_cut_either_way_are_entered_at_their_nearer_end() -> None:
    passes = [CutSegment(np.array([[x, 0.0, 0.0], [x, 5.0, 0.0]])) for x in np.arange(6.0)]   # all one way
    assert moves(rest_order.ordered(passes)) == 5 * np.hypot(1.0, 5.0)   # back across each pass
    out = rest_order.ordered(passes, {id(p) for p in passes})
    assert moves(out) == 5 * 1.0 and len(out) == 6                   # a zig-zag
    assert [float(seg.tips[0, 1]) for seg in out] == [0.0, 5.0] * 3 and not any(seg.joined for seg in out)
    assert out[0] is passes[0] and np.array_equal(out[1].tips, passes[1].tips[::-1])


def test_two_opt_undoes_the_long_moves_back_of_the_nearest_first_order() -> None:
    # touch-ups on a line: nearest-first from x = 0 goes 0, 1, 3, -1.5, -4.5 (10.5 mm); in a row it is 7.5
    points = [CutSegment(np.array([[x, 0.0, 0.0]] * 2)) for x in (0.0, -4.5, 3.0, -1.5, 1.0)]
    out = rest_order.ordered(points, {id(p) for p in points})
    assert moves(out) == 7.5
    assert sorted(float(seg.tips[0, 0]) for seg in out) == [-4.5, -1.5, 0.0, 1.0, 3.0]
    # none may turn: the nearest-first order as before
    assert moves(rest_order.ordered(points)) == 1.0 + 2.0 + 4.5 + 3.0


def test_loops_keep_their_sense_and_joined_chains_stay_together() -> None:
    def piece(x: float, y0: float, y1: float, joined: bool = False) -> CutSegment:
        return CutSegment(np.array([[x, y0, 0.0], [x, y1, 0.0]]), joined=joined)

    loop = piece(1.0, 0.0, 5.0)                                   # a loop's piece: its sense kept
    a, a2 = piece(0.0, 0.0, 5.0), piece(0.2, 5.0, 0.0, True)      # a chain: a, then a2 with the tool down
    b, c = piece(2.0, 0.0, 5.0), piece(3.0, 0.0, 5.0)
    out = rest_order.ordered([a, a2, loop, b, c], {id(s) for s in (a, a2, b, c)})
    assert any(seg is loop for seg in out)
    k = next(i for i, seg in enumerate(out) if np.array_equal(seg.tips, a.tips) or np.array_equal(seg.tips,
                                                                                                  a.tips[::-1]))
    first, second = out[k], out[k + 1]
    assert not first.joined and second.joined                     # still one chain, entered at one end
    assert {tuple(first.tips[0]), tuple(second.tips[-1])} == {tuple(a.tips[0]), tuple(a2.tips[-1])}
