"""The constant-scallop "3D offset" pattern (issue 14 item 1, third bullet): closed passes that follow the
machining region's boundary inward, each placed from the previous one so that the cusp between them is the
cusp height on the surface, not on the plane.

The first loop is the region's boundary (it bounds the tool centre, core.footprint.region); holes are loops
too and grow outward. Each next set of loops is the boundary of what is left of the region once every point
within d(p) of the current loops is taken away (an erosion by discs of variable radius): in XY the next loop
lies d(p) from the point p of the current one, whatever the shape, so loops split where the region pinches
and end where it is covered. d(p) is the planar cusp rule (core.footprint.cusp.stepover_for_cusp) for the
slope of the CL surface across the loops at p (the secant over the band the next loop will cover, the
larger of its two halves): on a plane rising at that slope, neighbouring passes d apart in XY leave exactly
the cusp along the normal (for a ball: 3D distance s0, XY distance s0 cos(slope)). Where the CL section across
the loops bends up (concave, curvature k from the same three heights), two balls of radius R at a distance L
leave (1 + R k) times the flat cusp (the ridge of two spheres on a circle of radius 1/k), so d is divided by
sqrt(1 + R k); convex places leave less than the flat rule and keep its step (on the safe side). Above
`max_slope_deg` (walls: waterline's) the slope is held there, and the step never falls below half the rule's
value there (a crease the tool cannot enter would otherwise ask for nothing).

Variable offset, not one uniform offset per loop: a loop that crosses a flat and a slope would otherwise
take the slope's step all round. The erosion is done by Clipper (core.polygons): the loop's segments are
grouped by their distance, rounded down to a grid of 1/`_BUCKETS` of the flat step (never wider than the
rule), each group swept by a disc of its radius (round ends, so neighbouring groups overlap), the sweeps
united and subtracted from the region left. Round ends are chords inside the circle, within `arc_tol` of
it: the XY gap can exceed d by that much (0 on straight edges, where the flat-plate test holds to 1e-6 mm).
A piece narrower than two steps (a strip, a wedge's tip, the middle) gets a last loop half a step in, so
points there lie within d / 2 of a loop too. An erosion keeps a sharp convex corner sharp, and on its bisector
the point between two loops' corners lies d / (1 + sin(half the corner's angle)) from both (0.586 d at a right
angle: 1.37 x the cusp): the cut loop gets a short spike out along the bisector there (_spiked), which brings
it to d / 2. (Shrinking d near corners was tried first: the next loop then has steps that are sharp corners of
their own, and the loops degrade level by level.)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.region_order import Chain, _sample_polyline
from tmm_workbench.core.footprint.region import edges_of, segment_inside
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.tools.cutter import Cutter

Heights = Callable[[np.ndarray], np.ndarray]   # XY (n, 2) -> CL tip heights (n,)
Progress = Callable[[float], bool]
_BUCKETS = 25          # distance grid: the flat step / 25 (4 %), rounded down
_SLOPE_GRID_DEG = 5.0  # the rule's step is tabulated every 5 deg and interpolated (concave: under the rule)
_SHARP_RAD = math.radians(20.0)  # turns above this are corners (Clipper's round joins turn less per vertex)
_MIN_AREA_FRACTION = 1e-4  # left-over pieces smaller than (this x flat step^2) are Clipper's crumbs


@dataclass
class Loop:
    points: np.ndarray      # (n, 2) XY, closed (last == first), sampled at most sample_step apart
    level: int              # 0: the region's boundary, k: k offsets inward


@dataclass
class OffsetLoops:
    loops: list[Loop] = field(default_factory=list)
    flat_step: float = 0.0   # the rule's step on a plane (mm)
    least_step: float = 0.0  # the smallest XY distance used (mm)
    levels: int = 0


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


def least_step(cutter: Cutter, cusp: float, max_slope_deg: float) -> float:
    """The smallest XY distance between loops (the rule at the slope limit): for the work estimate."""
    return StepRule(cutter, cusp, max_slope_deg).step(np.array([max_slope_deg]))[0]


def _pieces(shape: Shape, crumbs: float) -> list[polygons.Region]:
    """The connected pieces of a shape (outer boundary and its holes), without Clipper's crumbs."""
    out = []
    for r in polygons.regions(shape):
        if abs(polygons.signed_area(r.outer)) > crumbs:
            out.append(polygons.Region(r.outer, [h for h in r.holes if abs(polygons.signed_area(h)) > crumbs]))
    return out


