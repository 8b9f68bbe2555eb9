"""The 3D offset's passes as level sets of one arrival-time field.

A front leaves the start set (the machining region's boundary, holes included, or a chosen curve, open or
closed) and moves across the CL surface at the speed F(p, u) = the XY step the cusp rule allows at p for passes
crossed along u (core.footprint.offset3d.StepRule: the planar rule at the slope of the CL surface along u,
divided by sqrt(1 + R k) where the CL section along u bends up with curvature k; never below half the rule's
step at the slope limit). Its arrival time T (in steps, |grad T| = 1 / F) is computed by fast marching in the
kernel (native.arrival_field, the direction u taken along grad T at each update) on a grid of CL heights
(`_CELLS_PER_STEP` nodes per flat step), and pass k is the level set {T = k}, contoured by contourpy (Debian's
python3-contourpy, which matplotlib depends on): consecutive passes lie one local step apart everywhere, and a
pass is one long smooth loop that splits only where the region pinches (a distance field has no pieces of its
own, unlike a variable offset by discs, core.footprint.offset3d, which falls apart on a relief).

Pass 0 is the start set itself: the region's polygons, or the curve clipped to the region (the passes are then
offset to both sides of it, and clipped to the region). Where the front ends (a hilltop of T: the middle, a
strip, a wedge's tip) and the last pass k lies more than half a step from the top (T there above k + 1/2), the
half level {T = k + 1/2} is cut there too, so every point lies within half a local step of a pass. On a plane
the speed is the flat step in every direction: T is the distance over the step, exact for straight fronts, and
the passes are the boundary's offsets by k steps (sharp convex corners stay sharp: offset3d._spiked adds the
same short spike out along the bisector as there).

The rule aims under the cusp height (CUSP_AIM) for the field's first-order sampling. Where a corner's contour is
too irregular to rebuild and spike (a bisector meeting a slope's foot) or a hilltop's last loop is a sliver, points
on T's ridges may still lie more than half a step from both levels: those of the half level are checked against the
passes as cut and the uncovered runs cut too (offset_cover.uncovered; on flats, where the XY distance is the cusp rule, and where
fronts meet head on up to a 30 deg slope; the levels a quarter step either side of the half level too).
"""
from __future__ import annotations

import math
from typing import Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core import cancel, polygons
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.offset3d import Heights, Loop, OffsetLoops, StepRule, _closed, _spiked
from tmm_workbench.core.footprint.offset_cover import COVER_LEVELS, meet_nodes, uncovered
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
_CELLS_PER_STEP = 8      # grid nodes per flat step: the contours' positions to first order in the cell
_SLOPE_TABLE = 76        # the rule's step tabulated at this many slopes from 0 to the slope limit (the kernel
                         # interpolates linearly; StepRule itself interpolates a 5 deg table)
_BAND_CELLS = 1.5        # start nodes: within this many cells of the start set (both ends of every cut edge)
_WALK = 0.75            # the half level is cut where T reaches k + 1 within this many local steps (_half_level)
SIMPLIFY = 0.005         # contour vertices within this many flat steps of the chord kept over them go (and within
                         # polygons.ARC_TOL; Douglas-Peucker: the pass moves by at most 0.5 % of the step, the cusp
                         # by 1 %; at 1 % sphere_on_plate's maximum was 0.0101 mm)
_MIN_HALF = 2.0          # half-level pieces shorter than this many flat steps are left out
_PROBE = 0.4            # slope and curvature across from heights this many flat steps either side. At half a flat
                         # step (offset3d's band: 1.5 local steps at 72 deg, where the step moves by tan(slope) = 3 x
                         # the slope's error in rad) seed 000's concave surface read 69.7 deg and R k 0.02 where the
                         # section peaks at 72.3 deg bending up with R k 0.22: passes 0.49 mm apart where the exact
                         # cusp allows 0.44, 1.13 x the tolerance. Not smaller: on a convex flank the larger half
                         # secant is the margin (at 0.3 the dome's 99.9th percentile, test_offset3d, went to 1.03 x)
