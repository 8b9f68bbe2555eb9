"""No gouge between 3-axis CL points (the 3-axis side): the straight move between two
dropped points passes below the exact drop height where a ridge or an edge lies between them. Each move is
checked at 5 interior points (dropped in one batch for all moves); where it passes more than `tol` below,
or where a steep move's middle lies far from its chord (a jump of the drop height between samples), the
point halfway is dropped and inserted, and the two new moves are checked in turn. A move shorter than
`min_step` that still cuts in crosses a cliff (the tool dropping off an open edge to the floor, or climbing
onto one): it becomes a horizontal move at the upper height and a vertical one, the way a machinist would
go down an edge. Deeper moves than `tol` left after `rounds` are counted in the diagnostics.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from tmm_workbench.core import cancel

Drop = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # xy (n, 2) -> (z (n,), air (n,) bool)
_FRACTIONS = np.array([0.2, 0.4, 0.5, 0.6, 0.8])
_MID = 2  # the index of 0.5
_BLOCK = 20_000  # moves checked per drop: 100k drops, about 0.35 s on mount_rush (50k moves held the GUI 0.9 s)
_NONE = np.zeros(0, dtype=np.int64)


def refine(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray, drop: Drop, tol: float,
           chained: bool, rounds: int = 12, min_step: float = 1e-3, leave_tol: float = math.inf
           ) -> tuple[list[tuple[bool, np.ndarray]], np.ndarray, np.ndarray, dict]:
    """The runs (is_link, xy) with points inserted, their heights and air flags (flattened as the input).
    chained: consecutive runs are cut one after the other with the tool down (zig-zag: a pass, its link,
    the next pass), so the move from a run's last point to the next run's first is checked too (points
    found there are added to the end of the first run). leave_tol: a move passing more than this above the exact
    drop height is split too (the cusp modes: in a concave valley or corner a move across the crease of the CL
    surface leaves material above the cusp their spacing was computed for, which places it on the CL points).

    The moves to check are kept per run (the index of their first point) and checked as arrays, a block of
    runs at a time, so that a fine step-over's millions of moves neither hold a cancel (core.cancel) for a
    second nor ask for arrays of hundreds of MB."""
    pts: list[np.ndarray] = []   # per run: (k, 3) points
    airs: list[np.ndarray] = []
    k = 0
    for _, xy in runs:
        pts.append(np.column_stack([xy, z[k:k + len(xy)]]))
        airs.append(air[k:k + len(xy)].copy())
        k += len(xy)
    lengths = [len(p) for p in pts]
    todo = [np.arange(max(n - 1 + (chained and r + 1 < len(pts) and lengths[r + 1] > 0), 0))
            for r, n in enumerate(lengths)]
    inserted, cliffs, deepest = 0, 0, 0.0
    for _ in range(rounds):
        todo = _cutting(airs, todo)
        if not any(len(t) for t in todo):
            break
        todo, found, found_cliffs, worst = _split_round(pts, airs, todo, drop, tol, leave_tol, min_step)
        if not found:
            break
        inserted, cliffs, deepest = inserted + found, cliffs + found_cliffs, float(max(worst, 0.0))
    else:
        todo = _cutting(airs, todo)
    remaining = sum(len(t) for t in todo)
    out_runs = [(is_link, p[:, :2]) for (is_link, _), p in zip(runs, pts)]
    z_out = np.concatenate([p[:, 2] for p in pts]) if pts else z
    air_out = np.concatenate(airs) if airs else air
    return out_runs, z_out, air_out, {"inserted": inserted, "cliffs": cliffs, "unchecked_after_rounds": remaining,
                                      "deepest_refined": deepest}


def _cutting(airs: list[np.ndarray], todo: list[np.ndarray]) -> list[np.ndarray]:
    """The moves of todo that cut: neither end in the air."""
    out = []
    for r, t in enumerate(todo):
        if len(t):
            cancel.poll()
            after = np.concatenate([airs[r][1:], airs[r + 1][:1]]) if r + 1 < len(airs) else airs[r][1:]
            t = t[~(airs[r][t] | after[t])]
        out.append(t)
    return out


def _split_round(pts: list[np.ndarray], airs: list[np.ndarray], todo: list[np.ndarray], drop: Drop, tol: float,
                 leave_tol: float, min_step: float) -> tuple[list[np.ndarray], int, int, float]:
    """One round: the moves of todo checked a block of runs at a time, points inserted where they cut in (or
    leave too much); returns the moves to check next, the points inserted, the cliffs among them and the
    deepest cut found (-inf if none)."""
    following = [_NONE] * len(pts)
    found, found_cliffs, worst = 0, 0, -math.inf
    r0 = 0
    while r0 < len(pts):
        r1, count = r0, 0
        while r1 < len(pts) and (count == 0 or count + len(todo[r1]) <= _BLOCK):
            count, r1 = count + len(todo[r1]), r1 + 1
        group = [r for r in range(r0, r1) if len(todo[r])]
        r0 = r1
        if not group:
            continue
        cancel.poll()
        ends = [_ends(pts, r, todo[r]) for r in group]
        rs = np.repeat(group, [len(todo[r]) for r in group])
        bad, new, new_air, cliff, cuts = _check_block(np.concatenate([e[0] for e in ends]),
                                                      np.concatenate([e[1] for e in ends]),
                                                      drop, tol, leave_tol, min_step)
        if len(bad):
            found, found_cliffs, worst = found + len(bad), found_cliffs + int(cliff.sum()), max(worst, cuts.max())
            _insert(pts, airs, rs[bad], np.concatenate([todo[r] for r in group])[bad], new, new_air, following)
    return following, found, found_cliffs, worst


def _ends(pts: list[np.ndarray], r: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first and last points of the moves t of run r (the last point of a run moves to the next run's
    first)."""
    p = pts[r]
    b = p[np.minimum(t + 1, len(p) - 1)]
    last = t + 1 == len(p)
    if last.any():
        b[last] = pts[r + 1][0]
    return p[t], b


