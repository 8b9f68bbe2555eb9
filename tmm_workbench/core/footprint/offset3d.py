"""The constant-scallop "3D offset" pattern: what its passes are made of and how
they are cut. The passes themselves are the level sets of one arrival-time field (core.footprint.offset_field);
here: the cusp rule's step for a slope across the passes (StepRule), the passes (Loop, OffsetLoops), the spike a
sharp convex corner gets (_spiked) and the cutting order (loop_chains).

StepRule is the planar cusp rule (core.footprint.cusp.stepover_for_cusp) at the slope of the CL surface across
the passes: on a plane rising at that slope, neighbouring passes d apart in XY leave exactly the cusp along the
normal (for a ball: 3D distance s0, XY distance s0 cos(slope)). Above `max_slope_deg` (walls: waterline's) the
slope is held there.

An offset keeps a sharp convex corner sharp, and on its bisector the point between two passes' corners lies
d / (1 + sin(half the corner's angle)) from both (0.586 d at a right angle: 1.37 x the cusp): the cut pass gets a
short spike out along the bisector there (_spiked), which brings it to d / 2.

(Until 2026-12-02 the passes were a variable offset by discs, by Clipper: each next loop the boundary of what was
left once every point within d(p) of the current loops was taken away. On a relief it fell apart into many short
loops: see docs/history/results-log.md "### 3D offset" and this file's history.)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.region_order import Chain
from tmm_workbench.core.footprint.region import edges_of, segment_inside
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.tools.cutter import Cutter

Heights = Callable[[np.ndarray], np.ndarray]   # XY (n, 2) -> CL tip heights (n,)
_SLOPE_GRID_DEG = 5.0  # the rule's step is tabulated every 5 deg and interpolated (concave: under the rule)
_SHARP_RAD = math.radians(20.0)  # turns above this are corners (offset_field.sharpened rebuilds them from contours)


@dataclass
class Loop:
    points: np.ndarray      # (n, 2) XY, closed (last == first), sampled at most sample_step apart
    level: int              # 0: the region's boundary, k: k offsets inward


@dataclass
class OffsetLoops:
    loops: list[Loop] = field(default_factory=list)
    flat_step: float = 0.0   # the rule's step on a plane (mm)
    least_step: float = 0.0  # the smallest XY distance between passes allowed (mm)
    levels: int = 0
    field: Any = None        # offset_field.Field: the arrival field whose level sets the loops are (3D offset)


class StepRule:
    """The XY step for a slope across the loops (deg), by the planar cusp rule, tabulated lazily every
    _SLOPE_GRID_DEG and interpolated linearly (the step falls about as cos(slope), a concave function, so the
    chord lies under it: never wider than the rule)."""

    def __init__(self, cutter: Cutter, cusp: float, max_slope_deg: float) -> None:
        self.cutter, self.cusp, self.max_slope = cutter, cusp, max_slope_deg
        self._table: dict[float, float] = {}
        self.flat = self._at(0.0)

    def _at(self, slope: float) -> float:
        if slope not in self._table:
            self._table[slope] = stepover_for_cusp(self.cutter, self.cusp, slope, 2 * self.cutter.native.max_radius * 0.98)
        return self._table[slope]

    def step(self, slope_deg: np.ndarray) -> np.ndarray:
        s = np.clip(np.nan_to_num(np.asarray(slope_deg, dtype=float), nan=self.max_slope), 0.0, self.max_slope)
        grid = np.unique(np.concatenate([np.arange(0.0, self.max_slope, _SLOPE_GRID_DEG), [self.max_slope]]))
        lo = np.searchsorted(grid, s, side="right") - 1
        lo = np.clip(lo, 0, len(grid) - 1)
        hi = np.minimum(lo + 1, len(grid) - 1)
        out = np.empty(len(s))
        for i in np.unique(np.concatenate([lo, hi])):
            self._at(float(grid[i]))
        a = np.array([self._table[float(grid[i])] for i in lo])
        b = np.array([self._table[float(grid[i])] for i in hi])
        span = np.where(hi > lo, grid[hi] - grid[lo], 1.0)
        t = np.where(hi > lo, (s - grid[lo]) / span, 0.0)
        out[:] = a + (b - a) * t
        out[s <= 0.0] = self.flat  # exactly the planar rule on a flat
        return out


def _closed(p: np.ndarray) -> np.ndarray:
    return np.vstack([p, p[:1]])


def _clean(poly: np.ndarray, tol: float) -> np.ndarray:
    """The polygon without the vertices Clipper's round joins crowd in: those within `tol` mm of their
    neighbours or of the line through them (Clipper's CleanPolygon)."""
    import pyclipper

    ints = polygons._to_int([poly])
    if not ints:
        return poly
    out = pyclipper.CleanPolygon(ints[0], tol * polygons.SCALE)
    return np.asarray(out, dtype=float).reshape(-1, 2) / polygons.SCALE if len(out) >= 3 else poly


def _spiked(loop: np.ndarray, before: list[np.ndarray], sample_step: float) -> np.ndarray:
    """The loop with a spike out of each sharp convex corner along its bisector, toward the loop before (a
    corner clean-up: the erosion keeps corners sharp, and between two loops' corners the point on the bisector
    lies g / (1 + s) from both, g the gap, s = cos(turn / 2): 0.586 g at a right angle). A spike of length
    e = g (1 - s) / (2 s) brings it to g / 2 (the tool goes out and back, dropped like any point). Only the cut
    path has spikes; the next loop is made from the loop without them."""
    p = loop[:-1]
    a = p - np.roll(p, 1, axis=0)
    b = np.roll(p, -1, axis=0) - p
    la, lb = np.hypot(*a.T), np.hypot(*b.T)
    turn = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))  # left: convex (region left)
    sharp = np.flatnonzero((turn > _SHARP_RAD) & (la > 1e-9) & (lb > 1e-9))
    if not len(sharp):
        return loop
    gap, _ = _gaps(p[sharp], before)
    parts, last = [], 0
    for i, g in zip(sharp, gap):
        s = math.cos(min(float(turn[i]), math.radians(150.0)) / 2)
        e = g * (1 - s) / (2 * s)
        out_dir = a[i] / la[i] - b[i] / lb[i]
        out_dir /= max(float(np.hypot(*out_dir)), 1e-300)
        n = max(1, math.ceil(e / sample_step))
        there = p[i] + np.outer(np.arange(1, n + 1) / n, out_dir * e)
        parts += [p[last:i + 1], there, there[-2::-1], p[i:i + 1]]
        last = i + 1
    body = np.vstack(parts + [p[last:]])
    return np.vstack([body, body[:1]])


