"""Machining regions: where the 3-axis finishing passes may put the tool in XY.

A region is a core.polygons Shape (outer boundaries counter-clockwise, holes clockwise, non-zero rule) in mm.
It bounds the TOOL CENTRE (the CL point's XY), not the contact point: the tool's side reaches up to its
radius beyond the region's edge, as with FreeCAD's 3D Surface boundary and today's box boundary. A region
meant as "cut only this face" is therefore the face's outline; shrink it by the tool radius first
(polygons.offset) to keep the whole tool inside.

Sources (the App layer turns FreeCAD objects into these, discretised within a tolerance):
  box_region       the rectangle xmin, ymin, xmax, ymax (the stock's or model's box with its margin);
  loops_region     closed loops (a sketch or an edge loop projected along Z), a loop inside an odd number of
                   others is a hole (even-odd nesting), so an inner loop cuts a hole and a loop in that
                   hole an island;
  triangles_region the union of triangles projected along Z (the tessellated faces selected on the model:
                   each face's shadow, whatever its shape; vertical triangles add nothing).
Passes are clipped to the region exactly (clip_line: each crossing of a pass with a region edge solved in
floating point, the inside decided by the winding number).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.polygons import Shape

_MIN_PIECE_MM = 1e-6   # clipped pieces shorter than this are a touch of the boundary, not a pass
_UNION_CHUNK = 2000   # triangles per first union (triangles_region)
_LOOP_CLOSE_MM = 1e-6  # a loop whose last point repeats its first (within this) is closed by it


def box_region(rect: Sequence[float]) -> Shape:
    xmin, ymin, xmax, ymax = (float(v) for v in rect)
    if not (xmax > xmin and ymax > ymin):
        raise TmmError(f"region box is empty: x {xmin:g}..{xmax:g}, y {ymin:g}..{ymax:g}")
    return [polygons.rectangle(xmin, ymin, xmax, ymax)]


def loops_region(loops: Sequence[np.ndarray], name: str = "region") -> Shape:
    """The region bounded by closed XY loops ((n, 2) each, first point not repeated or repeated), holes
    from nesting (see the module doc). TmmError for a loop with no area."""
    clean = []
    for k, loop in enumerate(loops):
        p = np.asarray(loop, dtype=float).reshape(-1, 2)
        if len(p) >= 2 and np.hypot(*(p[-1] - p[0])) <= _LOOP_CLOSE_MM:
            p = p[:-1]
        if len(p) >= 4 and polygons.crosses_itself(p):
            raise TmmError(f"{name}: loop {k + 1} crosses itself seen from above (a figure eight?): a region's "
                           f"loops must not cross; split it into loops that do not")
        if len(p) < 3 or abs(polygons.signed_area(p)) <= 1e-12:
            raise TmmError(f"{name}: loop {k + 1} encloses no area in XY (seen from above it is a line or a "
                           f"point: a vertical loop?)")
        clean.append(p)
    if not clean:
        raise TmmError(f"{name}: no closed loop")
    out = []
    for k, p in enumerate(clean):
        depth = sum(polygons.contains_point([q], p[0]) for j, q in enumerate(clean) if j != k)
        out.append(polygons.oriented(p, depth % 2 == 0))
    shape = polygons.union(out)
    if polygons.area(shape) <= 1e-12:
        raise TmmError(f"{name}: the loops enclose no area")
    return shape


def triangles_region(triangles: np.ndarray, name: str = "faces") -> Shape:
    """The union of (m, 3, 2) XY triangles (the faces' shadow). TmmError when it has no area."""
    t = np.asarray(triangles, dtype=float).reshape(-1, 3, 2)
    a = t[:, 1] - t[:, 0]
    b = t[:, 2] - t[:, 0]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    keep = np.abs(cross) > 1e-12
    if not keep.any():
        raise TmmError(f"{name}: seen from above the selected faces cover no area (vertical faces only?)")
    t = np.where((cross < 0)[:, None, None], t[:, ::-1], t)[keep]  # all counter-clockwise
    # in chunks of neighbours (Morton order of the centroids), then the chunks' outlines pairwise: one union
    # of many triangles costs more than linearly, compact patches have short outlines
    t = t[_morton_order(t.mean(axis=1))]
    parts = [polygons.union(list(t[k:k + _UNION_CHUNK])) for k in range(0, len(t), _UNION_CHUNK)]
    while len(parts) > 1:
        parts = [polygons.union(a, b) for a, b in zip(parts[::2], parts[1::2] + [[]] * (len(parts) % 2))]
    shape = parts[0] if parts else []
    if not shape or polygons.area(shape) <= 1e-12:
        raise TmmError(f"{name}: seen from above the selected faces cover no area (vertical faces only?)")
    return shape


def _morton_order(points: np.ndarray) -> np.ndarray:
    """Indices sorting XY points along a Z-order curve (neighbours stay close in the order)."""
    lo, span = points.min(axis=0), np.ptp(points, axis=0)
    q = ((points - lo) / np.where(span > 0, span, 1.0) * 65535).astype(np.uint64)
    code = np.zeros(len(points), dtype=np.uint64)
    for bit in range(16):
        for axis in (0, 1):
            code |= ((q[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(2 * bit + axis)
    return np.argsort(code, kind="stable")


def check_overlap(shape: Shape, lo: Sequence[float], hi: Sequence[float]) -> None:
    """TmmError when the region does not overlap the model's XY box."""
    if not shape:
        raise TmmError("the machining region is empty")
    box = [polygons.rectangle(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))]
    if polygons.area(polygons.intersection(shape, box)) <= 1e-9:
        x0, y0, x1, y1 = polygons.bounds(shape)
        raise TmmError(f"the machining region (x {x0:.6g}..{x1:.6g}, y {y0:.6g}..{y1:.6g}) does not overlap the "
                       f"model (x {lo[0]:.6g}..{hi[0]:.6g}, y {lo[1]:.6g}..{hi[1]:.6g})")


def edges_of(shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    a = np.vstack([np.asarray(p, dtype=float) for p in shape])
    b = np.vstack([np.roll(np.asarray(p, dtype=float), -1, axis=0) for p in shape])
    return a, b


def clip_line(start: np.ndarray, end: np.ndarray, shape: Shape, edges=None) -> list[np.ndarray]:
    """The pieces of the segment start -> end inside `shape` ((2, 2) each, in the segment's direction and
    order along it). Exact: each crossing with a region edge is solved where it lies, the inside between
    crossings follows the winding number (non-zero rule). A piece along a region edge counts as inside on
    one side of the region only (half-open rule), so callers keep passes off the region's outer edges."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    length = float(np.hypot(*(end - start)))
    if length <= _MIN_PIECE_MM:
        return []
    d = (end - start) / length
    n = np.array([-d[1], d[0]])
    a, b = edges if edges is not None else edges_of(shape)
    sa, sb = (a - start) @ n, (b - start) @ n
    up, ub = sa > 0, sb > 0
    cross = up != ub
    if not cross.any():
        return []
    sa, sb, a, b, ub = sa[cross], sb[cross], a[cross], b[cross], ub[cross]
    w = sa / (sa - sb)
    t = ((a + (b - a) * w[:, None]) - start) @ d
    order = np.argsort(t, kind="stable")
    t, turn = t[order], np.where(ub[order], 1, -1)
    winding = np.cumsum(turn)
    out = []
    for k in range(len(t) - 1):
        if winding[k] != 0:
            t0, t1 = max(t[k], 0.0), min(t[k + 1], length)
            if t1 - t0 > _MIN_PIECE_MM:
                if out and t0 - float((out[-1][1] - start) @ d) <= 1e-12:
                    out[-1][1] = start + t1 * d     # a crossing where the winding stays non-zero: one piece
                else:
                    out.append(np.array([start + t0 * d, start + t1 * d]))
    return out


def segment_inside(a: np.ndarray, b: np.ndarray, shape: Shape, edges=None, tol: float = 1e-6) -> bool:
    """The straight move a -> b stays in the region or on its boundary (within `tol` mm of its length): the
    move, or the move shifted 1e-7 mm to either side (a move along a region edge is on the boundary)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    length = float(np.hypot(*(b - a)))
    if length <= tol:
        return polygons.contains_point(shape, a)
    side = np.array([a[1] - b[1], b[0] - a[0]]) / length * 1e-7
    for shift in (0.0, 1.0, -1.0):
        pieces = clip_line(a + shift * side, b + shift * side, shape, edges)
        if sum(float(np.hypot(*(p[1] - p[0]))) for p in pieces) >= length - tol:
            return True
    return False


def clip_raster(lines: Sequence[np.ndarray], shape: Shape) -> list[list[np.ndarray]]:
    """Each raster pass ((2, 2): start, end) clipped to the region: its pieces in order along it (a pass
    that misses the region gives none)."""
    edges = edges_of(shape)
    return [clip_line(ln[0], ln[1], shape, edges) for ln in lines]


def region_lines(shape: Shape, offsets: np.ndarray, angle_deg: float) -> list[np.ndarray]:
    """Passes at `angle_deg` from +X at the given offsets across (along the normal (-sin, cos)), long enough
    to cross the whole region; the passes on the region's extreme offsets are moved 1e-6 mm inside so they
    are not a pass along an edge (see clip_line), offsets beyond them give no pass."""
    a = math.radians(angle_deg)
    d = np.array([math.cos(a), math.sin(a)])
    n = np.array([-math.sin(a), math.cos(a)])
    pts = np.vstack(shape)
    along, across = pts @ d, pts @ n
    lo, hi = float(across.min()), float(across.max())
    c = np.asarray(offsets, dtype=float)
    c = np.clip(c[(c >= lo - 1e-6) & (c <= hi + 1e-6)], lo + 1e-6, hi - 1e-6)  # passes that miss it: none
    s0, s1 = float(along.min()) - 1.0, float(along.max()) + 1.0
    return [np.array([ci * n + s0 * d, ci * n + s1 * d]) for ci in c]
