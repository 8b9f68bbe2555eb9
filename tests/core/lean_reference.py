"""The lean fit in Python: the slow reference the kernel's fit (core.strategies.lean_kernel) is tested against
(tests/core/test_lean_kernel.py), on the same runs (core.strategies.raster_lean.straight_runs).

Each run's profile is fitted with the fewest pieces (lines, and arcs where the run lies in XZ or YZ) within
+-tol of its samples, then every move is checked against the exact profile between the samples (batch drops
every `check_step`) and, where a move leaves the band, the worst place is dropped, added to the samples and the
run fitted again. A run that still fails after `rounds` keeps its samples. The result holds vertically at
every sample and check point.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.segments import ArcsAt, CutSegment
from tmm_workbench.core.strategies.raster_lean import FLAT as _FLAT
from tmm_workbench.core.strategies.raster_lean import Run, plane_of, run_xy, straight_runs, with_runs_replaced

Drop = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # xy (n, 2) -> (z (n,), air (n,) bool)
_MIN_RADIUS_MM = 0.5      # tighter arcs are a valley's kink rounded, not the path
_MAX_RADIUS_MM = 1000.0   # flatter arcs are lines to a controller (and to the post's rounding)
_BAND_USED = 0.8          # of the tolerance, by the fit and at the check points (the rest: between them)
_ARC_MAX_SLOPE = 1.0      # arcs only where their chord rises no more than 45 deg


@dataclass
class LeanStats:
    points_in: int = 0       # CL points of the runs before
    points_out: int = 0      # vertices after
    arcs: int = 0
    checked: int = 0         # exact drops of the checks
    inserted: int = 0        # check points added to the samples
    kept_as_sampled: int = 0  # runs that kept all their samples after every round
    sampled_pieces: int = 0   # pieces whose checks did not converge: their samples kept (today's moves)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


# --- one profile -----------------------------------------------------------------------------------------
@dataclass
class _Piece:
    a: int                    # sample index of the start vertex
    b: int                    # of the end vertex
    za: float
    zb: float
    circle: Optional[tuple[float, float, float]] = None  # (centre s, centre z, +1 upper / -1 lower half)

    def z_at(self, s0: np.ndarray, sa: float, sb: float) -> np.ndarray:
        if self.circle is None:
            return self.za + (self.zb - self.za) * (s0 - sa) / (sb - sa)
        cs, cz, side = self.circle
        r2 = (sa - cs) ** 2 + (self.za - cz) ** 2
        return cz + side * np.sqrt(np.maximum(r2 - (s0 - cs) ** 2, 0.0))


def _circle(p: tuple[float, float], q: tuple[float, float], t: tuple[float, float]
            ) -> Optional[tuple[float, float, float]]:
    """Centre and half (+1: the arc above the centre) of the circle through p, q, t when the arc p..t through
    q lies in one half (z single-valued in s) and is not flatter than _MAX_RADIUS_MM."""
    (x1, y1), (x2, y2), (x3, y3) = p, q, t
    d = 2 * (x1 * (y2 - y3) + x2 * (y3 - y1) + x3 * (y1 - y2))
    if abs(d) < 1e-12:
        return None
    a1, a2, a3 = x1 * x1 + y1 * y1, x2 * x2 + y2 * y2, x3 * x3 + y3 * y3
    cx = (a1 * (y2 - y3) + a2 * (y3 - y1) + a3 * (y1 - y2)) / d
    cy = (a1 * (x3 - x2) + a2 * (x1 - x3) + a3 * (x2 - x1)) / d
    r = math.hypot(x1 - cx, y1 - cy)
    if not (_MIN_RADIUS_MM <= r <= _MAX_RADIUS_MM):
        return None
    side = 1.0 if y1 > cy else -1.0
    if not (side * (y1 - cy) > 0 and side * (y2 - cy) > 0 and side * (y3 - cy) > 0):
        return None
    if not (min(x1, x3) - cx > -r and max(x1, x3) - cx < r):
        return None
    return cx, cy, side


def fit_profile(s: np.ndarray, e: np.ndarray, tol: float, fixed: np.ndarray, arcs: bool,
                start: tuple[int, float] = (0, math.nan)) -> list[_Piece]:
    """Pieces (lines, arcs) from sample 0 to n-1 through the band e +- tol at every sample, exact (z = e) at
    the `fixed` samples (the ends are). s strictly increasing between consecutive fixed samples; a pair of
    consecutive samples with equal s (a vertical move) must both be fixed. Greedy: from each vertex the
    piece reaching farthest (lines: the slope sleeve, O(n); arcs: doubling then bisection on the end).
    `start`: (sample, z) of the first vertex when refitting the rest of a profile (default sample 0, exact)."""
    n = len(s)
    lo = np.where(fixed, e, e - tol)
    hi = np.where(fixed, e, e + tol)
    pieces: list[_Piece] = []
    # the first fixed sample at or after each index (never reached past by a piece)
    idx = np.where(fixed, np.arange(n), n - 1)
    next_fixed = np.minimum.accumulate(idx[::-1])[::-1]
    a, za = start[0], float(e[start[0]]) if math.isnan(start[1]) else start[1]
    while a < n - 1:
        if s[a + 1] - s[a] <= _FLAT:  # vertical move, both ends fixed
            pieces.append(_Piece(a, a + 1, za, float(e[a + 1])))
            a, za = a + 1, float(e[a + 1])
            continue
        # the slope sleeve: every line from (s[a], za) within the band at a+1..j (vectorized, in windows)
        j, mlo, mhi = _line_reach(s, lo, hi, int(next_fixed[a + 1]), a, za)
        # the end vertex: high in the band before a hump (the next chord sags across it), low before a hollow
        if fixed[j] or j == n - 1:
            m = 0.5 * (mlo + mhi)
        else:
            d1 = (e[j] - e[j - 1]) / max(s[j] - s[j - 1], _FLAT)
            d2 = (e[j + 1] - e[j]) / max(s[j + 1] - s[j], _FLAT)
            m = mhi if d2 < d1 - 1e-9 else mlo if d2 > d1 + 1e-9 else 0.5 * (mlo + mhi)
        zj = min(max(za + m * (s[j] - s[a]), float(lo[j])), float(hi[j]))
        best = _Piece(a, j, za, zj)
        if arcs:
            arc = _arc_reach(s, e, lo, hi, int(next_fixed[a + 1]), a, za)
            if arc is not None and arc.b > j:
                best = arc
        pieces.append(best)
        a, za = best.b, best.zb
    return pieces


def _line_reach(s, lo, hi, limit: int, a: int, za: float) -> tuple[int, float, float]:
    """(j, lowest slope, highest slope): the farthest sample j <= limit that a line from (s[a], za) reaches
    within the band at every sample a+1..j, and the slopes that do it. Short reaches (most, on detailed
    models) sample by sample; long ones in vectorized windows."""
    sa = s[a]
    mlo, mhi = -math.inf, math.inf
    k = a + 1
    while k <= min(limit, a + 8):
        ds = s[k] - sa
        nlo, nhi = max(mlo, (lo[k] - za) / ds), min(mhi, (hi[k] - za) / ds)
        if nlo > nhi:
            return k - 1, mlo, mhi
        mlo, mhi = nlo, nhi
        k += 1
    if k > limit:
        return limit, mlo, mhi
    width = 32
    while True:
        end = min(limit, k - 1 + width)
        ds = s[k:end + 1] - sa
        wlo = np.maximum.accumulate(np.maximum((lo[k:end + 1] - za) / ds, mlo))
        whi = np.minimum.accumulate(np.minimum((hi[k:end + 1] - za) / ds, mhi))
        broken = np.flatnonzero(wlo > whi)
        if len(broken):
            i = int(broken[0])
            if i == 0:
                return k - 1, mlo, mhi
            return k + i - 1, float(wlo[i - 1]), float(whi[i - 1])
        mlo, mhi = float(wlo[-1]), float(whi[-1])
        if end == limit:
            return end, mlo, mhi
        k = end + 1
        width *= 4


def _arc_reach(s, e, lo, hi, limit: int, a: int, za: float) -> Optional[_Piece]:
    """The arc from (s[a], za) to the farthest exact sample up to `limit` it can reach within the band (or
    None)."""
    if limit < a + 2:
        return None

    def fits(j: int) -> Optional[_Piece]:
        if abs(e[j] - za) > _ARC_MAX_SLOPE * (s[j] - s[a]):
            return None  # steep: lines (a vertical band there is a thin one along the normal)
        q = (a + j) // 2
        c = _circle((s[a], za), (s[q], e[q]), (s[j], e[j]))
        if c is None:
            return None
        piece = _Piece(a, j, za, float(e[j]), c)
        z = piece.z_at(s[a + 1:j], s[a], s[j])
        ok = np.all(z >= lo[a + 1:j] - 1e-12) and np.all(z <= hi[a + 1:j] + 1e-12)
        return piece if ok else None

    good, step, bad = None, 2, None
    while True:
        j = min(a + step, limit)
        p = fits(j)
        if p is None:
            bad = j
            break
        good = p
        if j == limit:
            return good
        step *= 2
    lo_j = good.b if good is not None else a + 1
    while bad - lo_j > 1:  # bisection between the last fit and the first miss
        mid = (lo_j + bad) // 2
        p = fits(mid) if mid >= a + 2 else None
        if p is None:
            bad = mid
        else:
            good, lo_j = p, mid
    return good


@dataclass
class _RefRun(Run):
    """A run with the fit's state: its pieces, whether they passed their checks, how many of them stay."""
    pieces: list = None
    done: bool = False
    keep: int = 0             # pieces before this one passed their checks and stay


