"""Pencil and multi-pencil footprints: the XY curves a small tool follows along concave creases, dropped like any
pattern's points (core.strategies.surface: positioning, segments, linking).

Three sources of curves:
  outline  seed 003's pencil (section 4.5): the outline of lettering or a logo from the drawing (closed loops,
           inner loops are holes) offset by the cutter radius to the side the tool runs (outside: around raised
           letters, at the foot of their walls; inside: within engraved ones); open curves to both sides;
  file     seed 003's footprint file: x, y and a lift flag per point (1: the tool lifts before this point);
  creases  found on the model: where the pencil tool, dropped on a grid, has its CL surface fold into a valley
           (it touches the model on two sides at once), the valley's cells thinned across it and chained.
Multi-pencil adds passes outward from each curve, `step` apart: further offsets of an outline away from the wall;
around a crease, closed loops at k x step from it (a band cleared on both sides).
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.offset_field import resampled
from tmm_workbench.core.footprint.region import loops_region
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter

OUTSIDE, INSIDE, BOTH = "outside", "inside", "both"
SIDES = (OUTSIDE, INSIDE, BOTH)
ARC_TOL = 0.005          # mm: the offsets' round corners
SMOOTH = 5               # points in the moving average that smooths a crease chained from grid cells
STEPS = ((1, 0), (0, 1), (1, 1), (1, -1))   # the directions a valley is looked for across (di, dj)
_STEPS = STEPS


def _closed(loop: np.ndarray) -> np.ndarray:
    return loop if np.allclose(loop[0], loop[-1]) else np.vstack([loop, loop[:1]])


def outline_curves(loops: list[np.ndarray], open_curves: list[np.ndarray], radius: float, side: str,
                   passes: int = 1, step: float = 0.0) -> list[np.ndarray]:
    """The tool centre's curves along an outline: the shape the closed `loops` bound (nested loops are holes:
    core.footprint.region.loops_region) offset by radius + k step, k < passes, to `side` (outside: away from the
    shape, inside: into it); each open curve's band of that half width (its outline: side both only). The innermost
    pass first (along the wall), each curve closed. A sign's drawing with its border's inner edge bounds the
    background: its letters are holes, the pencil runs inside it."""
    if side not in SIDES:
        raise TmmError(f"pencil side must be one of {', '.join(SIDES)}, got {side!r}")
    if open_curves and side != BOTH:
        a, b = open_curves[0][0], open_curves[0][-1]
        raise TmmError(f"pencil side {side!r} needs closed loops (a side of a shape); the outline has an open curve "
                       f"from ({a[0]:.6g}, {a[1]:.6g}) to ({b[0]:.6g}, {b[1]:.6g}): close it, or run on both sides")
    _check_passes(passes, step)
    shape = loops_region(loops, "pencil outline") if loops else []
    out: list[np.ndarray] = []
    for k in range(passes):
        d = radius + k * step
        for sign in ((1,) if side == OUTSIDE else (-1,) if side == INSIDE else (1, -1)):
            out += [_closed(p) for p in (polygons.offset(shape, sign * d, ARC_TOL) if shape else [])]
        if open_curves:
            out += [_closed(p) for p in polygons.offset_open(open_curves, d, ARC_TOL)]
    return out


def _check_passes(passes: int, step: float) -> None:
    if isinstance(passes, bool) or not isinstance(passes, (int, np.integer)) or not 1 <= passes <= 50:   # resolved
        raise TmmError(f"pencil passes must be a whole number in [1, 50], got {passes!r}")
    if passes > 1 and not (math.isfinite(step) and step > 0):
        raise TmmError(f"pencil step must be a length > 0 mm with more than one pass, got {step!r}")


def read_footprint(path: str | Path) -> list[np.ndarray]:
    """Seed 003's footprint file: a point per line, x y and a lift flag (0 or 1; 1: lift before this point),
    separated by spaces, tabs or commas; lines starting with # are comments. Its curves (the points between
    lifts). TmmError naming the line for a missing column, a number that is not finite or a flag not 0 or 1."""
    p = Path(path).expanduser()
    if not p.is_file():
        raise TmmError(f"pencil footprint file not found: {p}")
    curves: list[list[tuple[float, float]]] = []
    for n, raw in enumerate(p.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        line = raw.split("#", 1)[0].replace(",", " ").split()
        if not line:
            continue
        if len(line) != 3:
            raise TmmError(f"pencil footprint {p.name} line {n}: x, y and a lift flag expected, got {raw.strip()!r}")
        try:
            x, y, lift = (float(v) for v in line)
        except ValueError:
            raise TmmError(f"pencil footprint {p.name} line {n}: not numbers: {raw.strip()!r}") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise TmmError(f"pencil footprint {p.name} line {n}: x and y must be finite, got {raw.strip()!r}")
        if lift not in (0.0, 1.0):
            raise TmmError(f"pencil footprint {p.name} line {n}: the lift flag must be 0 or 1, got {line[2]!r}")
        if lift or not curves:
            curves.append([])
        curves[-1].append((x, y))
    out = [np.array(c) for c in curves if len(c) >= 2]
    if not out:
        raise TmmError(f"pencil footprint {p.name} has no curve of two points or more")
    return out


def crease_curves(surface: DropSurface, cutter: Cutter, box: tuple, cell: float, depth: float, floor_z: float,
                  min_length: Optional[float] = None) -> list[np.ndarray]:
    """The concave creases the tool finds in `box` (xmin, ymin, xmax, ymax): on a grid of `cell` mm, CL points
    whose height lies more than `depth` below the mean of their two neighbours across some direction (the tool
    touches the model on both sides: its CL surface folds), thinned to the deepest across the fold, chained
    8-connected, smoothed, and kept when at least `min_length` long (default the tool diameter)."""
    x0, y0, x1, y1 = box
    nx, ny = int(math.ceil((x1 - x0) / cell)) + 1, int(math.ceil((y1 - y0) / cell)) + 1
    xs, ys = x0 + np.arange(nx) * cell, y0 + np.arange(ny) * cell
    X, Y = np.meshgrid(xs, ys)
    z = surface.drop(cutter, np.column_stack([X.ravel(), Y.ravel()]), floor_z).reshape(ny, nx)
    return valley_curves(xs, ys, z, depth, cutter.diameter if min_length is None else min_length)


def valley_curves(xs: np.ndarray, ys: np.ndarray, z: np.ndarray, depth: float, min_length: float,
                  within: Optional[np.ndarray] = None, strict: bool = False) -> list[np.ndarray]:
    """The valleys of the heights `z` on the grid (xs, ys) as XY curves: the points more than `depth` below the
    mean of their two neighbours across some direction (and inside the mask `within`, if given), thinned to the
    deepest across the fold, chained 8-connected, joined where the thinning broke them, smoothed, and kept when
    at least `min_length` long. A crease's CL valley, or a strip's ridge of distance (its medial curve: `strict`,
    a ridge two cells wide is one curve)."""
    cell = float(xs[1] - xs[0]) if len(xs) > 1 else float(ys[1] - ys[0])
    fold, along = _folds(z)
    valley = (fold > depth) & _deepest_across(fold, along, strict)
    if within is not None:
        valley &= within
    curves = _joined([np.column_stack([xs[c[:, 1]], ys[c[:, 0]]]) for c in _chains(valley)], 2.5 * cell)
    return [c for c in (_smoothed(c) for c in curves) if curve_length(c) >= min_length]


def neighbours(z: np.ndarray, reach: int = 1):
    """For each direction k of _STEPS: (k, before, after), the heights `reach` steps behind and ahead of each
    inner point (the points at least `reach` from the border: z[reach:-reach, reach:-reach])."""
    ny, nx = z.shape
    m = reach
    for k, (di, dj) in enumerate(_STEPS):
        yield (k, z[m - m * dj:ny - m - m * dj, m - m * di:nx - m - m * di],
               z[m + m * dj:ny - m + m * dj, m + m * di:nx - m + m * di])


def _folds(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per grid point the deepest fold (mean of the two neighbours across a direction minus the point) and the
    direction index (_STEPS) it is across; 0 at the border."""
    ny, nx = z.shape
    folds = np.zeros((len(_STEPS), ny, nx))
    inner = (slice(1, ny - 1), slice(1, nx - 1))
    for k, before, after in neighbours(z):
        folds[k][inner] = 0.5 * (before + after) - z[inner]
    return folds.max(axis=0), folds.argmax(axis=0)


