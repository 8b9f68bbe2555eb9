"""No gouge between multipoint positions (issue 11 item 3): the tool moving from one position to the next
(the tip on its straight line, the axis by slerp, as a control with tool-centre-point mode moves it) is
checked against the face, densely sampled (core.verify.swept); where it cuts deeper than
`MultipointParams.between_tol`, the footprint point halfway is positioned and inserted, and the two new
moves are checked in turn, at most `between_rounds` times. What still cuts in after that is reported in
the diagnostics (never silently left).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from tmm_workbench.core.strategies.multipoint import STATUS_FAILED
from tmm_workbench.core.verify import swept


def refine(surface: Any, positioner: Any, Ro: float, Ri: float, params: Any, runs: list[list[int]], res: Any,
           position: Any) -> dict:
    """Inserts positions into `runs` (lists of row indices of `res`, a MultipointResults extended in place)
    until no move between consecutive positions cuts deeper than params.between_tol. `position(xy)` gives
    MultipointResults for new footprint points. Returns {"checked", "inserted", "remaining", "deepest"}."""
    # Screened on samples 0.5 mm apart, confirmed on samples 0.25 mm apart: between samples s apart a torus
    # of minor radius Ri dips at most (s/2)^2 / (2 Ri) (0.005 and 0.0013 mm for Ri = 6), so a move that cuts
    # deeper than the tolerance shows more than half of it on the coarse samples.
    coarse = swept.FaceSamples.of(surface, 0.5)
    fine = swept.FaceSamples.of(surface, 0.25)
    reach = Ro + 2.0 * Ri + 1.0  # the tool's XY extent from its tip at any tilt, with a margin

    def depth(i: int, j: int) -> float:
        ends = (res["tip"][i], res["axis"][i], res["tip"][j], res["axis"][j])
        if swept.between(positioner, coarse, reach, *ends, checks=8) <= params.between_tol / 2:
            return 0.0
        return swept.between(positioner, fine, reach, *ends, checks=12)

    todo = [(r, k) for r, run in enumerate(runs) for k in range(len(run) - 1)]
    checked = len(todo)
    inserted = 0
    deepest: dict[tuple[int, int], float] = {}
    for _ in range(params.between_rounds):
        bad = []
        for r, k in todo:
            i, j = runs[r][k], runs[r][k + 1]
            d = depth(i, j)
            if d > params.between_tol:
                bad.append((r, k, i, j))
                deepest[(i, j)] = d
        if not bad:
            break
        mid = np.array([(res.xy[i] + res.xy[j]) / 2 for _, _, i, j in bad])
        new = position(mid)
        base = len(res.xy)
        res.xy = np.vstack([res.xy, new.xy])
        res.passes = np.concatenate([res.passes, [res.passes[i] for _, _, i, _ in bad]])
        for key, arr in res.data.items():
            res.data[key] = np.concatenate([arr, new.data[key]])
        todo = []
        # insert from the back of each run so the earlier indices stay valid
        for n, (r, k, i, j) in sorted(enumerate(bad), key=lambda t: (t[1][0], -t[1][1])):
            row = base + n
            if res.data["status"][row] == STATUS_FAILED:
                continue  # no position there: the move stays as it was, and is reported below
            runs[r].insert(k + 1, row)
            inserted += 1
            deepest.pop((i, j), None)
        # the moves around every insertion are checked in the next round
        for r, run in enumerate(runs):
            for k in range(len(run) - 1):
                if run[k] >= base or run[k + 1] >= base:
                    todo.append((r, k))
    moves = {(a, b) for run in runs for a, b in zip(run, run[1:])}
    remaining = [d for pair, d in deepest.items() if pair in moves]
    return {"checked": checked, "inserted": inserted, "remaining": len(remaining),
            "deepest": max(remaining, default=0.0)}
