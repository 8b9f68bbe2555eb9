"""Lean passes: the forward step chosen by the chord tolerance instead of the sample step (issue 14 item 2).

Every raster pass (and zig-zag link) is straight in XY, so its exact CL path is a profile z(s) along the
pass: the drop height of the cutter at distance s. The samples raster_drop and raster_refine dropped are
points of that profile; this module replaces them by the fewest moves (lines, and optionally arcs in the
pass's vertical plane) that stay within a band of +-tol about it, then checks every move against the exact
profile between the samples (batch drops every `check_step`) and, where a move leaves the band, drops the
worst place, adds it to the samples and fits that pass again. A pass that still fails after `rounds`
keeps its samples (today's moves). The result holds vertically at every sample and check point.

The band, as commercial systems' in/out tolerances: a move may pass up to tol above the exact CL path
(material left) and up to tol below it (the surface cut by at most tol vertically; along the normal never
more). Splitting it both ways lets a chord across a convex stretch sag by 2 tol between vertices placed
tol above it, where an above-only band allows no chord at all; the simulation's gouge check for lean
passes is therefore "deepest gouge <= tol" (tests/core/test_raster_lean.py, benchmarks/lean_path.py).
The first and last point of a run, both ends of a vertical (cliff) move and the moves beside air stay
exact: the neighbouring segments, the linker and raster_refine's cliff corners see what they saw.

Arcs (G2/G3) are fitted where the pass lies in a principal vertical plane: a raster at 0 or 180 deg in
XZ (G18), at 90 or 270 deg in YZ (G19); elsewhere only lines. An arc's end point is exact.

The op's passes are fitted in the kernel (core.strategies.lean_kernel, native/src/query/lean_profile.cpp and
lean_arcs.cpp: exact breakpoints, min-link windows, arcs merged from the lines against the exact profile; fewer
moves and 5-10x faster); this fit is the slow reference of tests/core/test_lean_kernel.py, and this module
holds what both share (the runs of a path, the arcs' G-code form).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.toolpath import MoveKind, Toolpath

Drop = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # xy (n, 2) -> (z (n,), air (n,) bool)
_FLAT = 1e-7              # mm: collinearity, a vertical move's horizontal length
_MIN_RADIUS_MM = 0.5      # tighter arcs are a valley's kink rounded, not the path
_MAX_RADIUS_MM = 1000.0   # flatter arcs are lines to a controller (and to the post's rounding)
_BAND_USED = 0.8          # of the tolerance, by the fit and at the check points (the rest: between them)
_ARC_MAX_SLOPE = 1.0      # arcs only where their chord rises no more than 45 deg
_AXIS_TOL = 1e-9          # a pass direction this close to X or Y lies in a principal plane


@dataclass(frozen=True)
class Arc:
    """A circular move in a vertical principal plane, to the move's end point (FreeCAD/RS274 meaning)."""
    centre: tuple[float, float, float]  # mm, absolute
    clockwise: bool                     # G2: clockwise viewed from the plane's positive normal axis
    plane: str                          # "XZ" (G18, normal +Y) or "YZ" (G19, normal +X)


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


# --- runs of a tool path ----------------------------------------------------------------------------------
@dataclass
class _Run:
    seg: CutSegment
    origin: np.ndarray        # xy of the first point
    u: np.ndarray             # unit direction in XY
    s: np.ndarray
    e: np.ndarray
    fixed: np.ndarray
    settled: np.ndarray       # per sample: the move to the next one is final (vertical, beside air, or given up)
    pieces: list = None
    done: bool = False
    keep: int = 0             # pieces before this one passed their checks and stay
    end_xy: np.ndarray = None  # xy of the last point as given: origin + s u misses it by an ulp, and the next
                               # part (or segment) and the arcs keyed by their ends must meet it exactly


