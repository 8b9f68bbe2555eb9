"""Clearing one region on hand-made polygons (zlevel_clearing): every point of the region within a step-over
of some offset loop (dense sampling, brute-force distances), loops in cutting order (inside-out: deeper
levels first; outside-in: the outer offsets, then the loops round the island from the farthest in), their
sense for climb and conventional milling, zig-zag lines a step-over apart inside the region, and the gaps a
step-over past the reach leaves filled."""
from __future__ import annotations

import numpy as np
import pytest

from tmm_workbench.core import polygons as P
from tmm_workbench.core.strategies import zlevel_clearing as C


def ring_region() -> P.Region:
    (r,) = P.regions(P.difference([P.rectangle(0, 0, 40, 30)], [P.rectangle(15, 10, 25, 20)]))
    return r


def distance_to_passes(pts: np.ndarray, passes) -> np.ndarray:
    best = np.full(len(pts), np.inf)
    for p in passes:
        xy = np.vstack([p.xy, p.xy[:1]]) if p.closed else p.xy
        a, b = xy[:-1], xy[1:]
        d = b - a
        dd = np.maximum((d * d).sum(1), 1e-300)
        t = np.clip(((pts[:, None, :] - a) * d).sum(2) / dd, 0, 1)
        q = a + t[..., None] * d
        best = np.minimum(best, np.sqrt(((pts[:, None, :] - q) ** 2).sum(2)).min(1))
    return best


def samples_in(region: P.Region, n: int = 4000, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = P.bounds(region.shape)
    pts = np.column_stack([rng.uniform(x0, x1, n), rng.uniform(y0, y1, n)])
    return pts[[P.contains_point(region.shape, p) for p in pts]]


@pytest.mark.parametrize("outside_in", [False, True])
def test_offset_loops_cover_the_region_within_a_step_over(outside_in):
    region, s = ring_region(), 1.7
    passes = C.offset_passes(region, s, outside_in=outside_in)
    pts = samples_in(region)
    assert distance_to_passes(pts, passes).max() < s
    assert all(p.closed for p in passes)
    levels = [p.level for p in passes]
    if not outside_in:
        assert levels[-2:] == [0, 0] and max(levels) == levels[0]             # deepest first, boundary last
    else:
        assert passes[0].outer and passes[0].level == 0
        # the outer offsets first (parents before children), then the loops round the island, farthest first,
        # ending on the island's own contour; climb: outer offsets clockwise, island loops clockwise too
        def from_island(xy):   # distance of each vertex from the island 15..25 x 10..20
            return np.hypot(np.maximum(np.abs(xy[:, 0] - 20) - 5, 0), np.maximum(np.abs(xy[:, 1] - 15) - 5, 0))
        round_island = [np.abs(from_island(p.xy) - p.level * s).max() < 0.01 for p in passes]
        k = round_island.index(True)
        assert all(round_island[k:]) and not any(round_island[:k])
        tail = [p.level for p in passes[k:]]
        assert tail == sorted(tail, reverse=True) and tail[-1] == 0
        assert all(P.signed_area(p.xy) < 0 for p in passes)


def test_senses_for_climb_and_conventional():
    region = P.regions([P.rectangle(0, 0, 20, 10)])[0]
    for climb in (True, False):
        inside_out = C.offset_passes(region, 2.0, climb=climb)
        outside_in = C.offset_passes(region, 2.0, climb=climb, outside_in=True)
        # climb: material on the right; cut from the middle outwards the material is outside: CCW
        assert all((P.signed_area(p.xy) > 0) == climb for p in inside_out)
        assert all((P.signed_area(p.xy) > 0) != climb for p in outside_in)


def test_zigzag_lines_inside_the_region_a_step_over_apart():
    region, s = ring_region(), 2.0
    passes = C.zigzag_passes(region, s)
    lines = [p for p in passes if not p.closed]
    assert len(lines) >= 15 and all(P.segment_inside(p.xy[0], p.xy[-1], region.shape) for p in lines)
    ys = np.unique(np.round([p.xy[0, 1] for p in lines], 9))
    assert np.diff(ys).max() <= s + 1e-9
    assert distance_to_passes(samples_in(region), passes).max() <= s / 2 + 1e-6
    assert any(p.closed and p.outer for p in passes)                           # the contour pass


def test_gaps_past_the_reach_are_filled():
    region = P.regions([P.rectangle(0, 0, 30, 20)])[0]
    reach = 3.0
    passes = C.offset_passes(region, 5.7)                                     # 0.95 of a 6 mm tool
    gaps = C.fill_gaps(region, passes, reach)
    pts = samples_in(region, 6000)
    assert distance_to_passes(pts, passes).max() > reach                     # the offsets alone miss some
    assert gaps and distance_to_passes(pts, passes + gaps).max() <= reach + 1e-3
    assert C.fill_gaps(region, C.offset_passes(region, 2.0), reach) == []


def test_order_from_rotates_loops_to_the_nearest_vertex():
    region = P.regions([P.rectangle(0, 0, 20, 10)])[0]
    start = np.array([20.0, 10.0])
    passes = C.order_from(C.offset_passes(region, 2.0), start)
    assert np.hypot(*(passes[0].xy[0] - start)) == pytest.approx(np.hypot(*(passes[0].xy - start).T).min())
    for a, b in zip(passes, passes[1:]):
        d = np.hypot(*(b.xy - a.xy[0]).T)
        assert d[0] == pytest.approx(d.min())
