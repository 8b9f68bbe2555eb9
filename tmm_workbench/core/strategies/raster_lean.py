"""Lean passes: the forward step chosen by the chord tolerance instead of the sample step; the straight runs
of a path that the lean fit replaces.

Every raster pass (and zig-zag link) is straight in XY, so its exact CL path is a profile z(s) along the
pass: the drop height of the cutter at distance s. The samples raster_drop and raster_refine dropped are
points of that profile; the lean fit (core.strategies.lean_kernel, in the kernel: native/src/query/
lean_profile.cpp and lean_arcs.cpp) replaces them by the fewest moves (lines, and optionally arcs in the
pass's vertical plane) that stay within a band of +-tol about it, checked against the exact profile between
the samples.

The band, as commercial systems' in/out tolerances: a move may pass up to tol above the exact CL path
(material left) and up to tol below it (the surface cut by at most tol vertically; along the normal never
more). Splitting it both ways lets a chord across a convex stretch sag by 2 tol between vertices placed
tol above it, where an above-only band allows no chord at all; the simulation's gouge check for lean
passes is therefore "deepest gouge <= tol" (tests/core/test_raster_lean.py, benchmarks/lean_path.py).
The first and last point of a run, both ends of a vertical (cliff) move and the moves beside air stay
exact: the neighbouring segments, the linker and raster_refine's cliff corners see what they saw.

Arcs (G2/G3) are fitted where the pass lies in a principal vertical plane: a raster at 0 or 180 deg in
XZ (G18), at 90 or 270 deg in YZ (G19); elsewhere only lines. An arc's end point is exact. The fitted arcs
ride in the segments (CutSegment.arcs, per tip) and the linker makes them arc moves (Move.arc).

This module holds the runs: each segment's straight parts as profiles (`straight_runs`) and the segments
rebuilt from the fitted vertices and arcs (`with_runs_replaced`). A Python fit of the same band, the slow
reference the kernel's fit is tested against, is tests/core/lean_reference.py.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Container, Mapping, Optional

import numpy as np

from tmm_workbench.core.cancel import poll
from tmm_workbench.core.segments import ArcsAt, CutSegment

FLAT = 1e-7               # mm: collinearity, a vertical move's horizontal length
_AXIS_TOL = 1e-9          # a pass direction this close to X or Y lies in a principal plane
RunKey = tuple[int, int]  # (segment index, part index)
Parts = dict[int, list[tuple[int, int]]]  # segment index -> its straight parts (first, last point index)


@dataclass
class Run:
    """One straight part of a segment as a profile: z = e at distance s along u from origin."""
    seg: CutSegment
    origin: np.ndarray        # xy of the first point
    u: np.ndarray             # unit direction in XY
    s: np.ndarray
    e: np.ndarray
    fixed: np.ndarray         # per sample: a vertex stays here, exact (the ends, both ends of a vertical move)
    settled: np.ndarray       # per sample: the move to the next one is final (vertical, beside air, or given up)
    end_xy: np.ndarray        # xy of the last point as given: origin + s u misses it by an ulp, and the next
                              # part (or segment) must meet it exactly


def _straight_parts(pts: np.ndarray) -> list[tuple[int, int]]:
    """[first, last] index ranges of the points that run straight in one XY direction (vertical moves join
    either side): a zig-zag pass carries the first points of the turn to its link at its end."""
    poll()   # one segment of a Python pass over every point: Cancel heard, the dialog repaints
    d = np.diff(pts[:, :2], axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    cuts, u_prev = [], None
    for k in range(len(d)):
        if length[k] <= FLAT:
            continue
        u = d[k] / length[k]
        if u_prev is not None and (abs(u[0] * u_prev[1] - u[1] * u_prev[0]) > 1e-6 or u @ u_prev < 0):
            cuts.append(k)  # point k ends one part and starts the next
        u_prev = u
    bounds = [0] + cuts + [len(pts) - 1]
    return list(zip(bounds[:-1], bounds[1:]))


def _as_run(seg: CutSegment, pts: np.ndarray) -> Optional[Run]:
    poll()
    if len(pts) < 2 or seg.axes is not None:
        return None
    xy = pts[:, :2]
    d = xy[-1] - xy[0]
    length = float(np.hypot(*d))
    if length <= FLAT:
        return None
    u = d / length
    s = (xy - xy[0]) @ u
    off = np.abs((xy - xy[0]) @ np.array([-u[1], u[0]]))
    ds = np.diff(s)
    if off.max() > 1e-6 or np.any(ds < -FLAT):
        return None  # not one straight, ordered run: kept as it is
    fixed = np.zeros(len(s), dtype=bool)
    fixed[[0, -1]] = True
    vertical = np.flatnonzero(ds <= FLAT)
    fixed[vertical] = fixed[vertical + 1] = True
    settled = np.zeros(len(s), dtype=bool)
    settled[vertical] = True
    return Run(seg, xy[0].copy(), u, s.copy(), pts[:, 2].copy(), fixed, settled, xy[-1].copy())


def plane_of(u: np.ndarray) -> Optional[str]:
    """The principal vertical plane ("XZ", "YZ") a run along the XY unit vector u lies in, or None."""
    if abs(u[1]) < _AXIS_TOL:
        return "XZ"
    if abs(u[0]) < _AXIS_TOL:
        return "YZ"
    return None


def straight_runs(segments: list[CutSegment]) -> tuple[Parts, dict[RunKey, Run]]:
    """Each segment's straight parts and the runs a lean fit may replace, keyed (segment, part), in that order
    (tool-axis segments and single points have none; parts that are no profile are left out). The points are
    `_run_tips`': a segment the tool reaches without a retract starts at the previous one's last point."""
    tips = [_run_tips(segments, i) for i in range(len(segments))]
    parts = {i: _straight_parts(t) if len(t) >= 2 and segments[i].axes is None else [] for i, t in enumerate(tips)}
    runs = {(i, k): _as_run(segments[i], tips[i][a:b + 1]) for i in parts for k, (a, b) in enumerate(parts[i])}
    return parts, {key: r for key, r in runs.items() if r is not None}


def with_runs_replaced(segments: list[CutSegment], parts: Parts, keys: Container[RunKey],
                       vertices: Callable[[RunKey], np.ndarray], arcs: Optional[Mapping[RunKey, ArcsAt]] = None
                       ) -> list[CutSegment]:
    """The segments with the points of each run in `keys` replaced by `vertices(key)` (its first and last point
    the run's), called in segment and part order, and the arcs of its moves by `arcs[key]` (per vertex, the arc
    ending there; a run not in it: lines); the other parts keep their points as lines (the fit's segments are
    sampled points)."""
    arcs = arcs or {}
    out = list(segments)
    for i, seg in enumerate(segments):
        if not any((i, k) in keys for k in range(len(parts[i]))):
            continue
        run_tips = _run_tips(segments, i)
        tips: list[np.ndarray] = []
        at: list = []
        for k, (a, b) in enumerate(parts[i]):
            v = vertices((i, k)) if (i, k) in keys else run_tips[a:b + 1]
            first = 0 if k == 0 else 1  # the shared point once (the arc into it is the part before's)
            tips.append(v[first:])
            at.extend((arcs.get((i, k)) or (None,) * len(v))[first:])
        own = len(run_tips) - len(seg)  # the previous segment's point: its own
        out[i] = replace(seg, tips=np.vstack(tips)[own:], arcs=tuple(at[own:]) if any(at[own:]) else None)
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


def run_xy(r: Run, s: np.ndarray) -> np.ndarray:
    """The XY points at distances `s` along the run, its last point exactly as given."""
    xy = r.origin + s[:, None] * r.u
    xy[s >= r.s[-1]] = r.end_xy
    return xy