def _deepest_across(fold: np.ndarray, along: np.ndarray, strict: bool = False) -> np.ndarray:
    """Points whose fold is at least their two neighbours' across the fold's direction (a valley one cell wide);
    `strict`: above the one ahead (of two equal neighbours across, only the one ahead is kept)."""
    ny, nx = fold.shape
    keep = np.zeros_like(fold, dtype=bool)
    jj, ii = np.mgrid[1:ny - 1, 1:nx - 1]
    f = fold[1:ny - 1, 1:nx - 1]
    steps = np.array(_STEPS)[along[1:ny - 1, 1:nx - 1]]
    di, dj = steps[..., 0], steps[..., 1]
    ahead = fold[jj + dj, ii + di]
    keep[1:ny - 1, 1:nx - 1] = (f >= fold[jj - dj, ii - di]) & ((f > ahead) if strict else (f >= ahead))
    return keep


def _chains(mask: np.ndarray) -> list[np.ndarray]:
    """The mask's points as 8-connected chains of (row, column), each from an end (or any point of a loop)."""
    pts = {tuple(p) for p in np.argwhere(mask)}
    nbrs = [(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1) if (a, b) != (0, 0)]

    def around(p):
        return [(p[0] + a, p[1] + b) for a, b in nbrs if (p[0] + a, p[1] + b) in pts]

    out = []
    ends = sorted(p for p in pts if len(around(p)) == 1)
    seen: set = set()
    for start in ends + sorted(pts):
        if start in seen:
            continue
        chain, p = [start], start
        seen.add(start)
        while True:
            nxt = [q for q in around(p) if q not in seen]
            if not nxt:
                break
            p = min(nxt, key=lambda q: abs(q[0] - chain[-1][0]) + abs(q[1] - chain[-1][1]))   # 4-neighbours first
            chain.append(p)
            seen.add(p)
        if len(chain) >= 2:
            out.append(np.array(chain))
    return out


