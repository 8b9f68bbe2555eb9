"""The Surface's pass segments: dropped runs of CL points (passes and zig-zag links) in cutting order, split where
they cross air, each straight pass thinned by its chord tolerance (reduce_chords). The raster (core.strategies.
raster_drop), the region's chains (raster_region) and the verification's partial passes (variable_step) cut
their runs with it."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.cancel import poll
from tmm_workbench.core.segments import CutSegment, SegmentKind
from tmm_workbench.core.strategies.surface.params import ONEWAY

_COLLINEAR_MM = 1e-7  # points this close to the chord of their neighbours add nothing to the path


def segments(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray,
             pattern: str, chord_tol: float = 0.0) -> list[CutSegment]:
    """Segments in cutting order. A pass is split where it crosses air; a zig-zag link that crosses air is
    left out. A segment is `joined` when the tool reaches it without a retract."""
    out: list[CutSegment] = []
    detach = True
    k = 0
    index = -1  # pass number (a link belongs to the pass it leads to)
    for is_link, xy in runs:
        poll()   # Python per pass over millions of points: Cancel heard, the dialog repaints
        index += 0 if is_link else 1
        pts, gap = np.column_stack([xy, z[k:k + len(xy)]]), air[k:k + len(xy)]
        k += len(xy)
        if is_link:
            if gap.any():
                detach = True
            elif len(pts):
                out.append(CutSegment(pts, SegmentKind.LINK, joined=not detach, pass_index=index + 1))
                detach = False
            continue
        if pattern == ONEWAY:
            detach = True
        # consecutive on-model points: [start, end) index pairs
        edges = np.flatnonzero(np.diff(np.concatenate([[True], gap, [True]]).astype(np.int8)))
        for start, end in zip(edges[::2], edges[1::2]):
            out.append(CutSegment(reduce_chords(pts[start:end], chord_tol), joined=not (detach or start > 0),
                                  pass_index=index))
            detach = False
        if len(gap) and gap[-1]:
            detach = True
    return out


def reduce_chords(pts: np.ndarray, tol: float) -> np.ndarray:
    """The points of one straight pass (XY on one line, in order) thinned so that each straight move that
    replaces some passes no more than `tol` above any of them and never below one (by more than
    _COLLINEAR_MM): the exact CL path is the sampled one, and a chord above all its vertices is above the
    sampled polyline everywhere (both linear in between), so nothing gouges that did not before. Greedy
    from each kept point: the feasible slopes of the chord form an interval that every skipped point
    narrows (a sleeve), O(n)."""
    n = len(pts)
    if n < 3:
        return pts
    xy = pts[:, :2]
    d = xy[-1] - xy[0]
    length = float(np.hypot(*d))
    if length <= 0:  # all on one XY point (a closed 3D offset loop also ends where it starts: kept as it is)
        return pts[[0, -1]] if np.ptp(pts[:, 2]) <= _COLLINEAR_MM and np.ptp(xy, axis=0).max() <= _COLLINEAR_MM else pts
    u = d / length
    s = (xy - xy[0]) @ u                                   # distance along the pass
    off = np.abs((xy - xy[0]) @ np.array([-u[1], u[0]]))  # off the pass line (none, for a raster pass)
    if off.max() > _COLLINEAR_MM or np.any(np.diff(s) < 0):
        return pts  # not one straight, ordered pass: keep it as it is
    steps = np.flatnonzero(np.diff(s) <= _COLLINEAR_MM)  # vertical moves (raster_refine's cliff corners)
    if len(steps):  # each side reduced on its own, the vertical moves kept
        cuts = np.concatenate([[0], steps + 1, [n]])
        return np.vstack([reduce_chords(pts[a:b], tol) for a, b in zip(cuts[:-1], cuts[1:])])
    z = pts[:, 2]
    keep = [0]
    a = 0
    lo, hi = -math.inf, math.inf
    for j in range(1, n):
        ds = s[j] - s[a]
        m = (z[j] - z[a]) / ds
        if j > a + 1 and not (lo <= m <= hi):
            keep.append(j - 1)                               # the chord a -> j - 1 was the last that held
            a = j - 1
            ds = s[j] - s[a]
            lo, hi = -math.inf, math.inf
        # j becomes a point a later chord from a must pass: on or above it, within tol
        lo = max(lo, (z[j] - _COLLINEAR_MM - z[a]) / ds)
        hi = min(hi, (z[j] + tol - z[a]) / ds)
    keep.append(n - 1)
    return pts[np.unique(keep)]