def _closed(p: np.ndarray) -> np.ndarray:
    return np.vstack([p, p[:1]])


def _inward_normals(loop: np.ndarray) -> np.ndarray:
    """(n, 2) unit normals to the left of the closed loop's direction at its points (n + 1 rows given, the
    last repeating the first): Clipper's outer boundaries run counter-clockwise and holes clockwise, so the
    region is on the left of both."""
    p = loop[:-1]
    t = np.roll(p, -1, axis=0) - np.roll(p, 1, axis=0)
    t /= np.maximum(np.hypot(*t.T), 1e-300)[:, None]
    n = np.column_stack([-t[:, 1], t[:, 0]])
    return np.vstack([n, n[:1]])


def _across(loop: np.ndarray, heights: Heights, band: float) -> tuple[np.ndarray, np.ndarray]:
    """(n,) the CL surface's slope (deg) across the loop at its points, the larger secant of the two halves of
    the band `band` mm inward (the next loop lies within it), and (n,) its curvature across (1/mm, positive
    where it bends up: concave, a valley) from the same three heights."""
    n = _inward_normals(loop)
    h = 0.5 * band
    probe = np.vstack([loop, loop + h * n, loop + band * n])
    z = heights(probe).reshape(3, len(loop))
    rise = np.maximum(np.abs(z[1] - z[0]), np.abs(z[2] - z[1]))
    grad = (z[2] - z[0]) / band
    curvature = (z[0] - 2 * z[1] + z[2]) / (h * h) / (1 + grad * grad) ** 1.5
    return np.degrees(np.arctan2(rise, h)), curvature


def _clean(poly: np.ndarray, tol: float) -> np.ndarray:
    """The polygon without the vertices Clipper's round joins crowd in: those within `tol` mm of their
    neighbours or of the line through them (Clipper's CleanPolygon)."""
    import pyclipper

    ints = polygons._to_int([poly])
    if not ints:
        return poly
    out = pyclipper.CleanPolygon(ints[0], tol * polygons.SCALE)
    return np.asarray(out, dtype=float).reshape(-1, 2) / polygons.SCALE if len(out) >= 3 else poly