def _joined(curves: list[np.ndarray], gap: float) -> list[np.ndarray]:
    """Chains whose ends lie within `gap` of each other joined end to end (longest first), and a chain whose own
    ends do closed: the thinning breaks a crease where it turns a corner."""
    pool = sorted((c for c in curves), key=len, reverse=True)
    out = []
    while pool:
        c = pool.pop(0)
        grown = True
        while grown:
            grown = False
            for k, d in enumerate(pool):
                for a, b in ((c, d), (c, d[::-1]), (d, c), (d[::-1], c)):
                    if np.hypot(*(a[-1] - b[0])) <= gap:
                        c = np.vstack([a, b])
                        del pool[k]
                        grown = True
                        break
                if grown:
                    break
        if len(c) > 2 and np.hypot(*(c[-1] - c[0])) <= gap:
            c = np.vstack([c, c[:1]])
        out.append(c)
    return out


def _smoothed(c: np.ndarray) -> np.ndarray:
    if len(c) < SMOOTH:
        return c.astype(float)
    k = np.ones(SMOOTH) / SMOOTH
    pad = SMOOTH // 2
    padded = np.vstack([np.repeat(c[:1], pad, axis=0), c, np.repeat(c[-1:], pad, axis=0)]).astype(float)
    return np.column_stack([np.convolve(padded[:, 0], k, "valid"), np.convolve(padded[:, 1], k, "valid")])


def curve_length(c: np.ndarray) -> float:
    return float(np.hypot(*np.diff(c, axis=0).T).sum()) if len(c) > 1 else 0.0


def around_creases(curves: list[np.ndarray], passes: int, step: float) -> list[np.ndarray]:
    """Multi-pencil around creases: each crease, then the closed loops k x step from the creases (k = 1 ..
    passes - 1), innermost first."""
    _check_passes(passes, step)
    out = [np.asarray(c, dtype=float) for c in curves]
    for k in range(1, passes):
        out += [_closed(p) for p in polygons.offset_open(out[:len(curves)], k * step, ARC_TOL)]
    return out


def sampled(curves: list[np.ndarray], step: float) -> list[np.ndarray]:
    """Each curve with points at most `step` apart (its vertices kept)."""
    return [resampled(np.asarray(c, dtype=float), step) for c in curves if len(c) >= 2]
