"""The one polygon module: offsets and booleans of XY polygons by Clipper 6 (Debian's python3-pyclipper).

Polygons are (n, 2) float arrays in mm, closed implicitly; a *shape* is a list of them read with the
non-zero fill rule (outer boundaries counter-clockwise, holes clockwise, as Clipper returns them). Clipper
works on integers: coordinates are scaled by SCALE (1 unit = 1 nm) here and nowhere else.

Round joins everywhere (an offset of a polygon by a disc is what a cutter of that radius sweeps); arcs are
split into chords within `arc_tol` mm (ARC_TOL by default) of the true circle, the chords lying inside it
(Clipper's round joins), so an inward offset is never wider than the exact one by more than `arc_tol`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError

SCALE = 1e6          # Clipper integer units per mm
ARC_TOL = 0.005      # mm: chord deviation of round joins unless given
Shape = list[np.ndarray]


def _to_int(paths: Iterable[np.ndarray]) -> list[list[tuple[int, int]]]:
    out = []
    for p in paths:
        a = np.asarray(p, dtype=float).reshape(-1, 2)
        if len(a) >= 2:
            out.append([(int(x), int(y)) for x, y in np.rint(a * SCALE)])
    return out


def _from_int(paths: Iterable[Sequence[Sequence[int]]]) -> Shape:
    return [np.asarray(p, dtype=float).reshape(-1, 2) / SCALE for p in paths if len(p) >= 3]


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area, mm^2: positive counter-clockwise."""
    p = np.asarray(poly, dtype=float).reshape(-1, 2)
    if len(p) < 3:
        return 0.0
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def area(shape: Shape) -> float:
    """Area of a shape (outer boundaries minus holes, as oriented by Clipper), mm^2."""
    return float(sum(signed_area(p) for p in shape))


def crosses_itself(poly: np.ndarray) -> bool:
    """True when the closed loop's edges cross (a figure eight, a bow tie): Clipper splits such a loop into
    several, or its simple pieces' area differs from the loop's signed area."""
    ints = _to_int([poly])
    if not ints or len(ints[0]) < 4:
        return False
    pieces = _clipper().SimplifyPolygon(ints[0], _clipper().PFT_NONZERO)
    if len(pieces) != 1:
        return True
    simple = abs(signed_area(np.asarray(pieces[0], dtype=float) / SCALE))
    return abs(simple - abs(signed_area(poly))) > 1e-6 * max(simple, 1.0)


def is_ccw(poly: np.ndarray) -> bool:
    return bool(_clipper().Orientation(_to_int([poly])[0]))


def oriented(poly: np.ndarray, ccw: bool) -> np.ndarray:
    """`poly` counter-clockwise (ccw True) or clockwise."""
    return poly if (signed_area(poly) > 0) == ccw else poly[::-1].copy()


def _clipper():
    """pyclipper, imported on first use: a FreeCAD without it still loads the workbench and every document,
    and only roughing says what is missing."""
    try:
        import pyclipper
    except ImportError as exc:
        raise TmmError("polygon clipping needs pyclipper (Clipper 6): install Debian's python3-pyclipper, or "
                       "`python3 -m pip install pyclipper` for the Python FreeCAD runs") from exc
    return pyclipper


def _offsetter(arc_tol: float):
    return _clipper().PyclipperOffset(2.0, arc_tol * SCALE)


def offset(shape: Shape, delta: float, arc_tol: float = ARC_TOL, miter: bool = False) -> Shape:
    """The shape grown by `delta` mm (negative: shrunk; an erosion by a disc), round joins; miter=True:
    mitred joins (limit 2: corners sharper than 60 degrees squared off), which contain the round ones and
    add no points (for small safety growths)."""
    paths = _to_int(shape)
    if not paths:
        return []
    if delta == 0:
        return union(shape)
    o = _offsetter(arc_tol)
    o.AddPaths(paths, _clipper().JT_MITER if miter else _clipper().JT_ROUND, _clipper().ET_CLOSEDPOLYGON)
    return _from_int(o.Execute(delta * SCALE))


