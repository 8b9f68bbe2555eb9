"""The adaptive step-over's step control (stepover.adaptive_passes, its _Planes and _give_up_lagging) replayed on
widths known beforehand, for the estimates that tell the passes without planning them (mesh5.estimate, the op's
work; core.plan.mesh5_estimate, the planner's cycle time). One replay, the step-over's named constants imported
(they change with it); a change of its rule's steps must be made here too, which
tests/core/test_mesh5_step_replay.py tells (the step-over's own offsets replayed from what its passes finished).

What it replays, per bin of the feed coordinate (the step-over's Coverage keeps one level per forward step; here
a bin is the width field's column): the first plane 0.125 D inside the model; each next one a gap beyond the
least finished level of the open bins it runs through, no higher than the top of any open bin; the pass finishes
each bin it runs through forward to its left half-width where its right one reaches back to the bin's level
(a bin still at the model's own edge: always), and the next gap is half the GAP_QUANTILE of the widths (left +
right) it finished; a pass where some CC point cannot reach back to its bin's level (right), or has no room for
a quarter of the left step asked (AHEAD_SHARE of the gap), is rebuilt SHRINK nearer; a plane coming back to
less than REPEAT x the gap beyond the last, held by at most LAGGING bins' worth of lagging bins, leaves them
behind. Not replayed: the peeling of CC points at a path's ends (a few per pass, on the model's slanted edges)
and the machine's tilt (the widths' own business).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.strategies.mesh5.stepover import (AHEAD_SHARE, BACK_MORE, BACK_SHARE, EDGE, FIRST_AHEAD,
                                                          FIRST_GAP, GAP_QUANTILE, LAGGING, LEAST_GAP, MAX_TRIES,
                                                          MOST_GAP, REPEAT, SHRINK, SKIP, WIDE_QUANTILE,
                                                          settled)

Reach = Callable[[float], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class WidthField:
    """Half-widths one pass finishes (mm along the plane normal m), left (+m) and right (-m), on rows at
    m = m0 + k dm (k = 0..nm-1) and columns the bins along the feed: (nm, nb) each, NaN off the model.
    The model in a bin spans from its first row with a width less dm / 2 to its last plus dm / 2."""
    m0: float
    dm: float
    left: np.ndarray
    right: np.ndarray

    @classmethod
    def symmetric(cls, m0: float, dm: float, half: np.ndarray) -> "WidthField":
        half = np.asarray(half, dtype=float)
        return cls(float(m0), float(dm), half, half)

    @classmethod
    def binned(cls, m: np.ndarray, f: np.ndarray, half: np.ndarray, dm: float, df: float) -> "WidthField":
        """Both sides alike from points at m (along the normal) and f (along the feed) with half-widths `half`
        (NaN: none known there, e.g. no posture): the least in each cell dm x df (rows from the least m, a cell
        per point's nearest), a cell with none known the nearest known across in its column."""
        m, f, half = (np.asarray(v, dtype=float).ravel() for v in (m, f, half))
        m0 = float(m.min())
        rows = np.rint((m - m0) / dm).astype(np.int64)
        cols = np.rint((f - float(f.min())) / df).astype(np.int64)
        out = np.full((int(rows.max()) + 1, int(cols.max()) + 1), np.inf)
        np.minimum.at(out, (rows, cols), np.where(np.isnan(half), np.inf, half))
        seen = np.zeros(out.shape, dtype=bool)
        seen[rows, cols] = True
        for c in range(out.shape[1]):
            known = np.flatnonzero(seen[:, c] & np.isfinite(out[:, c]))
            fill = np.flatnonzero(seen[:, c] & ~np.isfinite(out[:, c]))
            if known.size and fill.size:
                out[fill, c] = out[known[np.abs(known[None, :] - fill[:, None]).argmin(axis=1)], c]
        return cls.symmetric(m0, dm, np.where(seen & np.isfinite(out), out, np.nan))

    def extent(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) (nb,) the model along m in each bin (NaN for a bin with no width)."""
        on = ~np.isnan(self.left) & ~np.isnan(self.right)
        rows = np.arange(len(on))[:, None]
        first = np.where(on, rows, len(on)).min(axis=0)
        last = np.where(on, rows, -1).max(axis=0)
        seen = last >= 0
        lo = np.where(seen, self.m0 + (first - 0.5) * self.dm, np.nan)
        hi = np.where(seen, self.m0 + (last + 0.5) * self.dm, np.nan)
        return lo, hi

    def __call__(self, offset: float) -> tuple[np.ndarray, np.ndarray]:
        """(left, right) (nb,) at the plane `offset`: linear between the two nearest rows (the one with a width
        where the other has none), NaN where the plane misses the bin's model."""
        u = (offset - self.m0) / self.dm
        n = len(self.left)
        k = int(np.clip(math.floor(u), 0, n - 1))
        k1 = min(k + 1, n - 1)
        t = float(np.clip(u - k, 0.0, 1.0))
        lo, hi = self.extent()
        inside = (offset >= lo - 1e-9) & (offset <= hi + 1e-9)
        out = []
        for w in (self.left, self.right):
            a, b = w[k], w[k1]
            v = np.where(np.isnan(a), b, np.where(np.isnan(b), a, (1 - t) * a + t * b))
            out.append(np.where(inside, v, np.nan))
        return out[0], out[1]


def replay_planes(reach: Reach, lo: np.ndarray, hi: np.ndarray, radius: float, bin_width: float,
                  forward_step: float, widest: bool = True, max_planes: int = 10_000) -> np.ndarray:
    """The drive planes' offsets (along m) the step-over places over the model spanning lo..hi (nb,) along m
    in each bin of the feed (`bin_width` mm; NaN: no model there), where `reach(offset)` tells the half-widths
    (left +m, right -m; (nb,) each, NaN where the plane misses the bin, inf: to the model's edge) a pass at
    `offset` finishes (module doc). `forward_step`: the op's (its bins' width, in which LAGGING counts).
    `widest`: reach tells the widest each place allows, of which a pass finishes no more than its WIDE_QUANTILE
    place's (stepover.widest_cspace keeps the postures reaching that far, or a place's own widest where less,
    and chooses among them for the motion time); False: what the pass finishes itself."""
    if not (radius > 0 and bin_width > 0 and forward_step > 0):
        raise ValueError(f"radius, bin_width and forward_step must be > 0 mm, got {radius}, {bin_width}, "
                         f"{forward_step}")
    on = np.isfinite(lo) & np.isfinite(hi)
    if not on.any():
        return np.zeros(0)
    lo_b, hi_b = np.asarray(lo, dtype=float)[on], np.asarray(hi, dtype=float)[on]
    state = _Replay(reach, on, lo_b, hi_b, radius, max(1, round(LAGGING * forward_step / bin_width)), widest)
    return state.run(max_planes)


class _Replay:
    """The replay's finished levels per bin and its loop (adaptive_passes' own, on known widths)."""

    def __init__(self, reach: Reach, on: np.ndarray, lo: np.ndarray, hi: np.ndarray, radius: float,
                 lagging: int, widest: bool):
        self.reach, self.on, self.lo, self.hi, self.radius, self.lagging = reach, on, lo, hi, radius, lagging
        self.widest = widest
        self.level = lo.copy()
        self.edge = EDGE * radius

    @property
    def open(self) -> np.ndarray:
        return self.level < self.hi - self.edge

    def widths(self, offset: float) -> tuple[np.ndarray, np.ndarray]:
        left, right = self.reach(offset)
        return np.asarray(left, dtype=float)[self.on], np.asarray(right, dtype=float)[self.on]

    def place(self, guess: float, gap: float) -> tuple[float, float, np.ndarray]:
        """(offset, the least level it starts from, the open bins it runs through): _Planes.place."""
        opened = self.open
        top = float(self.hi[opened].min()) - self.edge
        offset, span, base = min(guess, top), opened, float(self.level[opened].min())
        for _ in range(4):
            span = ~np.isnan(self.widths(offset)[0]) & opened
            base = float(self.level[span].min()) if span.any() else float(self.level[opened].min())
            nxt = min(base + gap, top)
            if settled(nxt, offset, gap) and span.any():
                break
            offset = nxt
        return offset, base, span

    def give_up_lagging(self, span: np.ndarray, base: float, gap: float) -> bool:
        """stepover._give_up_lagging: the few bins within half a gap of the least level left behind."""
        lag = span & (self.level < base + 0.5 * gap)
        rest = span & ~lag
        if not lag.any() or lag.sum() > self.lagging or not rest.any():
            return False
        self.level = np.where(lag, np.maximum(self.level, float(self.level[rest].min())), self.level)
        return True

    def advanced(self, offset: float, ahead: float) -> Optional[tuple[np.ndarray, np.ndarray]]:
        """(the levels after a pass at `offset`, the widths it finished (n,)), None where some CC point of it has
        no posture: its right side short of its bin's level, or its left one of a quarter of the step asked."""
        left, right = self.widths(offset)
        run = ~np.isnan(left) & ~np.isnan(right)
        fresh = self.level <= self.lo + 1e-9                       # the model's own edge: covered to it
        need = np.where(fresh, -np.inf, BACK_SHARE * (offset - self.level) + BACK_MORE)
        if not run.any() or (run & ((right < need) | (left < 0.25 * ahead))).any():
            return None
        if self.widest:                                            # the pass as wide as nearly all its places
            fin = left[run & np.isfinite(left)]
            target = float(np.quantile(fin, WIDE_QUANTILE)) if fin.size else np.inf
            left = np.where(np.isinf(left), left, np.minimum(left, target))   # to the edge: those kept
            right = np.maximum(np.minimum(right, target), need)
        reached = np.where(offset + left >= self.hi - self.edge, np.inf, offset + left)
        level = np.where(run & self.open, np.maximum(self.level, reached), self.level)
        total = np.minimum(left, self.hi.max() - offset) + np.minimum(right, offset - self.lo.min())
        return level, total[run]

    def run(self, max_planes: int) -> np.ndarray:
        r = self.radius
        gap, ahead = FIRST_GAP * r, FIRST_AHEAD * r
        guess, offsets = float(self.lo.min()) + gap, []
        while self.open.any() and len(offsets) < max_planes:
            for _ in range(MAX_TRIES):
                offset, base, span = self.place(guess, gap)
                if offsets and offset < offsets[-1] + REPEAT * gap and self.give_up_lagging(span, base, gap):
                    offset, base, span = self.place(guess, gap)
                got = self.advanced(offset, ahead)
                if got is not None and (got[0] > self.level + 1e-9)[self.open].any():
                    break
                gap *= SHRINK
                ahead = min(ahead, gap)
                guess = base + gap
            else:
                stuck = self.open & (self.level <= base + 1e-9)    # no pass advances them: a strip skipped
                self.level[stuck] = base + SKIP * r
                gap, guess = SKIP * r, base + 2 * SKIP * r
                continue
            offsets.append(offset)
            self.level, total = got
            gap = float(np.clip(0.5 * np.quantile(total, GAP_QUANTILE), LEAST_GAP * r, MOST_GAP * r))
            ahead, guess = AHEAD_SHARE * gap, offset + 2 * gap
        return np.array(offsets)