_BYTES_PER_NODE = 64     # heights, T, masks, the node coordinates and the drop's work arrays
CUSP_AIM = 0.92          # the rule's cusp: this share of the tolerance (the step 4 % narrower for a ball), for
                         # what the field samples only to first order: the marching in its cell, the 0.25 mm
                         # chords along the passes, the slope and curvature as secants over _PROBE of a step
                         # (measured: benchmarks/offset3d_where.py, history/results-log.md "3D offset")
_FIT_REACH = 4.0         # sharpened: each edge fitted over 2 to this many reaches from the corner
_EDGE_TURN = 10.0        # deg: ... as long as it turns by no more than this (not round a short side's corner)


_RULES: dict[tuple, StepRule] = {}


def step_rule(cutter: Cutter, cusp: float, max_slope_deg: float) -> StepRule:
    """The rule for these inputs, tabulated once per process (each entry is a bisection of the planar cusp:
    seconds for the table, the same for every op with this tool and cusp)."""
    key = (cutter.describe(), float(cusp), float(max_slope_deg))
    if key not in _RULES:
        _RULES.clear()
        _RULES[key] = StepRule(cutter, CUSP_AIM * cusp, max_slope_deg)   # aimed under the tolerance (CUSP_AIM)
    return _RULES[key]


def resampled(p: np.ndarray, step: float) -> np.ndarray:
    """The polyline with its vertices kept and points added so that none are more than `step` apart (vectorized
    region_order._sample_polyline: a contour has thousands of short segments)."""
    d = np.diff(p, axis=0)
    n = np.maximum(np.ceil(np.hypot(*d.T) / step - 1e-9).astype(int), 1)
    seg = np.repeat(np.arange(len(d)), n)
    t = (np.arange(len(seg)) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    return np.vstack([p[seg] + t[:, None] * d[seg], p[-1:]])


def simplified(line: np.ndarray, tol: float) -> np.ndarray:
    """The polyline with the vertices dropped that lie within `tol` mm of the chord kept over them (Douglas-Peucker:
    no point of the result is farther than `tol` from the line, nor the other way round). Not Clipper's
    CleanPolygon, which drops each vertex against its current neighbours and so, on a long gently curved contour,
    ate a bulge away vertex by vertex (0.47 mm, 30 % of the step, on seed 000's whole convex surface)."""
    n = len(line)
    if n < 3:
        return line
    keep = np.zeros(n, dtype=bool)
    keep[[0, -1]] = True
    stack = [(0, n - 1)]
    while stack:
        a, b = stack.pop()
        if b <= a + 1:
            continue
        d = line[a + 1:b] - line[a]
        chord = line[b] - line[a]
        length = float(np.hypot(*chord))
        off = (np.abs(d[:, 0] * chord[1] - d[:, 1] * chord[0]) / length if length > 1e-12 else np.hypot(*d.T))
        i = int(np.argmax(off))
        if off[i] > tol:
            keep[a + 1 + i] = True
            stack += [(a, a + 1 + i), (a + 1 + i, b)]
    return line[keep]


def simplified_ring(ring: np.ndarray, tol: float) -> np.ndarray:
    """simplified() for a closed ring (first point not repeated): split at its first point and the vertex farthest
    from it."""
    if len(ring) < 4:
        return ring
    far = int(np.argmax(np.hypot(*(ring - ring[0]).T)))
    if far == 0:
        return ring
    a = simplified(ring[:far + 1], tol)
    b = simplified(np.vstack([ring[far:], ring[:1]]), tol)
    return np.vstack([a, b[1:-1]])


def _fitted_line(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares line of the points (at least two): its centroid and unit direction, oriented from the
    first point toward the last."""
    c = pts.mean(axis=0)
    q = pts - c
    d = np.linalg.eigh(q.T @ q)[1][:, -1] if len(pts) > 2 else q[-1] - q[0]
    d = d / max(float(np.hypot(*d)), 1e-300)
    return c, (d if float(d @ (pts[-1] - pts[0])) >= 0 else -d)


def _straight(turn: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """The leading vertices of `idx` (walked away from a corner) before the turns past its first add up to more
    than _EDGE_TURN either way (the next corner of a short side), at least two."""
    if len(idx) < 3:
        return idx
    bend = np.maximum.accumulate(np.abs(np.cumsum(turn[idx[1:-1]])))
    return idx[:max(2, 2 + int(np.searchsorted(bend, math.radians(_EDGE_TURN), side="right")))]


def sharpened(loop: np.ndarray, reach: float) -> np.ndarray:
    """The closed loop with its contoured corners made sharp again. At a convex corner's bisector T has a ridge
    (two fronts meet), where first-order fast marching solves across the ridge (T a little low there) and the
    contour cuts the corner over a few cells: the left turns within `reach` mm either side of a vertex add up to
    more than offset3d's sharp turn. The vertices there are replaced by the crossing of the edges either side,
    the corner the exact offset has, so that offset3d._spiked sees it. Each edge is the least-squares line of the
    contour's vertices 2 to _FIT_REACH reaches from the corner: the line through two vertices a cell apart,
    extrapolated several times their spacing, amplified the contour's first-order wobble (seed 000's convex
    surface: a corner 0.14 mm out, 1.07 x half a step from the next pass, 2 % over the cusp)."""
    from tmm_workbench.core.footprint.offset3d import _SHARP_RAD

    p = loop[:-1]
    n = len(p)
    if n < 12:
        return loop
    a = p - np.roll(p, 1, axis=0)
    b = np.roll(p, -1, axis=0) - p
    turn = np.arctan2(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], (a * b).sum(axis=1))
    length = np.hypot(*b.T)
    per = float(length.sum())
    if per <= 8 * reach:
        return loop
    s3 = np.concatenate([[0.0], np.cumsum(np.tile(length, 3))])[:-1]   # arc length over three turns of the loop
    t3 = np.concatenate([[0.0], np.cumsum(np.tile(turn, 3))])
    mid = s3[n:2 * n]
    lo = np.searchsorted(s3, mid - reach, side="left")
    hi = np.searchsorted(s3, mid + reach, side="right")
    window = t3[hi] - t3[lo]                                             # turns within +-reach of each vertex
    corner: dict[int, np.ndarray] = {}
    taken = np.zeros(n, dtype=bool)
    at = lambda d: np.searchsorted(s3, mid + d, side="left")  # noqa: E731 (vertex indices at arc offsets)
    run_lo, run_hi = at(-2 * reach), at(2 * reach)
    in_lo, out_hi = at(-_FIT_REACH * reach), at(_FIT_REACH * reach)
    for i in np.argsort(-window):
        if window[i] <= _SHARP_RAD:
            break
        run = np.arange(run_lo[i], run_hi[i]) % n    # replaced: the smeared stretch, clear of the ridge's reach
        if taken[run].any() or turn[np.arange(lo[i], hi[i]) % n].min() < -math.radians(1.0):
            continue
        edge_in = p[_straight(turn, np.arange(run_lo[i] - 1, in_lo[i] - 1, -1) % n)][::-1]   # the edge coming in,
        edge_out = p[_straight(turn, np.arange(run_hi[i], out_hi[i] + 1) % n)]              # the one going out
        if len(edge_in) < 2 or len(edge_out) < 2:
            continue
        (p0, d1), (q0, d2) = _fitted_line(edge_in), _fitted_line(edge_out)
        den = d1[0] * d2[1] - d1[1] * d2[0]
        if abs(den) < 1e-12:
            continue
        t = ((q0[0] - p0[0]) * d2[1] - (q0[1] - p0[1]) * d2[0]) / den
        x = p0 + t * d1
        # the corner ahead of the edge coming in and before the one going out, near the smeared one
        if t <= 0 or float((q0 - x) @ d2) <= 0 or float(np.hypot(*(x - p[i]))) > 2 * reach:
            continue
        taken[run] = True
        corner[int(run[0])] = x
    if not corner:
        return loop
    keep = ~taken
    for k in corner:
        keep[k] = True
    out = np.array([corner.get(k, p[k]) for k in range(n) if keep[k]])
    return np.vstack([out, out[:1]])


def grid_cell(flat_step: float) -> float:
    """The field's node spacing (mm) for the rule's flat step."""
    return flat_step / _CELLS_PER_STEP


def field_box(shape: Shape, start: Optional[Sequence[np.ndarray]] = None) -> tuple[float, float, float, float]:
    """The field's box: the region's, and the start curves' (the passes beside a curve are offsets of all of it,
    its parts outside the region too; a grid that ended at the region's edge would make T there from one side
    only, and that error would run along the passes into the region)."""
    x0, y0, x1, y1 = polygons.bounds(shape)
    for c in start or ():
        c = np.asarray(c, float)
        x0, y0 = min(x0, float(c[:, 0].min())), min(y0, float(c[:, 1].min()))
        x1, y1 = max(x1, float(c[:, 0].max())), max(y1, float(c[:, 1].max()))
    return x0, y0, x1, y1


def node_count(shape: Shape, flat_step: float, start: Optional[Sequence[np.ndarray]] = None) -> float:
    """Nodes of the field's grid over field_box (for the work estimate, before any is allocated)."""
    x0, y0, x1, y1 = field_box(shape, start)
    cell = grid_cell(flat_step)
    return (math.ceil((x1 - x0) / cell) + 6) * (math.ceil((y1 - y0) / cell) + 6)


