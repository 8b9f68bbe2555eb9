"""The order a rest's pieces (passes, waterline loops, touch-ups: core.strategies.rest_steep) are cut in: from each
piece's end to the nearest next (a rise counted UPHILL + 1 times its height, a descent once: level by level over
a large group of loops the tool would cross the group at every level), a piece that may be cut either way entered
at its nearer end; then improved by 2-opt, a run of such pieces cut backwards in reverse order where that shortens
the moves between them (a greedy order leaves long moves back across what it skipped). A chain of pieces joined
to one another (reached with the tool down) stays together. Waterline loops keep their sense (climb or
conventional); a raster's zig-zag passes and the touch-ups have none."""
from __future__ import annotations

from dataclasses import replace
from typing import Optional

import numpy as np

from tmm_workbench.core.segments import CutSegment

UPHILL = 3.0       # a move up counts this many times its height more than a move down in choosing the next piece
SWEEPS = 5         # 2-opt rounds over the whole order at most (each makes the best reversal from every position;
#                    on 3,000 random pieces 3 rounds took 8 % off the greedy order, 10 rounds 10 %)
WINDOW = 100       # reversals of runs up to this many chains (a greedy order's detours are local; all pairs of
#                    3,000 pieces took 26 s)
GAIN_MM = 1e-6     # a reversal is made when it shortens the moves by more than this


def cost(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cost of moving from points `a` to points `b` ((..., 3) each, broadcast)."""
    d = b - a
    return np.hypot(d[..., 0], d[..., 1]) + UPHILL * np.maximum(d[..., 2], 0.0) + np.abs(d[..., 2])


def chains_of(segments: list[CutSegment]) -> list[list[CutSegment]]:
    """The segments in runs, each piece joined to the one before it kept after it."""
    chains: list[list[CutSegment]] = []
    for seg in segments:
        if seg.joined and chains:
            chains[-1].append(seg)
        else:
            chains.append([seg])
    return chains


def reversible(seg: CutSegment) -> bool:
    """Whether the segment can be cut backwards as it is: 3-axis, lines only, no entry of its own."""
    return (seg.axes is None and seg.arcs is None and seg.entry is None and seg.entry_z is None
            and seg.helix_centre is None)


def ordered(segments: list[CutSegment], either_way: Optional[set] = None) -> list[CutSegment]:
    """The pieces in the order described by the module; `either_way`: the ids of the segments that may be cut
    backwards (a chain is turned only when all of its segments may). The segments themselves are kept, a turned
    chain's as new ones."""
    chains = chains_of(segments)
    ids = either_way or set()
    turnable = np.array([all(id(s) in ids and reversible(s) for s in c) for c in chains], dtype=bool)
    if len(chains) < 3 and not (len(chains) == 2 and turnable.any()):
        return segments
    starts = np.array([c[0].tips[0] for c in chains])
    ends = np.array([c[-1].tips[-1] for c in chains])
    order, turned = _nearest_first(starts, ends, turnable)
    order, turned = _two_opt(order, turned, starts, ends, turnable)
    out: list[CutSegment] = []
    for k, back in zip(order, turned):
        out += turned_chain(chains[k]) if back else chains[k]
    return out


def turned_chain(chain: list[CutSegment]) -> list[CutSegment]:
    """The chain cut backwards: its segments in reverse order, each reversed, the first entered, the others
    joined."""
    return [replace(seg, tips=seg.tips[::-1].copy(), joined=k > 0) for k, seg in enumerate(reversed(chain))]


def _nearest_first(starts: np.ndarray, ends: np.ndarray, turnable: np.ndarray) -> tuple[list[int], list[bool]]:
    """From the first chain (as it runs), each next the nearest by `cost` to where the tool is: at its start, or
    at its end (then cut backwards) when it may turn."""
    n = len(starts)
    left = np.ones(n, dtype=bool)
    left[0] = False
    order, turned, at = [0], [False], ends[0]
    while left.any():
        fwd = cost(at, starts)
        back = np.where(turnable, cost(at, ends), np.inf)
        fwd[~left] = np.inf
        back[~left] = np.inf
        k, kb = int(np.argmin(fwd)), int(np.argmin(back))
        flip = back[kb] < fwd[k]
        k = kb if flip else k
        left[k] = False
        order.append(k)
        turned.append(bool(flip))
        at = starts[k] if flip else ends[k]
    return order, turned


def _two_opt(order: list[int], turned: list[bool], starts: np.ndarray, ends: np.ndarray,
             turnable: np.ndarray) -> tuple[list[int], list[bool]]:
    """2-opt on the order: a run of turnable chains [i, j] (at most WINDOW long) cut in reverse order, each
    backwards, where that lowers the sum of `cost` over the moves between the chains (the first chain's start is
    free: the op begins there). Each sweep makes, from every position i, the best such reversal."""
    order, turned = list(order), list(turned)
    n = len(order)
    s, e, ok = _oriented(order, turned, starts, ends, turnable)
    for _ in range(SWEEPS):
        better = False
        fixed = np.append(np.flatnonzero(~ok), n)   # the run [i, j] holds turnable chains only
        for i in range(n - 1):
            stop = min(int(fixed[np.searchsorted(fixed, i)]), i + WINDOW)
            if stop - i < 2:
                continue
            b = _best_reversal(s, e, i, stop, n)
            if b is None:
                continue
            order[i:b + 1] = order[i:b + 1][::-1]
            turned[i:b + 1] = [not t for t in turned[i:b + 1][::-1]]
            s[i:b + 1], e[i:b + 1] = e[i:b + 1][::-1].copy(), s[i:b + 1][::-1].copy()
            better = True
        if not better:
            break
    return order, turned


def _best_reversal(s: np.ndarray, e: np.ndarray, i: int, stop: int, n: int) -> Optional[int]:
    """The j in (i, stop) whose reversal of [i, j] lowers the moves' cost most, None when none does."""
    f = cost(e[i:stop - 1], s[i + 1:stop])                      # the moves inside the run as they are
    inside = np.concatenate([[0.0], np.cumsum(cost(s[i + 1:stop], e[i:stop - 1]) - f)])[1:]   # turned
    j = np.arange(i + 1, stop)
    delta = inside.copy()
    if i > 0:
        delta += cost(e[i - 1], e[j]) - cost(e[i - 1], s[i])
    inner = j < n - 1
    jj = j[inner]
    delta[inner] += cost(s[i], s[jj + 1]) - cost(e[jj], s[jj + 1])
    best = int(np.argmin(delta))
    return int(j[best]) if delta[best] < -GAIN_MM else None


def _oriented(order: list[int], turned: list[bool], starts: np.ndarray, ends: np.ndarray,
              turnable: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per position: where its chain is entered, where it is left, whether it may turn."""
    idx = np.array(order)
    back = np.array(turned)
    s = np.where(back[:, None], ends[idx], starts[idx])
    e = np.where(back[:, None], starts[idx], ends[idx])
    return s, e, turnable[idx]
