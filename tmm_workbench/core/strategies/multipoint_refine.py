"""No gouge and no chord error between multipoint positions: the tool moving from one
position to the next (the tip on its straight line, the axis by slerp, as a control with tool-centre-point
mode moves it) is checked against the real face at instances at most 0.25 mm apart by the kernel's signed
clearance (the smallest signed distance from the face to the tool solid, exact by Newton: negative a gouge,
positive a gap). Where the move cuts deeper than `MultipointParams.between_tol`, or stands further off the
face than the positions at its ends do by more than it (the chord error: material left, on concave
stretches), the footprint point halfway is positioned and inserted, and the two new moves are checked in
turn, at most `between_rounds` times. What remains after that is reported in the diagnostics (never
silently left).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.strategies.multipoint_status import STATUS_FAILED

CHECK_SPACING_MM = 0.25  # between checked instances of a move: a torus of minor radius Ri dips at most
#                          (0.125)^2 / (2 Ri) between them (0.0013 mm for Ri = 6)
MAX_CHECKS = 256


def move_deviation(positioner: Any, tip0: np.ndarray, axis0: np.ndarray, tip1: np.ndarray, axis1: np.ndarray,
                   end_clearance: tuple[float, float], threads: int = 0) -> tuple[float, float]:
    """(gouge, gap) of one move: how deep (>= 0) the tool cuts into the face strictly between its ends, and
    how much further (>= 0) it stands off the face than the ends' clearances, interpolated, say it should."""
    length = float(np.linalg.norm(np.asarray(tip1) - np.asarray(tip0)))
    n = int(min(MAX_CHECKS, max(4, math.ceil(length / CHECK_SPACING_MM))))
    s = np.arange(1, n) / n
    tips = np.asarray(tip0, float)[None, :] * (1 - s[:, None]) + np.asarray(tip1, float)[None, :] * s[:, None]
    c = positioner.clearance(tips, slerp(axis0, axis1, s), threads)
    gouge = max(0.0, -float(c.min()))
    c0, c1 = end_clearance
    expected = c0 * (1 - s) + c1 * s
    on_face = np.isfinite(c) & np.isfinite(expected)  # off the face (no sample under the tool) leaves nothing
    gap = max(0.0, float((c[on_face] - expected[on_face]).max())) if on_face.any() else 0.0
    return gouge, gap


def refine(positioner: Any, params: Any, runs: list[list[int]], res: Any, position: Any) -> dict:
    """Inserts positions into `runs` (lists of row indices of `res`, a MultipointResults extended in place)
    until no move between consecutive positions cuts deeper, or leaves more, than params.between_tol.
    `position(xy)` gives MultipointResults for new footprint points. Returns {"checked", "inserted",
    "remaining", "deepest", "widest_gap"} (the last three for the moves still out of tolerance)."""
    tol, threads = params.between_tol, int(params.threads)
    clearance = list(positioner.clearance(res["tip"], res["axis"], threads))  # of each position, by row

    def deviation(i: int, j: int) -> tuple[float, float]:
        return move_deviation(positioner, res["tip"][i], res["axis"][i], res["tip"][j], res["axis"][j],
                              (clearance[i], clearance[j]), threads)

    todo = [(r, k) for r, run in enumerate(runs) for k in range(len(run) - 1)]
    checked = len(todo)
    inserted = 0
    out_of_tol: dict[tuple[int, int], tuple[float, float]] = {}
    for round_ in range(params.between_rounds + 1):
        bad = []
        for r, k in todo:
            i, j = runs[r][k], runs[r][k + 1]
            gouge, gap = deviation(i, j)
            if gouge > tol or gap > tol:
                bad.append((r, k, i, j))
                out_of_tol[(i, j)] = (gouge, gap)
        if not bad or round_ == params.between_rounds:  # the moves the last insertions made are checked too
            break
        mid = np.array([(res.xy[i] + res.xy[j]) / 2 for _, _, i, j in bad])
        new = position(mid)
        base = len(res.xy)
        res.xy = np.vstack([res.xy, new.xy])
        res.passes = np.concatenate([res.passes, [res.passes[i] for _, _, i, _ in bad]])
        for key, arr in res.data.items():
            res.data[key] = np.concatenate([arr, new.data[key]])
        clearance.extend(positioner.clearance(new["tip"], new["axis"], threads))
        todo = []
        # insert from the back of each run so the earlier indices stay valid
        for n, (r, k, i, j) in sorted(enumerate(bad), key=lambda t: (t[1][0], -t[1][1])):
            row = base + n
            if res.data["status"][row] == STATUS_FAILED:
                continue  # no position there: the move stays as it was, and is reported below
            runs[r].insert(k + 1, row)
            inserted += 1
            out_of_tol.pop((i, j), None)
        # the moves around every insertion are checked in the next round
        for r, run in enumerate(runs):
            for k in range(len(run) - 1):
                if run[k] >= base or run[k + 1] >= base:
                    todo.append((r, k))
    moves = {(a, b) for run in runs for a, b in zip(run, run[1:])}
    remaining = [d for pair, d in out_of_tol.items() if pair in moves]
    return {"checked": checked, "inserted": inserted, "remaining": len(remaining),
            "deepest": max((g for g, _ in remaining), default=0.0),
            "widest_gap": max((w for _, w in remaining), default=0.0)}
