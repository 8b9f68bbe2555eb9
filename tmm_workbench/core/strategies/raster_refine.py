"""No gouge between 3-axis CL points (issue 11 item 3, the 3-axis side): the straight move between two
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
_BLOCK = 100_000  # moves checked per drop: a block's arrays take a fraction of a second, cancel is asked between


def refine(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray, drop: Drop, tol: float,
           chained: bool, rounds: int = 12, min_step: float = 1e-3, leave_tol: float = math.inf
           ) -> tuple[list[tuple[bool, np.ndarray]], np.ndarray, np.ndarray, dict]:
    """The runs (is_link, xy) with points inserted, their heights and air flags (flattened as the input).
    chained: consecutive runs are cut one after the other with the tool down (zig-zag: a pass, its link,
    the next pass), so the move from a run's last point to the next run's first is checked too (points
    found there are added to the end of the first run). leave_tol: a move passing more than this above the exact
    drop height is split too (the cusp modes: in a concave valley or corner a move across the crease of the CL
    surface leaves material above the cusp their spacing was computed for, which places it on the CL points).

    A move is named by its run r and its first point i; with the runs laid end to end (`_cut_moves`) its
    points are the flat indices start[r] + i and the one after (in the next run when i is the last): array
    work only, so that a fine step-over's millions of moves do not hold a cancel (core.cancel) for a second."""
    pts: list[np.ndarray] = []   # per run: (k, 3) points
    airs: list[np.ndarray] = []
    k = 0
    for _, xy in runs:
        pts.append(np.column_stack([xy, z[k:k + len(xy)]]))
        airs.append(air[k:k + len(xy)].copy())
        k += len(xy)
    todo_r, todo_i = _all_moves([len(p) for p in pts], chained)
    inserted, cliffs, deepest = 0, 0, 0.0
    for _ in range(rounds):
        cancel.poll()
        todo_r, todo_i, g, flat = _cut_moves(pts, airs, todo_r, todo_i)
        if not len(g):
            break
        bad, new, new_air, cliff, worst = _check(flat, g, drop, tol, leave_tol, min_step)
        if not len(bad):
            todo_r = todo_i = np.zeros(0, dtype=np.int64)
            break
        deepest = float(max(worst.max(), 0.0))
        cliffs += int(cliff.sum())
        inserted += len(bad)
        todo_r, todo_i = _insert(pts, airs, todo_r[bad], todo_i[bad], new, new_air)
    else:
        todo_r, todo_i, _, _ = _cut_moves(pts, airs, todo_r, todo_i)
    remaining = len(todo_r)
    out_runs = [(is_link, p[:, :2]) for (is_link, _), p in zip(runs, pts)]
    z_out = np.concatenate([p[:, 2] for p in pts]) if pts else z
    air_out = np.concatenate(airs) if airs else air
    return out_runs, z_out, air_out, {"inserted": inserted, "cliffs": cliffs, "unchecked_after_rounds": remaining,
                                      "deepest_refined": deepest}


def _check(flat: np.ndarray, g: np.ndarray, drop: Drop, tol: float, leave_tol: float, min_step: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The moves g (flat indices of their first points) to split, checked in blocks: their positions in g, the
    points to insert, whether each is in the air, which are cliffs, and how far each cuts in."""
    starts = range(0, len(g), _BLOCK)
    blocks = [_check_block(flat, g[lo:lo + _BLOCK], drop, tol, leave_tol, min_step) for lo in starts]
    bad = np.concatenate([lo + block[0] for lo, block in zip(starts, blocks)])
    return (bad, *(np.concatenate([block[k] for block in blocks]) for k in range(1, 5)))


def _check_block(flat: np.ndarray, g: np.ndarray, drop: Drop, tol: float, leave_tol: float, min_step: float
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """_check for one block of moves."""
    cancel.poll()
    a, b = flat[g], flat[g + 1]
    samples = a[:, None, :] + _FRACTIONS[None, :, None] * (b - a)[:, None, :]   # (m, 5, 3)
    zs, air_s = drop(samples[:, :, :2].reshape(-1, 2))
    zs, air_s = zs.reshape(len(g), -1), air_s.reshape(len(g), -1)
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


def _all_moves(lengths: list[int], chained: bool) -> tuple[np.ndarray, np.ndarray]:
    """Every move (r, i) of the runs, in order: within a run, and with `chained` from a run's last point to
    the next run's first when that run has points."""
    n = np.asarray(lengths, dtype=np.int64)
    following = np.append(n[1:], 0)
    count = np.maximum(n - 1 + (chained & (following > 0)), 0)
    r = np.repeat(np.arange(len(n)), count)
    return r, np.arange(len(r)) - np.repeat(np.cumsum(count) - count, count)


def _cut_moves(pts: list[np.ndarray], airs: list[np.ndarray], todo_r: np.ndarray, todo_i: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The moves (r, i) of todo that cut (neither end in the air), their first points' flat indices and the
    runs' points laid end to end."""
    if not len(todo_r):
        return todo_r, todo_i, todo_r, np.zeros((0, 3))
    flat, flat_air = np.concatenate(pts), np.concatenate(airs)
    start = np.cumsum([0] + [len(p) for p in pts[:-1]])
    g = start[todo_r] + todo_i
    cuts = ~(flat_air[g] | flat_air[g + 1])
    return todo_r[cuts], todo_i[cuts], g[cuts], flat


def _insert(pts: list[np.ndarray], airs: list[np.ndarray], rs: np.ndarray, is_: np.ndarray, new: np.ndarray,
            new_air: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inserts new[k] after point is_[k] of run rs[k] (the moves in order), one insert per run; returns the
    moves to check next: both halves of each move split at a new point (a cliff's corner, in line with an
    end, is not checked again)."""
    todo_r: list[np.ndarray] = []
    todo_i: list[np.ndarray] = []
    bounds = np.flatnonzero(np.diff(rs)) + 1
    for lo, hi in zip(np.concatenate([[0], bounds]), np.concatenate([bounds, [len(rs)]])):
        cancel.poll()
        r = int(rs[lo])
        pts[r] = np.insert(pts[r], is_[lo:hi] + 1, new[lo:hi], axis=0)
        airs[r] = np.insert(airs[r], is_[lo:hi] + 1, new_air[lo:hi])
        at = is_[lo:hi] + 1 + np.arange(hi - lo)  # earlier insertions in the run shift each by their count
        p = pts[r]
        after = np.vstack([p[1:], pts[r + 1][:1]]) if r + 1 < len(pts) else p[1:]
        split = (p[at, :2] != after[at, :2]).any(axis=1) & (p[at, :2] != p[at - 1, :2]).any(axis=1)
        at = at[split]
        todo_r.append(np.full(2 * len(at), r))
        todo_i.append(np.column_stack([at - 1, at]).ravel())
    return np.concatenate(todo_r), np.concatenate(todo_i)