def _gaps(points: np.ndarray, loops: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Each point's distance to the nearest segment of the closed polylines, and that segment's index in their
    concatenation (in chunks: points x segments)."""
    a = np.vstack([p[:-1] for p in loops])
    ab = np.vstack([p[1:] for p in loops]) - a
    ll = np.maximum((ab * ab).sum(axis=1), 1e-300)
    out, at = np.empty(len(points)), np.empty(len(points), dtype=int)
    chunk = max(1, 2_000_000 // len(a))
    for k in range(0, len(points), chunk):
        p = points[k:k + chunk, None, :]
        t = np.clip(((p - a[None]) * ab[None]).sum(-1) / ll[None], 0.0, 1.0)
        dist = np.hypot(*(a[None] + t[..., None] * ab[None] - p).transpose(2, 0, 1))
        at[k:k + chunk] = dist.argmin(axis=1)
        out[k:k + chunk] = dist[np.arange(len(dist)), at[k:k + chunk]]
    return out, at


def _nearest(loop: np.ndarray, p: np.ndarray) -> tuple[float, int, np.ndarray]:
    """(distance, segment index, point) of the closed polyline `loop`'s nearest point to p."""
    a, b = loop[:-1], loop[1:]
    ab = b - a
    ll = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(((p - a) * ab).sum(axis=1) / ll, 0.0, 1.0)
    q = a + t[:, None] * ab
    d = np.hypot(*(q - p).T)
    i = int(np.argmin(d))
    return float(d[i]), i, q[i]


def _start_at(loop: np.ndarray, i: int, q: np.ndarray) -> np.ndarray:
    """The closed loop re-started at q, which lies on its segment i."""
    body = np.vstack([q, loop[i + 1:-1], loop[:i + 1], q])
    keep = np.concatenate([[True], np.hypot(*np.diff(body, axis=0).T) > 1e-9])
    return body[keep]


def _closed_loop(p: np.ndarray) -> bool:
    return len(p) > 2 and float(np.hypot(*(p[0] - p[-1]))) < 1e-9


def _entry(loop: np.ndarray, p: np.ndarray) -> tuple[float, int, np.ndarray]:
    """Where the tool enters the pass from p: a closed loop at its nearest point (distance, segment, point), an
    open one (the passes beside a start curve, clipped by the region) at its nearer end (segment 0 or -1)."""
    if _closed_loop(loop):
        return _nearest(loop, p)
    a, b = float(np.hypot(*(loop[0] - p))), float(np.hypot(*(loop[-1] - p)))
    return (a, 0, loop[0]) if a <= b else (b, -1, loop[-1])


def _entered(loop: np.ndarray, i: int, q: np.ndarray) -> np.ndarray:
    """The pass cut from its entry (_entry's segment i and point q)."""
    if _closed_loop(loop):
        return _start_at(loop, i, q)
    return loop if i == 0 else loop[::-1]


def loop_chains(result: OffsetLoops, shape: Shape, max_link: float, linked: bool = True) -> list[Chain]:
    """The loops in cutting order, outside in, as region_order chains: after a loop, the nearest loop one
    level further in whose straight link from here stays in the region and is at most `max_link` long (the
    tool stays down; the link is dropped on the surface like any CL point, so it is gouge-free), started at
    its point nearest to here; else the chain ends and the next starts at the nearest loop of the outermost
    level left (a jump: the linker lifts). linked=False: every loop its own chain."""
    edges = edges_of(shape)
    todo = list(range(len(result.loops)))
    chains: list[Chain] = []
    here: Optional[np.ndarray] = None
    while todo:
        pick = None
        if here is not None and linked:
            level = result.loops[chains[-1][-1][2]].level + 1 if chains else 0
            cands = [(_entry(result.loops[k].points, here), k) for k in todo if result.loops[k].level == level]
            for (dist, i, q), k in sorted(cands, key=lambda c: c[0][0]):
                if dist <= max_link and segment_inside(here, q, shape, edges):
                    pick = (k, i, q, np.array([here, q]))
                    break
        if pick is None:
            outer = min(result.loops[k].level for k in todo)
            cands = [k for k in todo if result.loops[k].level == outer]
            if here is None:
                k = cands[0]
                pts = result.loops[k].points
                pick = (k, 0, pts[0], None)
            else:
                best = min(((_entry(result.loops[k].points, here), k) for k in cands), key=lambda c: c[0][0])
                (_, i, q), k = best
                pick = (k, i, q, None)
        k, i, q, link = pick
        loop = _entered(result.loops[k].points, i, q)
        if link is None:
            chains.append([(None, loop, k)])  # type: ignore[list-item]
        else:
            chains[-1].append((link, loop, k))  # type: ignore[arg-type]
        todo.remove(k)
        here = loop[-1]
    return [[(lk, p) for lk, p, _ in ch] for ch in chains]  # type: ignore[misc]
