"""nearest_first against the plain quadratic scan it replaces (the reference, written out here)."""
import numpy as np
import pytest

from tmm_workbench.core.geometry.ordering import nearest_first


def _scan(pieces, start=None):
    """The plain scan: each next piece the free one with an end nearest the last exit (ties: lowest index, head)."""
    left = list(range(len(pieces)))
    out = []
    if start is None:
        k, turn = 0, False
    else:
        k, turn = None, None
    here = None if start is None else np.asarray(start, float)
    while left:
        if k is None:
            ends = np.array([[pieces[i][0][:2], pieces[i][-1][:2]] for i in left])
            d = np.hypot(*(ends - here).transpose(2, 0, 1))
            i, e = np.unravel_index(int(np.argmin(d)), d.shape)
            k, turn = left[int(i)], e == 1
        left.remove(k)
        p = pieces[k][::-1] if turn else pieces[k]
        out.append(p)
        here, k = p[-1][:2], None
    return out


def _same(a, b):
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b))


@pytest.mark.parametrize("seed", range(4))
def test_the_order_is_the_plain_scans_on_random_pieces(seed):
    rng = np.random.default_rng(seed)
    pieces = [rng.uniform(0, 50, (rng.integers(2, 5), 2)) for _ in range(300)]
    assert _same(nearest_first(pieces), _scan(pieces))
    assert _same(nearest_first(pieces, start=(25.0, -3.0)), _scan(pieces, (25.0, -3.0)))


def test_ties_go_to_the_lowest_piece_then_its_head():
    # A grid: many ends at equal distances, and pieces sharing ends (a rebuilt tree must keep the tie rule).
    xs = np.arange(12, dtype=float)
    pieces = [np.array([[x, y], [x + 1, y]]) for y in range(6) for x in xs]
    pieces += [np.array([[x + 1, y], [x, y]]) for y in range(3) for x in xs]
    ordered = nearest_first(pieces, start=(0.0, 0.0))
    assert _same(ordered, _scan(pieces, (0.0, 0.0)))
    assert len(ordered) == len(pieces)


def test_three_d_pieces_are_ordered_by_xy_and_empty_input_gives_nothing():
    pieces = [np.array([[0.0, 0, 5], [1, 0, 9]]), np.array([[9.0, 0, 0], [1.5, 0, 0]])]
    ordered = nearest_first(pieces)
    assert ordered[1][0, 0] == 1.5            # entered at its nearer end, turned
    assert nearest_first([]) == []