def _check_points(run: _RefRun, step: float, first: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, z of the pieces, piece index) every `step` inside each piece from `first` on that spans more than
    one sample or whose vertices left the exact profile (not at the samples: the fit holds there)."""
    s, e = run.s, run.e
    a = np.array([p.a for p in run.pieces])
    b = np.array([p.b for p in run.pieces])
    za = np.array([p.za for p in run.pieces])
    zb = np.array([p.zb for p in run.pieces])
    arc = np.array([p.circle is not None for p in run.pieces])
    sa, sb = s[a], s[b]
    as_sampled = (b == a + 1) & run.settled[a]
    use = np.flatnonzero((sb - sa > _FLAT) & ~as_sampled & (np.arange(len(a)) >= first))
    if not len(use):
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=int)
    m = np.maximum(4, np.ceil((sb[use] - sa[use]) / step).astype(int))  # 3 at least: a kink is seen
    who = np.repeat(use, m + 1)
    first = np.repeat(np.cumsum(m + 1) - (m + 1), m + 1)
    frac = (np.arange(len(who)) - first) / np.repeat(m, m + 1)
    t = sa[who] + (sb[who] - sa[who]) * frac
    i = np.clip(np.searchsorted(s, t), 1, len(s) - 1)
    ends = (frac == 0) | (frac == 1)
    keep = ends | (np.minimum(np.abs(s[i] - t), np.abs(s[i - 1] - t)) > 1e-6)
    t, who, ends, frac = t[keep], who[keep], ends[keep], frac[keep]
    z = za[who] + (zb[who] - za[who]) * (t - sa[who]) / (sb[who] - sa[who])
    for k in np.unique(who[arc[who]]):
        sel = who == k
        p = run.pieces[k]
        z[sel] = p.z_at(t[sel], s[p.a], s[p.b])
    # the piece's ends as the exact samples they are: never outside, seen by the kink test (_refine_kinks)
    z[ends] = np.where(frac[ends] == 0, e[a[who[ends]]], e[b[who[ends]]])
    return t, z, who


def lean_segments(segments: list[CutSegment], drop: Drop, tol: float, arcs: bool = False,
                  check_step: float = 0.05, insert_rounds: int = 10, rounds: int = 12
                  ) -> tuple[list[CutSegment], LeanStats]:
    """The segments with each straight run's points replaced by lean moves (see the module doc; the arcs in
    CutSegment.arcs) and the counts. `drop` gives the exact CL height (and air) at XY points; `check_step` (mm)
    the spacing of the checks between samples. For `insert_rounds` the check points outside the band become
    samples; then the pieces still outside keep their samples (the sampled moves there), for up to `rounds`
    more."""
    stats = LeanStats()
    # the fit and the checks keep a margin of the band for the exact path between two check points: its
    # chord there is within h^2 / (8 rho) of it, 2e-4 mm for h 0.05 mm on the 1 mm corner radius of a small
    # bull-nose (convex stretches of a CL path curve no tighter than the cutter's corner)
    margin = tol * (1 - _BAND_USED)
    tol = tol * _BAND_USED
    parts, plain = straight_runs(segments)
    runs = {key: _RefRun(**vars(r)) for key, r in plain.items()}
    stats.points_in = sum(len(seg) for seg in segments)
    for round_ in range(rounds + insert_rounds):
        todo = [r for r in runs.values() if not r.done]
        if not todo:
            break
        checks = []
        for r in todo:
            head = (r.pieces or [])[:r.keep]
            start = (head[-1].b, head[-1].zb) if head else (0, math.nan)
            r.pieces = head + fit_profile(r.s, r.e, tol, r.fixed, arcs and plane_of(r.u) is not None, start)
            checks.append(_check_points(r, check_step, r.keep))
        xy = np.vstack([r.origin + c[0][:, None] * r.u for r, c in zip(todo, checks)])
        exact, air = drop(xy) if len(xy) else (np.zeros(0), np.zeros(0, dtype=bool))
        stats.checked += len(xy)
        checks = _refine_kinks(todo, checks, exact, air, drop, margin, stats)
        for r, (cs, cz, who, ex, ai) in zip(todo, checks):
            dev = np.abs(cz - ex)
            dev[ai] = np.inf
            bad = dev > tol
            if not bad.any():
                r.done = True
                continue
            # samples are added and fixed only inside failing pieces: the pieces before the one ahead of the
            # first (whose reach an added sample may shorten) stay as checked
            r.keep = max(0, int(who[bad].min()) - 1)
            if round_ >= insert_rounds:
                _keep_sampled(r, cs, who, ex, ai, bad, stats)
            else:
                _add_samples(r, cs, ex, ai, bad, stats)
    fitted = {key: _vertices(r, stats) for key, r in runs.items()}
    out = with_runs_replaced(segments, parts, runs, lambda key: fitted[key][0],
                             {key: at for key, (_, at) in fitted.items() if at is not None})
    stats.points_out = sum(len(seg) for seg in out)
    return out, stats


def _keep_sampled(r: _RefRun, cs: np.ndarray, who: np.ndarray, ex: np.ndarray, ai: np.ndarray, bad: np.ndarray,
                  stats: LeanStats) -> None:
    """Not converging: the failing pieces become the polyline through every exact point known there (their
    samples and all their check points, fixed), which no later round checks."""
    pieces = np.unique(who[bad])
    spans = [(r.s[r.pieces[k].a], r.s[r.pieces[k].b]) for k in pieces]
    w = np.flatnonzero(np.isin(who, pieces) & ~ai)
    w = w[np.argsort(cs[w], kind="stable")]
    i = np.clip(np.searchsorted(r.s, cs[w]), 1, len(r.s) - 1)
    w = w[np.minimum(np.abs(r.s[i] - cs[w]), np.abs(r.s[i - 1] - cs[w])) > 1e-6]
    for piece in pieces:
        q = r.pieces[piece]
        r.fixed[q.a:q.b + 1] = True
        stats.sampled_pieces += 1
    if len(w):
        at = np.searchsorted(r.s, cs[w])
        r.s = np.insert(r.s, at, cs[w])
        r.e = np.insert(r.e, at, ex[w])
        r.fixed = np.insert(r.fixed, at, True)
        r.settled = np.insert(r.settled, at, True)
        stats.inserted += len(w)
    for sa, sb in spans:
        r.settled[(r.s >= sa) & (r.s < sb)] = True


def _add_samples(r: _RefRun, cs: np.ndarray, ex: np.ndarray, ai: np.ndarray, bad: np.ndarray,
                 stats: LeanStats) -> None:
    """Every check point outside the band becomes a sample (the profile curves more between the samples there
    than the tolerance allows); air between two samples keeps that move as sampled."""
    w = np.flatnonzero(bad & ~ai)
    w = w[np.argsort(cs[w], kind="stable")]
    adds_s, adds_e = list(cs[w]), list(ex[w])
    i = np.searchsorted(r.s, cs[bad & ai])
    fix_pairs = list(np.concatenate([i - 1, i]))
    r.fixed[fix_pairs] = True
    r.settled[i - 1] = True  # the sampled move across air stays
    if adds_s:
        at = np.searchsorted(r.s, adds_s)
        r.s = np.insert(r.s, at, adds_s)
        r.e = np.insert(r.e, at, adds_e)
        r.fixed = np.insert(r.fixed, at, False)
        r.settled = np.insert(r.settled, at, False)
        stats.inserted += len(adds_s)


def _vertices(r: _RefRun, stats: LeanStats) -> tuple[np.ndarray, Optional[ArcsAt]]:
    """The run's vertices (its samples when it never passed its checks) and their arcs (per vertex, the arc
    ending there; None: lines only)."""
    if not r.done:  # still outside the band after every round: its samples, exact
        stats.kept_as_sampled += 1
        return np.column_stack([run_xy(r, r.s), r.e]), None
    plane = plane_of(r.u)
    verts = [np.array([*(r.origin + r.s[0] * r.u), r.pieces[0].za])]
    at: list[Optional[Arc]] = [None]
    for p in r.pieces:
        end = np.array([*run_xy(r, r.s[p.b:p.b + 1])[0], p.zb])
        arc = None
        if p.circle is not None and plane is not None:
            cs, cz, _ = p.circle
            arc = Arc.through(verts[-1], end, (*(r.origin + cs * r.u), cz), plane)
            stats.arcs += 1
        verts.append(end)
        at.append(arc)
    return np.array(verts), (tuple(at) if any(at) else None)


def _piece_z(run: _RefRun, t: np.ndarray, who: np.ndarray) -> np.ndarray:
    """z of the run's pieces `who` at `t`."""
    a = np.array([run.pieces[k].a for k in who], dtype=int)
    b = np.array([run.pieces[k].b for k in who], dtype=int)
    za = np.array([run.pieces[k].za for k in who])
    zb = np.array([run.pieces[k].zb for k in who])
    z = za + (zb - za) * (t - run.s[a]) / (run.s[b] - run.s[a])
    for k in np.unique(who):
        p = run.pieces[k]
        if p.circle is not None:
            sel = who == k
            z[sel] = p.z_at(t[sel], run.s[p.a], run.s[p.b])
    return z