def offset_open(paths: Sequence[np.ndarray], delta: float, arc_tol: float = ARC_TOL,
                closed: bool = False) -> Shape:
    """What a disc of radius `delta` sweeps along open polylines (round ends), or along closed loops
    (closed=True: the band either side of each loop)."""
    ints = _to_int(paths)
    if not ints or delta <= 0:
        return []
    o = _offsetter(arc_tol)
    o.AddPaths(ints, _clipper().JT_ROUND, _clipper().ET_CLOSEDLINE if closed else _clipper().ET_OPENROUND)
    return _from_int(o.Execute(delta * SCALE))


def _boolean(subject: Shape, clip: Shape, op: int) -> Shape:
    s, c = _to_int(subject), _to_int(clip)
    if not s and op != _clipper().CT_UNION:
        return []
    pc = _clipper().Pyclipper()
    if s:
        pc.AddPaths(s, _clipper().PT_SUBJECT, True)
    if c:
        pc.AddPaths(c, _clipper().PT_CLIP, True)
    if not s and not c:
        return []
    return _from_int(pc.Execute(op, _clipper().PFT_NONZERO, _clipper().PFT_NONZERO))


def union(a: Shape, b: Shape = ()) -> Shape:  # type: ignore[assignment]
    """Union (also: one shape cleaned into non-overlapping, oriented boundaries)."""
    return _boolean(list(a) + list(b), [], _clipper().CT_UNION)


def difference(a: Shape, b: Shape) -> Shape:
    return _boolean(a, b, _clipper().CT_DIFFERENCE) if b else union(a)


def intersection(a: Shape, b: Shape) -> Shape:
    return _boolean(a, b, _clipper().CT_INTERSECTION)


_OPEN_BATCH = 100  # open paths per Clipper sweep (5,000 at once: 5x slower than in batches of 100)


def clip_open(paths: Sequence[np.ndarray], shape: Shape) -> list[np.ndarray]:
    """The pieces of open polylines that lie inside `shape` ((n, 2) each, in their own direction or
    reversed: Clipper does not keep the direction of open paths)."""
    ints, c = _to_int(paths), _to_int(shape)
    if not ints or not c:
        return []
    out: list[np.ndarray] = []
    for k in range(0, len(ints), _OPEN_BATCH):  # the same pieces; one sweep over thousands of paths costs more
        pc = _clipper().Pyclipper()
        for p in ints[k:k + _OPEN_BATCH]:
            pc.AddPath(p, _clipper().PT_SUBJECT, False)
        pc.AddPaths(c, _clipper().PT_CLIP, True)
        tree = pc.Execute2(_clipper().CT_INTERSECTION, _clipper().PFT_NONZERO, _clipper().PFT_NONZERO)
        out.extend(np.asarray(p, dtype=float).reshape(-1, 2) / SCALE
                   for p in _clipper().OpenPathsFromPolyTree(tree) if len(p) >= 2)
    return out


def segment_inside(a: np.ndarray, b: np.ndarray, shape: Shape, tol: float = 1e-6) -> bool:
    """The straight segment a -> b lies in `shape` (within `tol` mm of its length)."""
    length = float(np.hypot(*(np.asarray(b, float) - np.asarray(a, float))))
    if length <= tol:
        return contains_point(shape, a)
    inside = clip_open([np.array([a, b], dtype=float)], shape)
    return sum(float(np.hypot(*np.diff(p, axis=0).T).sum()) for p in inside) >= length - tol


def contains_point(shape: Shape, point: Sequence[float]) -> bool:
    """`point` inside the shape or on its boundary (non-zero rule over all its polygons)."""
    q = (int(round(point[0] * SCALE)), int(round(point[1] * SCALE)))
    winding = 0
    for p in _to_int(shape):
        r = _clipper().PointInPolygon(q, p)
        if r == -1:
            return True
        if r == 1:
            winding += 1 if _clipper().Orientation(p) else -1
    return winding != 0


