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


def refine(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray, drop: Drop, tol: float,
           chained: bool, rounds: int = 12, min_step: float = 1e-3, leave_tol: float = math.inf
           ) -> tuple[list[tuple[bool, np.ndarray]], np.ndarray, np.ndarray, dict]:
    """The runs (is_link, xy) with points inserted, their heights and air flags (flattened as the input).
    chained: consecutive runs are cut one after the other with the tool down (zig-zag: a pass, its link,
    the next pass), so the move from a run's last point to the next run's first is checked too (points
    found there are added to the end of the first run). leave_tol: a move passing more than this above the exact
    drop height is split too (the cusp modes: in a concave valley or corner a move across the crease of the CL
    surface leaves material above the cusp their spacing was computed for, which places it on the CL points)."""
    pts: list[np.ndarray] = []   # per run: (k, 3) points
    airs: list[np.ndarray] = []
    k = 0
    for _, xy in runs:
        pts.append(np.column_stack([xy, z[k:k + len(xy)]]))
        airs.append(air[k:k + len(xy)].copy())
        k += len(xy)

    def nxt(r: int, i: int) -> tuple[np.ndarray, bool]:
        """The point after point i of run r (in the next run when i is the last), and its air flag."""
        if i + 1 < len(pts[r]):
            return pts[r][i + 1], bool(airs[r][i + 1])
        return pts[r + 1][0], bool(airs[r + 1][0])

    last = len(pts) - 1
    todo = [(r, i) for r in range(len(pts))
            for i in range(len(pts[r]) - (0 if chained and r < last and len(pts[r + 1]) else 1))]
    inserted, cliffs, deepest = 0, 0, 0.0
    for _ in range(rounds):
        cancel.poll()
        todo = [(r, i) for r, i in todo if not (airs[r][i] or nxt(r, i)[1])]
        if not todo:
            break
        cancel.poll()
        a = np.array([pts[r][i] for r, i in todo])
        cancel.poll()
        b = np.array([nxt(r, i)[0] for r, i in todo])
        cancel.poll()
        samples = a[:, None, :] + _FRACTIONS[None, :, None] * (b - a)[:, None, :]   # (m, 5, 3)
        zs, air_s = drop(samples[:, :, :2].reshape(-1, 2))
        zs, air_s = zs.reshape(len(todo), -1), air_s.reshape(len(todo), -1)
        cut = zs - samples[:, :, 2]
        cut[air_s] = -np.inf
        worst = cut.max(axis=1)
        left = np.where(air_s, -np.inf, -cut).max(axis=1)
        # a jump of the drop height (an edge the tool falls off or climbs onto) can hide between the samples:
        # a steep move whose middle is far from its chord, above or below, is split until the jump is found
        steep = np.abs(b[:, 2] - a[:, 2]) > 10 * tol
        jump = steep & (np.abs(cut[:, _MID]) > tol) & np.isfinite(cut[:, _MID])
        bad = np.flatnonzero((worst > tol) | jump | (left > leave_tol))
        if not len(bad):
            todo = []
            break
        deepest = float(max(worst[bad].max(), 0.0))
        additions: dict[int, list[tuple[int, np.ndarray, bool]]] = {}
        for n in bad:
            r, i = todo[n]
            pa, pb = a[n], b[n]
            if np.hypot(*(pb[:2] - pa[:2])) > min_step:  # the halfway point, dropped with the samples
                half = np.array([samples[n, _MID, 0], samples[n, _MID, 1], zs[n, _MID]])
                additions.setdefault(r, []).append((i, half, bool(air_s[n, _MID])))
            else:  # a cliff: across at the upper height, then straight down (or up, then across)
                corner = np.array([pb[0], pb[1], pa[2]]) if pa[2] > pb[2] else np.array([pa[0], pa[1], pb[2]])
                additions.setdefault(r, []).append((i, corner, False))
                cliffs += 1
        todo = []
        for r, adds in additions.items():
            cancel.poll()
            adds.sort(key=lambda t: t[0])
            for rank, (i, p, is_air) in enumerate(adds):
                at = i + 1 + rank  # earlier insertions of this round shift it by their count
                pts[r] = np.insert(pts[r], at, p, axis=0)
                airs[r] = np.insert(airs[r], at, is_air)
                inserted += 1
                after = nxt(r, at)[0]
                if not np.array_equal(p[:2], after[:2]) and not np.array_equal(p[:2], pts[r][at - 1][:2]):
                    todo += [(r, at - 1), (r, at)]  # a midpoint: both new moves checked next round
    else:
        todo = [(r, i) for r, i in todo if not (airs[r][i] or nxt(r, i)[1])]
    remaining = len(todo)
    out_runs = [(is_link, p[:, :2]) for (is_link, _), p in zip(runs, pts)]
    z_out = np.concatenate([p[:, 2] for p in pts]) if pts else z
    air_out = np.concatenate(airs) if airs else air
    return out_runs, z_out, air_out, {"inserted": inserted, "cliffs": cliffs, "unchecked_after_rounds": remaining,
                                      "deepest_refined": deepest}