def _running_min(d: np.ndarray, reach: int) -> np.ndarray:
    """d (closed: last == first) replaced by its least value within `reach` points either side round the loop:
    fewer changes of distance along the loop (each costs Clipper a round cap), never a wider step."""
    body = d[:-1]
    out = body.copy()
    for k in range(1, min(reach, len(body) // 2) + 1):
        out = np.minimum(out, np.minimum(np.roll(body, k), np.roll(body, -k)))
    return np.append(out, out[0])


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


def _sweep(loop: np.ndarray, d: np.ndarray, quantum: float, flat: float, arc_tol: float) -> Shape:
    """What discs of radius d (per point, rounded down to the grid) sweep along the closed loop."""
    seg = np.minimum(d[:-1], d[1:])                             # per segment: the smaller end's distance
    q = np.where(seg >= flat, flat, np.floor(seg / quantum) * quantum)
    q = np.maximum(q, quantum)
    out: Shape = []
    if np.all(q == q[0]):
        return polygons.offset_open([loop[:-1]], float(q[0]), arc_tol, closed=True)
    start = int(np.flatnonzero(q != np.roll(q, 1))[0])          # begin where the distance changes
    order = np.roll(np.arange(len(q)), -start)
    groups: dict[float, list[np.ndarray]] = {}
    run = [order[0]]
    for i in order[1:]:
        if q[i] == q[run[-1]]:
            run.append(i)
        else:
            groups.setdefault(float(q[run[0]]), []).append(loop[[*run, run[-1] + 1]])
            run = [i]
    groups.setdefault(float(q[run[0]]), []).append(loop[[*run, run[-1] + 1]])
    for dist, paths in groups.items():
        out.extend(polygons.offset_open(paths, dist, arc_tol))
    return out


def _half(swept: list[tuple[np.ndarray, np.ndarray]], quantum: float, flat: float, arc_tol: float) -> Shape:
    """What discs of half the given distances sweep along the loops."""
    return polygons.union([q for loop, d in swept for q in _sweep(loop, 0.5 * d, 0.5 * quantum, 0.5 * flat, arc_tol)])


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


def _next_pieces(piece: polygons.Region, swept: list[tuple[np.ndarray, np.ndarray]], quantum: float, flat: float,
                 arc_tol: float, crumbs: float, sample_step: float) -> list[polygons.Region]:
    """The region left after this piece's loops (the erosion), with what it would leave uncovered. Where the
    piece is narrower than two steps (a strip, a wedge's tip, the middle at the end) the erosion takes it whole,
    and points in its middle lie up to a step from the loops, not half: that part of the piece (farther than
    half the local step from its loops, and than half the gap from the next ones) gets loops of its own, half
    a step in. Slivers thinner than a fifth of the flat step and specks smaller than a quarter step square
    (by sharp corners, see the module; the rounding of the distances) are left out: there the points lie at
    most about 0.6 of the step from a loop."""
    sweeps = [q for loop, d in swept for q in _sweep(loop, d, quantum, flat, arc_tol)]
    rest_shape = polygons.difference(piece.shape, polygons.union(sweeps))
    rest = _pieces(rest_shape, crumbs)
    # covered: within half the rule's step of this piece's loops or of the next ones (for those, the step of
    # their nearest point on this piece's loops)
    half = polygons.difference(piece.shape, _half(swept, quantum, flat, arc_tol))
    if not rest:
        return _pieces(half, crumbs)
    loops = [loop for loop, _ in swept]
    nominal = np.concatenate([d[:-1] for _, d in swept])
    near = []
    for r in rest:
        for p in r.shape:
            q = _sample_polyline(_closed(_clean(p, arc_tol)), sample_step)
            near.append((q, nominal[_gaps(q, loops)[1]] * (1 + 1e-3)))
    uncovered = polygons.difference(half, polygons.union(rest_shape + _half(near, quantum, flat, arc_tol)))
    eps = 0.1 * flat
    uncovered = polygons.offset(polygons.offset(uncovered, -eps, arc_tol), eps, arc_tol) if uncovered else []
    return rest + [r for r in _pieces(uncovered, crumbs) if r.area > (0.25 * flat) ** 2]


def offset_loops(shape: Shape, heights: Heights, cutter: Cutter, cusp: float, sample_step: float,
                 max_slope_deg: float = 75.0, progress: Optional[Progress] = None,
                 max_levels: int = 100_000) -> OffsetLoops:
    """The loops of the region `shape` (tool-centre region) from its boundary inward (see the module);
    `heights` gives the CL tip heights (the drop) at XY points."""
    if not (math.isfinite(max_slope_deg) and 0 < max_slope_deg < 90):
        raise TmmError(f"cusp slope limit must be in (0, 90) deg, got {max_slope_deg!r}")
    rule = StepRule(cutter, cusp, max_slope_deg)
    flat = rule.flat
    least = float(rule.step(np.array([max_slope_deg]))[0])
    quantum = flat / _BUCKETS
    arc_tol = min(polygons.ARC_TOL, 0.002 * flat)
    crumbs = _MIN_AREA_FRACTION * flat * flat
    left = _pieces(polygons.union(shape), crumbs)
    total = sum(r.area for r in left)
    out = OffsetLoops(flat_step=flat, least_step=flat)
    level = 0
    while left:
        if progress is not None and progress(1.0 - sum(r.area for r in left) / total) is False:
            raise Cancelled("tool path computation cancelled")
        if level >= max_levels:
            raise TmmError(f"3D offset: more than {max_levels} loops")
        nxt: list[polygons.Region] = []
        cut_before = [lp.points for lp in out.loops if lp.level == level - 1]
        for piece in left:  # each connected piece on its own: one may be covered while others go on
            swept: list[tuple[np.ndarray, np.ndarray]] = []
            for p in piece.shape:
                loop = _sample_polyline(_closed(_clean(p, arc_tol)), sample_step)
                out.loops.append(Loop(_spiked(loop, cut_before, sample_step) if cut_before else loop, level))
                slope, curvature = _across(loop, heights, flat)
                # a concave CL section of curvature k leaves (1 + R k) times the flat cusp for the same spacing
                # (a ball of radius R: module doc); the cusp grows as the step squared. Convex places keep the
                # flat rule's step (they leave less: on the safe side)
                concave = 1.0 + cutter.radius * np.clip(curvature, 0.0, None)
                d = np.maximum(rule.step(slope) / np.sqrt(concave), 0.5 * least)
                d = _running_min(d, math.ceil(flat / sample_step))
                out.least_step = min(out.least_step, float(d.min()))
                swept.append((loop, d))
            nxt.extend(_next_pieces(piece, swept, quantum, flat, arc_tol, crumbs, sample_step))
        left = nxt
        level += 1
    out.levels = level
    if not out.loops:
        raise TmmError("3D offset: the machining region has no area to follow")
    return out


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