def grid_inside(shape: Shape, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """(len(ys), len(xs)) bool: the grid nodes inside the shape (even-odd rule, one scanline per row: the
    shapes here are Clipper's, outer boundaries and holes that do not overlap)."""
    a = np.vstack([np.asarray(p, float) for p in shape])
    b = np.vstack([np.roll(np.asarray(p, float), -1, axis=0) for p in shape])
    out = np.zeros((len(ys), len(xs)), dtype=bool)
    for j, y in enumerate(ys):
        cross = (a[:, 1] > y) != (b[:, 1] > y)
        if not cross.any():
            continue
        pa, pb = a[cross], b[cross]
        xc = np.sort(pa[:, 0] + (y - pa[:, 1]) * (pb[:, 0] - pa[:, 0]) / (pb[:, 1] - pa[:, 1]))
        count = np.searchsorted(xc, xs, side="right")
        out[j] = count % 2 == 1
    return out


def points_inside(shape: Shape, xy: np.ndarray) -> np.ndarray:
    """(n,) bool: the points (n, 2) inside the shape (even-odd rule, as grid_inside), vectorised over the
    points, one edge at a time."""
    xy = np.asarray(xy, float).reshape(-1, 2)
    x, y = xy[:, 0], xy[:, 1]
    out = np.zeros(len(xy), dtype=bool)
    for p in shape:
        a = np.asarray(p, float)
        b = np.roll(a, -1, axis=0)
        for (xa, ya), (xb, yb) in zip(a, b):
            if ya == yb:
                continue
            crosses = (ya > y) != (yb > y)
            out ^= crosses & (x < xa + (y - ya) * (xb - xa) / (yb - ya))
    return out


def covers(outer: Shape, inner: Shape, tol_area: float = 1e-6) -> bool:
    """`inner` lies in `outer` (what sticks out is below `tol_area` mm^2)."""
    return area(difference(inner, outer)) <= tol_area


def rectangle(xmin: float, ymin: float, xmax: float, ymax: float) -> np.ndarray:
    return np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]], dtype=float)


def circle(centre: Sequence[float], radius: float, chord_tol: float = ARC_TOL) -> np.ndarray:
    """A counter-clockwise polygon inscribed in the circle with sagitta at most `chord_tol`."""
    n = max(8, math.ceil(math.pi / math.acos(max(-1.0, 1.0 - chord_tol / radius)))) if radius > chord_tol else 8
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    return np.column_stack([centre[0] + radius * np.cos(t), centre[1] + radius * np.sin(t)])


@dataclass
class Region:
    """One connected piece of a shape: its outer boundary (counter-clockwise) and holes (clockwise)."""
    outer: np.ndarray
    holes: list[np.ndarray] = field(default_factory=list)

    @property
    def shape(self) -> Shape:
        return [self.outer, *self.holes]

    @property
    def area(self) -> float:
        return area(self.shape)


def regions(shape: Shape) -> list[Region]:
    """The connected pieces of a shape (Clipper's PolyTree: each outer boundary with its own holes; an
    island inside a hole is a piece of its own)."""
    ints = _to_int(shape)
    if not ints:
        return []
    pc = _clipper().Pyclipper()
    pc.AddPaths(ints, _clipper().PT_SUBJECT, True)
    tree = pc.Execute2(_clipper().CT_UNION, _clipper().PFT_NONZERO, _clipper().PFT_NONZERO)
    out: list[Region] = []

    def walk(node) -> None:
        for child in node.Childs:
            if not child.IsHole:
                holes = [np.asarray(h.Contour, float).reshape(-1, 2) / SCALE for h in child.Childs
                         if len(h.Contour) >= 3]
                if len(child.Contour) >= 3:
                    out.append(Region(np.asarray(child.Contour, float).reshape(-1, 2) / SCALE, holes))
                for h in child.Childs:
                    walk(h)

    walk(tree)
    return out


def bounds(shape: Shape) -> tuple[float, float, float, float]:
    pts = np.vstack(shape)
    return float(pts[:, 0].min()), float(pts[:, 1].min()), float(pts[:, 0].max()), float(pts[:, 1].max())


def point_count(shape: Shape) -> int:
    return int(sum(len(p) for p in shape))