def _band(curves: Sequence[np.ndarray], xs: np.ndarray, ys: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Distance (mm) from each grid node within `reach` of the polylines to the nearest of their segments
    (inf elsewhere), and that segment's unit normal there ((ny, nx, 2))."""
    dist = np.full((len(ys), len(xs)), np.inf)
    normal = np.zeros((len(ys), len(xs), 2))
    x0, cell = xs[0], xs[1] - xs[0]
    y0 = ys[0]
    for c in curves:
        for a, b in zip(c[:-1], c[1:]):
            ab = b - a
            ll = float(ab @ ab)
            if ll <= 0:
                continue
            i0 = max(int(math.floor((min(a[0], b[0]) - reach - x0) / cell)), 0)
            i1 = min(int(math.ceil((max(a[0], b[0]) + reach - x0) / cell)) + 1, len(xs))
            j0 = max(int(math.floor((min(a[1], b[1]) - reach - y0) / cell)), 0)
            j1 = min(int(math.ceil((max(a[1], b[1]) + reach - y0) / cell)) + 1, len(ys))
            if i0 >= i1 or j0 >= j1:
                continue
            px, py = np.meshgrid(xs[i0:i1], ys[j0:j1])
            t = np.clip(((px - a[0]) * ab[0] + (py - a[1]) * ab[1]) / ll, 0.0, 1.0)
            d = np.hypot(a[0] + t * ab[0] - px, a[1] + t * ab[1] - py)
            win = d < dist[j0:j1, i0:i1]
            dist[j0:j1, i0:i1][win] = d[win]
            n = np.array([-ab[1], ab[0]]) / math.sqrt(ll)
            normal[j0:j1, i0:i1][win] = n
    dist[dist > reach] = np.inf
    return dist, normal


class Field:
    """The arrival-time field over a grid: T (ny, nx) at nodes (xs[i], ys[j]), in steps."""

    def __init__(self, xs: np.ndarray, ys: np.ndarray, t: np.ndarray,
                 steps: Optional[Callable[[np.ndarray, np.ndarray, float], np.ndarray]] = None) -> None:
        self.xs, self.ys, self.t = xs, ys, t
        self.probe = 0.0        # mm: the probe the marching took the slope and curvature over
        self.flat_step = 0.0    # mm: the rule's step on a plane (one unit of T there)
        self.slope: Optional[np.ndarray] = None   # (ny, nx) the CL surface's slope (deg) at the nodes
        self.steps = steps      # (xy, u, probe) -> the speed's step (mm) at XY points for fronts along u, the
                                # slope and curvature from heights `probe` mm either side (the kernel's)
        self._gen = None
        self._grad: Optional[list[np.ndarray]] = None

    def lines(self, level: float) -> list[np.ndarray]:
        """The level set {T = level} as polylines (closed ones repeat their first point; higher T on their left:
        contourpy's orientation)."""
        if self._gen is None:
            import contourpy

            self._gen = contourpy.contour_generator(self.xs, self.ys, np.ma.masked_invalid(self.t),
                                                    line_type="Separate")
        return [np.asarray(p, float) for p in self._gen.lines(level) if len(p) >= 2]

    def at(self, xy: np.ndarray, values: Optional[np.ndarray] = None) -> np.ndarray:
        """Bilinear T (or `values` on the same grid) at XY points (NaN off the grid; inf where a corner is)."""
        v = self.t if values is None else values
        cell = self.xs[1] - self.xs[0]
        fx, fy = (xy[:, 0] - self.xs[0]) / cell, (xy[:, 1] - self.ys[0]) / cell
        off = (fx < 0) | (fy < 0) | (fx > len(self.xs) - 1) | (fy > len(self.ys) - 1)
        i = np.clip(fx.astype(int), 0, len(self.xs) - 2)
        j = np.clip(fy.astype(int), 0, len(self.ys) - 2)
        a, b = np.clip(fx - i, 0, 1), np.clip(fy - j, 0, 1)
        with np.errstate(invalid="ignore"):
            out = ((1 - b) * ((1 - a) * v[j, i] + a * v[j, i + 1]) + b * ((1 - a) * v[j + 1, i] + a * v[j + 1, i + 1]))
        out[off] = np.nan
        return out

    def gradient(self, xy: np.ndarray) -> np.ndarray:
        """(n, 2) grad T at XY points (central differences on the grid, bilinear; NaN beside unreached nodes)."""
        if self._grad is None:
            cell = self.xs[1] - self.xs[0]
            t = np.where(np.isfinite(self.t), self.t, np.nan)
            self._grad = np.gradient(t, cell)   # d/dy (rows), d/dx (columns)
        gy, gx = self._grad
        return np.column_stack([self.at(xy, gx), self.at(xy, gy)])


def arrival(shape: Shape, heights: Heights, cutter: Cutter, cusp: float, max_slope_deg: float,
            start: Optional[Sequence[np.ndarray]] = None) -> tuple[Field, StepRule]:
    """The field over the region `shape` from its boundary (start None) or from the polylines `start`."""
    from tmm_workbench.core.kernel import native

    rule = step_rule(cutter, cusp, max_slope_deg)
    flat = rule.flat
    least = float(rule.step(np.array([max_slope_deg]))[0])
    cell = grid_cell(flat)
    if start is not None and not polygons.clip_open(list(start), polygons.offset(shape, 2 * cell)):
        raise TmmError("3D offset start curve: it lies outside the machining region (no point of it within "
                       f"{2 * cell:.3g} mm of the region)")
    count = node_count(shape, flat, start)
    check_work("field nodes", count, _BYTES_PER_NODE,
               f"3D offset: cusp height {cusp:g} mm (flat step {flat:.3g} mm, field cell {cell:.3g} mm) over the "
               f"{polygons.area(shape):.6g} mm^2 region and the start curve's box", )
    x0, y0, x1, y1 = field_box(shape, start)
    xs = x0 - 3 * cell + cell * np.arange(math.ceil((x1 - x0) / cell) + 7)
    ys = y0 - 3 * cell + cell * np.arange(math.ceil((y1 - y0) / cell) + 7)
    gx, gy = np.meshgrid(xs, ys)
    z = np.asarray(heights(np.column_stack([gx.ravel(), gy.ravel()])), float).reshape(gx.shape)
    reach = _BAND_CELLS * cell
    if start is None:
        inside = polygons.grid_inside(shape, xs, ys)
        active = inside
        dist, normal = _band([_closed(np.asarray(p, float)) for p in shape], xs, ys, reach)
        dist = np.where(inside, dist, -dist)       # outside: before the start (negative T)
    else:
        active = np.ones(z.shape, dtype=bool)
        dist, normal = _band([np.asarray(c, float) for c in start], xs, ys, reach)
    slopes = np.linspace(0.0, max_slope_deg, _SLOPE_TABLE)
    steps = rule.step(slopes)
    args = dict(steps=steps, dslope=math.radians(slopes[1]), radius=float(cutter.radius), probe=_PROBE * flat,
                min_step=0.5 * least)
    band = np.isfinite(dist)
    t0 = np.full(z.shape, np.nan)
    if band.any():
        f = native.arrival_steps(z, cell, np.column_stack([gx[band] - xs[0], gy[band] - ys[0]]), normal[band], **args)
        t0[band] = dist[band] / f
    t = cancel.native_call(native.arrival_field, z, cell, active.astype(np.uint8), t0, **args)
    origin = np.array([xs[0], ys[0]])

    def steps_at(xy: np.ndarray, u: np.ndarray, probe: float) -> np.ndarray:
        return native.arrival_steps(z, cell, np.asarray(xy, float) - origin, np.asarray(u, float),
                                    **dict(args, probe=probe))

    field = Field(xs, ys, t, steps_at)
    field.probe, field.flat_step = args["probe"], flat
    dz_dy, dz_dx = np.gradient(z, cell)
    field.slope = np.degrees(np.arctan(np.hypot(dz_dx, dz_dy)))
    return field, rule


def _half_level(field: Field, k: int) -> list[np.ndarray]:
    """The pieces of {T = k + 1/2} where pass k + 1 does not come within half a local step: a hilltop of T that
    level k + 1 does not reach, and a ridge (a strip's middle, where two fronts meet below k + 1). From each point
    of the half level, a walk of _WALK local steps up the gradient of T, or 45 deg from it, must reach T >= k + 1
    (on a convex corner's bisector pass k + 1's corner lies sqrt(2) / 2 of a step from the half level, and its
    spike covers the rest); where none does (T falls again beyond the ridge, or the top is below k + 1), the
    point is more than half a step from both passes and the half level is cut there."""
    out = []
    for line in field.lines(k + 0.5):
        g = field.gradient(line)
        norm2 = (g * g).sum(axis=1)
        ok = np.isfinite(norm2) & (norm2 > 0)
        walk = np.where(ok[:, None], _WALK * g / np.where(ok, norm2, 1.0)[:, None], 0.0)
        reached = np.zeros(len(line), dtype=bool)
        for turn in (0.0, math.pi / 4, -math.pi / 4):  # up the gradient, and along a convex corner's bisector
            c, s_ = math.cos(turn), math.sin(turn)
            w = np.column_stack([c * walk[:, 0] - s_ * walk[:, 1], s_ * walk[:, 0] + c * walk[:, 1]])
            with np.errstate(invalid="ignore"):
                reached |= field.at(line + w) >= k + 1
        need = ok & ~reached
        closed = len(line) > 3 and np.allclose(line[0], line[-1])
        if need.all():
            out.append(line)
            continue
        if not need.any():
            continue
        body = line[:-1] if closed else line
        flag = need[:-1] if closed else need
        if closed:  # start the walk where a run begins, so that no run is split by the loop's start
            first = int(np.flatnonzero(flag & ~np.roll(flag, 1))[0])
            body, flag = np.roll(body, -first, axis=0), np.roll(flag, -first)
        edges = np.flatnonzero(np.diff(np.concatenate([[0], flag.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            lo, hi = max(a - 1, 0), min(b + 1, len(body))   # one point beyond either end: the runs overlap
            if hi - lo >= 2:
                out.append(body[lo:hi])
    return out


def field_loops(shape: Shape, heights: Heights, cutter: Cutter, cusp: float, sample_step: float,
                max_slope_deg: float = 75.0, start: Optional[Sequence[np.ndarray]] = None,
                progress: Optional[Progress] = None) -> OffsetLoops:
    """The passes of the region `shape` (tool-centre region) as level sets of the arrival field (see the
    module), from its boundary (start None) or from the polylines `start` (XY, open or closed; the passes go to
    both sides); `heights` gives the CL tip heights (the drop) at XY points."""
    if not (math.isfinite(max_slope_deg) and 0 < max_slope_deg < 90):
        raise TmmError(f"cusp slope limit must be in (0, 90) deg, got {max_slope_deg!r}")
    field, rule = arrival(shape, heights, cutter, cusp, max_slope_deg, start)
    flat = rule.flat
    arc_tol = min(polygons.ARC_TOL, SIMPLIFY * flat)
    finite = field.t[np.isfinite(field.t)]
    top = float(finite.max()) if len(finite) else 0.0
    levels = int(math.floor(top))
    out = OffsetLoops(flat_step=flat, least_step=flat, field=field)
    out.least_step = float(rule.step(np.array([max_slope_deg]))[0]) * 0.5

    def keep(lines: list[np.ndarray]) -> list[np.ndarray]:
        if start is None:
            return lines
        clipped = []
        for line in lines:  # the passes beside a curve run to the region's edge and stop there
            clipped.extend(polygons.clip_open([line], shape))
        return clipped

    def add(line: np.ndarray, level: int, before: list[np.ndarray]) -> Optional[np.ndarray]:
        """Pass `line` at `level` appended as cut (spiked, resampled); that polyline, None if left out."""
        closed = len(line) > 3 and np.hypot(*(line[0] - line[-1])) < 1e-9
        if closed:
            ring = simplified_ring(sharpened(line, 2 * grid_cell(flat))[:-1], arc_tol)
            if len(ring) < 3:
                return None
            loop = resampled(_closed(ring), sample_step)
            # contourpy puts higher T on a line's left: the region still to cut, as offset3d's loops have it
            spike = before and start is None  # (clip_open does not keep a direction: no spikes beside a curve)
            out.loops.append(Loop(_spiked(loop, before, sample_step) if spike else loop, level))
        elif len(line) >= 2 and float(np.hypot(*np.diff(line, axis=0).T).sum()) > 1e-6:
            out.loops.append(Loop(resampled(line, sample_step), level))
        else:
            return None
        return out.loops[-1].points

    if start is None:
        previous = [_closed(np.asarray(p, float)) for p in shape]
        for p in previous:
            out.loops.append(Loop(resampled(p, sample_step), 0))
        cut_before = [lp.points for lp in out.loops]
    else:
        previous = keep([np.asarray(c, float) for c in start])
        if not previous:
            raise TmmError("3D offset start curve: it lies outside the machining region")
        cut_before = [c for c in (add(p, 0, []) for p in previous) if c is not None]
    meets = meet_nodes(field)
    for k in range(1, levels + 2):
        if progress is not None and progress(min(k / max(levels, 1), 1.0)) is False:
            raise Cancelled("tool path computation cancelled")
        current = keep(field.lines(float(k))) if k <= levels else []
        # (pieces shorter than half a flat step are left out: the points they would serve lie within a few
        # hundredths of a step more than half a step from the passes)
        caps = [c for c in keep(_half_level(field, k - 1)) if float(np.hypot(*np.diff(c, axis=0).T).sum()) > _MIN_HALF * flat]
        cut = [c for c in (add(line, k, previous) for line in current + caps) if c is not None]
        # the half level's points on a ridge of T still farther than half a local step from both levels as cut
        quarter = bool(np.any(meets & (field.t > k - 1) & (field.t < k)))   # (contouring costs: only where needed)
        for line in (ln for d in COVER_LEVELS if d == 0.5 or quarter
                     for ln in keep(uncovered(field, k - d, cut_before + cut, flat, meet_only=d != 0.5))):
            c = add(line, k, [])
            if c is not None:
                cut.append(c)
        previous = current + caps if current or caps else previous
        cut_before = cut if cut else cut_before
    out.levels = max(lp.level for lp in out.loops) + 1
    if not out.loops:
        raise TmmError("3D offset: the machining region has no area to follow")
    return out