def _straight_parts(pts: np.ndarray) -> list[tuple[int, int]]:
    """[first, last] index ranges of the points that run straight in one XY direction (vertical moves join
    either side): a zig-zag pass carries the first points of the turn to its link at its end."""
    d = np.diff(pts[:, :2], axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    cuts, u_prev = [], None
    for k in range(len(d)):
        if length[k] <= _FLAT:
            continue
        u = d[k] / length[k]
        if u_prev is not None and (abs(u[0] * u_prev[1] - u[1] * u_prev[0]) > 1e-6 or u @ u_prev < 0):
            cuts.append(k)  # point k ends one part and starts the next
        u_prev = u
    bounds = [0] + cuts + [len(pts) - 1]
    return list(zip(bounds[:-1], bounds[1:]))


def _as_run(seg: CutSegment, pts: np.ndarray) -> Optional[_Run]:
    if len(pts) < 2 or seg.axes is not None:
        return None
    xy = pts[:, :2]
    d = xy[-1] - xy[0]
    length = float(np.hypot(*d))
    if length <= _FLAT:
        return None
    u = d / length
    s = (xy - xy[0]) @ u
    off = np.abs((xy - xy[0]) @ np.array([-u[1], u[0]]))
    ds = np.diff(s)
    if off.max() > 1e-6 or np.any(ds < -_FLAT):
        return None  # not one straight, ordered run: kept as it is
    fixed = np.zeros(len(s), dtype=bool)
    fixed[[0, -1]] = True
    vertical = np.flatnonzero(ds <= _FLAT)
    fixed[vertical] = fixed[vertical + 1] = True
    settled = np.zeros(len(s), dtype=bool)
    settled[vertical] = True
    return _Run(seg, xy[0].copy(), u, s.copy(), pts[:, 2].copy(), fixed, settled, end_xy=xy[-1].copy())


def plane_of(u: np.ndarray) -> Optional[str]:
    """The principal vertical plane ("XZ", "YZ") a run along the XY unit vector u lies in, or None."""
    if abs(u[1]) < _AXIS_TOL:
        return "XZ"
    if abs(u[0]) < _AXIS_TOL:
        return "YZ"
    return None


def _check_points(run: _Run, step: float, first: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
                  ) -> tuple[list[CutSegment], dict, LeanStats]:
    """The segments with each straight run's points replaced by lean moves (see the module doc), the arcs
    ({(start xyz, end xyz): Arc} for attach_arcs) and the counts. `drop` gives the exact CL height (and
    air) at XY points; `check_step` (mm) the spacing of the checks between samples. For `insert_rounds` the
    check points outside the band become samples; then the pieces still outside keep their samples (the
    sampled moves there, as today), for up to `rounds` more."""
    stats = LeanStats()
    # the fit and the checks keep a margin of the band for the exact path between two check points: its
    # chord there is within h^2 / (8 rho) of it, 2e-4 mm for h 0.05 mm on the 1 mm corner radius of a small
    # bull-nose (convex stretches of a CL path curve no tighter than the cutter's corner)
    margin = tol * (1 - _BAND_USED)
    tol = tol * _BAND_USED
    parts, runs = straight_runs(segments)
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
                # not converging: the failing pieces become the polyline through every exact point known there
                # (their samples and all their check points, fixed), which no later round checks
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
                continue
            # every check point outside the band becomes a sample (the profile curves more between the
            # samples there than the tolerance allows); air between two samples keeps that move as sampled
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
    arc_map: dict = {}
    out = with_runs_replaced(segments, parts, runs, lambda key: _vertices(runs[key], arc_map, stats))
    stats.points_out = sum(len(seg) for seg in out)
    return out, arc_map, stats


Parts = dict[int, list[tuple[int, int]]]  # segment index -> its straight parts (first, last point index)


def straight_runs(segments: list[CutSegment]) -> tuple[Parts, dict[tuple[int, int], "_Run"]]:
    """Each segment's straight parts and the runs a lean fit may replace, keyed (segment, part), in that order
    (tool-axis segments and single points have none; parts that are no profile are left out). The points are
    `_run_tips`': a segment the tool reaches without a retract starts at the previous one's last point."""
    tips = [_run_tips(segments, i) for i in range(len(segments))]
    parts = {i: _straight_parts(t) if len(t) >= 2 and segments[i].axes is None else [] for i, t in enumerate(tips)}
    runs = {(i, k): _as_run(segments[i], tips[i][a:b + 1]) for i in parts for k, (a, b) in enumerate(parts[i])}
    return parts, {key: r for key, r in runs.items() if r is not None}


def with_runs_replaced(segments: list[CutSegment], parts: Parts, keys, vertices: Callable[[tuple[int, int]], np.ndarray]
                       ) -> list[CutSegment]:
    """The segments with the points of each run in `keys` replaced by `vertices(key)` (its first and last point
    the run's), called in segment and part order; the other parts keep their points."""
    out = list(segments)
    for i, seg in enumerate(segments):
        if not any((i, k) in keys for k in range(len(parts[i]))):
            continue
        run_tips = _run_tips(segments, i)
        tips = []
        for k, (a, b) in enumerate(parts[i]):
            v = vertices((i, k)) if (i, k) in keys else run_tips[a:b + 1]
            tips.append(v if k == 0 else v[1:])  # the shared point once
        out[i] = replace(seg, tips=np.vstack(tips)[len(run_tips) - len(seg):])  # the previous segment's point: its own
    return out


def _run_tips(segments: list[CutSegment], i: int) -> np.ndarray:
    """Segment i's points, led by the previous segment's last point when the linker joins them (the tool goes
    on down, core.linking): that move (into a zig-zag link, out of it, between the runs of a region's chain)
    is a cutting move like the others, fitted and checked with them. (A link of one sample between two passes
    had its two moves outside the band: -0.0047 mm on mount_rush.)"""
    seg = segments[i]
    if not seg.joined or seg.axes is not None or not len(seg):
        return seg.tips
    prev = next((s for s in reversed(segments[:i]) if len(s)), None)  # the linker leaves empty segments out
    if prev is None or prev.axes is not None:
        return seg.tips
    return np.vstack([prev.tips[-1:], seg.tips])


def _vertices(r: _Run, arc_map: dict, stats: LeanStats) -> np.ndarray:
    """The run's vertices (its samples when it never passed its checks); its arcs into `arc_map`."""
    if not r.done:  # still outside the band after every round: its samples, exact
        stats.kept_as_sampled += 1
        return np.column_stack([run_xy(r, r.s), r.e])
    plane = plane_of(r.u)
    verts = [np.array([*(r.origin + r.s[0] * r.u), r.pieces[0].za])]
    for p in r.pieces:
        end = np.array([*run_xy(r, r.s[p.b:p.b + 1])[0], p.zb])
        if p.circle is not None and plane is not None:
            cs, cz, _ = p.circle
            centre = (*(r.origin + cs * r.u), cz)
            key, arc = arc_entry(verts[-1], end, np.array(centre), plane)
            arc_map[key] = arc
            stats.arcs += 1
        verts.append(end)
    return np.array(verts)


def run_xy(r: _Run, s: np.ndarray) -> np.ndarray:
    """The XY points at distances `s` along the run, its last point exactly as given."""
    xy = r.origin + s[:, None] * r.u
    xy[s >= r.s[-1]] = r.end_xy
    return xy


def _piece_z(run: _Run, t: np.ndarray, who: np.ndarray) -> np.ndarray:
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


def _key(p: np.ndarray) -> tuple[float, float, float]:
    return (float(p[0]), float(p[1]), float(p[2]))


def arc_entry(start: np.ndarray, end: np.ndarray, centre: np.ndarray, plane: str
              ) -> tuple[tuple[tuple[float, float, float], tuple[float, float, float]], Arc]:
    """The arc_map entry of the move start -> end about `centre` (its sweep under 180 deg): (start, end) -> Arc."""
    normal = np.cross(start - centre, end - centre)
    axis = 1 if plane == "XZ" else 0
    return (_key(start), _key(end)), Arc(_key(centre), bool(normal[axis] < 0), plane)


def both_ways(arc_map: dict) -> dict:
    """`arc_map` with each arc also under its move run backwards (the same circle, the other sense): for a pass
    set a start point or the pass sets' order runs the other way (core.strategies.finish_passes)."""
    out = dict(arc_map)
    for (start, end), arc in arc_map.items():
        out.setdefault((end, start), replace(arc, clockwise=not arc.clockwise))
    return out


def attach_arcs(toolpath: Toolpath, arc_map: dict) -> Toolpath:
    """Marks the FEED moves of `toolpath` that are arcs (toolpath.arcs: move index -> Arc): the linker copies
    the segments' tips, so a move is found by its start and end."""
    if not arc_map:
        return toolpath
    moves = toolpath.moves
    for i in range(1, len(moves)):
        m, p = moves[i], moves[i - 1]
        if m.kind is MoveKind.FEED:
            arc = arc_map.get(((p.x, p.y, p.z), (m.x, m.y, m.z)))
            if arc is not None:
                toolpath.arcs[i] = arc
    return toolpath


def arc_offsets(start: tuple[float, float, float], arc: Arc) -> dict[str, float]:
    """The G-code centre words of `arc` from `start`: I and K (XZ) or J and K (YZ)."""
    d = [arc.centre[k] - start[k] for k in range(3)]
    return {"I": d[0], "K": d[2]} if arc.plane == "XZ" else {"J": d[1], "K": d[2]}


def arc_chords(start: Sequence[float], end: Sequence[float], arc: Arc, tolerance: float) -> np.ndarray:
    """The points after `start` along `arc` to `end` (included) as chords within `tolerance` (core.arcs)."""
    from tmm_workbench.core.arcs import arc_points

    off = arc_offsets(tuple(start), arc)
    return arc_points(start, end, off.get("I", 0.0), off.get("J", 0.0), arc.clockwise, tolerance, plane=arc.plane,
                      k=off["K"])


def chorded(toolpath: Toolpath, tolerance: float = 1e-4) -> Toolpath:
    """The tool path with its arcs as chords within `tolerance` (core.arcs): what a simulation of the
    moves as lines reads."""
    if not toolpath.arcs:
        return toolpath
    out = Toolpath()
    for i, m in enumerate(toolpath.moves):
        arc = toolpath.arcs.get(i)
        if arc is None or i == 0:
            out.moves.append(m)
            continue
        p = toolpath.moves[i - 1]
        for q in arc_chords((p.x, p.y, p.z), (m.x, m.y, m.z), arc, tolerance):
            out.add(m.kind, *q, m.axis)
    return out