def _check_block(a: np.ndarray, b: np.ndarray, drop: Drop, tol: float, leave_tol: float, min_step: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The moves a -> b to split: their positions, the points to insert, whether each is in the air, which
    are cliffs, and how far each cuts in."""
    samples = a[:, None, :] + _FRACTIONS[None, :, None] * (b - a)[:, None, :]   # (m, 5, 3)
    zs, air_s = drop(samples[:, :, :2].reshape(-1, 2))
    zs, air_s = zs.reshape(len(a), -1), air_s.reshape(len(a), -1)
    cut = zs - samples[:, :, 2]
    cut[air_s] = -np.inf
    worst = cut.max(axis=1)
    left = np.where(air_s, -np.inf, -cut).max(axis=1)
    # a jump of the drop height (an edge the tool falls off or climbs onto) can hide between the samples:
    # a steep move whose middle is far from its chord, above or below, is split until the jump is found
    steep = np.abs(b[:, 2] - a[:, 2]) > 10 * tol
    jump = steep & (np.abs(cut[:, _MID]) > tol) & np.isfinite(cut[:, _MID])
    bad = np.flatnonzero((worst > tol) | jump | (left > leave_tol))
    # the halfway point, dropped with the samples; a move shorter than min_step is a cliff: across at the
    # upper height, then straight down (or up, then across)
    pa, pb = a[bad], b[bad]
    cliff = ~(np.hypot(pb[:, 0] - pa[:, 0], pb[:, 1] - pa[:, 1]) > min_step)
    new = np.column_stack([samples[bad, _MID, 0], samples[bad, _MID, 1], zs[bad, _MID]])
    down = pa[:, 2] > pb[:, 2]
    corner = np.where(down[:, None], np.column_stack([pb[:, :2], pa[:, 2]]),
                      np.column_stack([pa[:, :2], pb[:, 2]]))
    new[cliff] = corner[cliff]
    return bad, new, air_s[bad, _MID] & ~cliff, cliff, worst[bad]


def _insert(pts: list[np.ndarray], airs: list[np.ndarray], rs: np.ndarray, is_: np.ndarray, new: np.ndarray,
            new_air: np.ndarray, following: list[np.ndarray]) -> None:
    """Inserts new[k] after point is_[k] of run rs[k] (the moves in order), one insert per run, and sets the
    run's moves to check next: both halves of each move split at a new point (a cliff's corner, in line with
    an end, is not checked again)."""
    bounds = np.flatnonzero(np.diff(rs)) + 1
    for lo, hi in zip(np.concatenate([[0], bounds]), np.concatenate([bounds, [len(rs)]])):
        r = int(rs[lo])
        pts[r] = np.insert(pts[r], is_[lo:hi] + 1, new[lo:hi], axis=0)
        airs[r] = np.insert(airs[r], is_[lo:hi] + 1, new_air[lo:hi])
        at = is_[lo:hi] + 1 + np.arange(hi - lo)  # earlier insertions in the run shift each by their count
        p = pts[r]
        after = np.vstack([p[1:], pts[r + 1][:1]]) if r + 1 < len(pts) else p[1:]
        split = (p[at, :2] != after[at, :2]).any(axis=1) & (p[at, :2] != p[at - 1, :2]).any(axis=1)
        following[r] = np.column_stack([at[split] - 1, at[split]]).ravel()