def _refine_kinks(todo: list, checks: list, exact: np.ndarray, air: np.ndarray, drop: Drop, margin: float,
                  stats: LeanStats, levels: int = 3) -> list:
    """Per run (s, z, piece, exact z, air) of its checks, in order along the run, with check points added
    halfway either side of those where the exact path leaves the chord of its two neighbours by more than
    half the `margin` (a ridge or a valley between checks, where the exact path is not within the margin
    of its chords), `levels` times, each level one batch of drops."""
    runs = []
    k = 0
    for r, (cs, cz, who) in zip(todo, checks):
        runs.append([cs, cz, who, exact[k:k + len(cs)], air[k:k + len(cs)]])
        k += len(cs)
    for _ in range(levels):
        extra = []
        for r, (cs, cz, who, ex, ai) in zip(todo, runs):
            if len(cs) < 3:
                extra.append((np.zeros(0), np.zeros(0, dtype=int)))
                continue
            f = (cs[1:-1] - cs[:-2]) / (cs[2:] - cs[:-2])
            off = np.abs(ex[1:-1] - (ex[:-2] + f * (ex[2:] - ex[:-2])))
            same = (who[:-2] == who[1:-1]) & (who[2:] == who[1:-1]) & ~ai[:-2] & ~ai[1:-1] & ~ai[2:]
            kinks = np.flatnonzero(same & (off > 0.5 * margin)) + 1
            if not len(kinks):
                extra.append((np.zeros(0), np.zeros(0, dtype=int)))
                continue
            new = np.unique(np.concatenate([(cs[kinks - 1] + cs[kinks]) / 2, (cs[kinks] + cs[kinks + 1]) / 2]))
            i = np.clip(np.searchsorted(r.s, new), 1, len(r.s) - 1)
            new = new[np.minimum(np.abs(r.s[i] - new), np.abs(r.s[i - 1] - new)) > 1e-6]  # samples hold
            new = new[~np.isin(new, cs)]
            j = np.clip(np.searchsorted(cs, new), 1, len(cs) - 1)
            extra.append((new, who[j]))
        xy = [r.origin + t[:, None] * r.u for r, (t, _) in zip(todo, extra) if len(t)]
        if not xy:
            break
        ex2, ai2 = drop(np.vstack(xy))
        stats.checked += len(ex2)
        k = 0
        for n, (r, (t, w)) in enumerate(zip(todo, extra)):
            if not len(t):
                continue
            cs, cz, who, ex, ai = runs[n]
            e2, a2 = ex2[k:k + len(t)], ai2[k:k + len(t)]
            k += len(t)
            cs, cz = np.concatenate([cs, t]), np.concatenate([cz, _piece_z(r, t, w)])
            who, ex, ai = np.concatenate([who, w]), np.concatenate([ex, e2]), np.concatenate([ai, a2])
            order = np.argsort(cs, kind="stable")
            runs[n] = [cs[order], cz[order], who[order], ex[order], ai[order]]
    return [tuple(x) for x in runs]
