"""Waterline finishing: the exact waterline loops (core.query.waterline) at levels step-down apart, each loop
one closed pass at its height; the linker (core.linking, VERTICAL) makes the tool path.

    result = compute(mesh, Cutter.ball(6), WaterlineParams(boundary=(0, 0, 100, 80), step_down=0.5))
    path = link(result.segments, LinkPolicy(safe_height=40, clearance_height=45))

Levels run top-down from `top_z` - `step_down` (default top: the model's highest point) to `bottom_z` (the
last level exactly there; default: the model's lowest point), within the stock (`stock_z`). The loops are cut
nearest-first, each closed loop starting at its point nearest to where the tool is, a loop only after those of the
level above within a tool diameter of it (region_order: down one wall at a time); a loop that
starts within a tool radius below where the previous one ended is reached with the tool down when that move
clears the model. Where the blocked region runs past the
boundary, the loop's points on the boundary split it: those pieces are not cut, the rest are open passes.

Direction, for a right-hand (M3, clockwise seen from above) spindle: the kernel's loops keep the material on
the tool's left, which is conventional milling (the tooth at the contact moves with the tool's travel);
climb milling keeps the material on the tool's right. So with "climb" an island loop (around material) runs
clockwise and a pocket loop counter-clockwise; with "conventional" the other way round.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, fields
from typing import Any, Optional

import numpy as np

from tmm_workbench.core import polygons as P
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.raster import Rect
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import FINEST_MM
from tmm_workbench.core.params import StrategyParams, check_finite, param
from tmm_workbench.core.query import waterline as wl
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import CutSegment, SegmentKind, StrategyResult
from tmm_workbench.core.strategies import holder_guard, rest_filter, rest_joins
from tmm_workbench.core.strategies.holder_guard import WholeToolParams
from tmm_workbench.core.strategies.rest_filter import RestParams
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Box, Work

SUPPORTED_TOOLS = ("ball", "flat", "bull", "general")  # Cutter.kind values: any APT cutter drops
CLIMB, CONVENTIONAL = "climb", "conventional"
_LEVEL_EPS_MM = 1e-9  # a level this close above the bottom is the bottom
REPEAT_MM = 1e-3      # a move within this of an earlier lifted piece's, no lower, repeats it (what it cuts more
#                       is within the loops' chord tolerance)
# The chord tolerance is shared: the kernel's loops within 0.4 of it of the exact loop (inside it, on convex
# stretches), then grown by 0.5 of it (core.polygons, mitred): no move inside the exact loop, none more than 0.9
# of the tolerance outside it (a sharp convex corner's mitre a little more).
_LOOP_CHORD, _GROWTH = 0.4, 0.5
_HAS_CLOSED = "closed" in {f.name for f in fields(CutSegment)}  # the linker's ramp entry walks closed loops


@dataclass
class WaterlineParams(StrategyParams, WholeToolParams, RestParams):  # + the whole tool (holder_guard), the rest
    boundary: Rect = (0.0, 0.0, 0.0, 0.0)        # xmin, ymin, xmax, ymax of the tip positions (mm)
    step_down: float = param(1.0, "step-down", "mm", low=0, low_open=True, kind="length")
    top_z: Optional[float] = param(None, "top", "mm", optional=True)        # default: the model's top
    bottom_z: Optional[float] = param(None, "bottom", "mm", optional=True)  # default: the model's lowest point
    stock_to_leave: float = param(0.0, "stock to leave", "mm", low=0)
    sample_step: Optional[float] = param(None, "sample step", "mm", optional=True, low=0, low_open=True)
    chord_tol: float = param(0.01, "chord tolerance", "mm", low=FINEST_MM, high=1.0)
    direction: str = param(CLIMB, "direction", choices=(CLIMB, CONVENTIONAL))
    stock_z: Optional[tuple[float, float]] = None  # the stock's bottom and top, mm: the levels stay within it
    z_levels: Optional[list] = None   # the tip heights themselves, top-down (a rest's steep part); None: step-down
    empty_ok: bool = False            # no loop (or none cutting rest material): no segments rather than an error
    join_rest: bool = True            # a rest's pieces joined by rest_joins (rest_steep joins its groups' together)

    def validate(self) -> None:
        super().validate()
        if len(self.boundary) != 4:
            raise TmmError(f"boundary must be four finite numbers xmin, ymin, xmax, ymax, got {self.boundary!r}")
        check_finite("boundary (xmin, ymin, xmax, ymax)", self.boundary)
        b = self.boundary
        if not (b[2] > b[0] and b[3] > b[1]):
            raise TmmError(f"boundary is empty: x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g}")
        if self.top_z is not None and self.bottom_z is not None and not self.top_z > self.bottom_z:
            raise TmmError(f"top {self.top_z:g} mm must be above bottom {self.bottom_z:g} mm")
        if self.stock_z is not None:
            check_finite("stock bottom and top", self.stock_z)


def level_count(top: float, bottom: float, step_down: float) -> int:
    """How many levels `levels` gives (counted, not made)."""
    if not top > bottom:
        raise TmmError(f"top {top:g} mm must be above bottom {bottom:g} mm")
    return max(1, math.ceil((top - bottom) / step_down - _LEVEL_EPS_MM))


def levels(top: float, bottom: float, step_down: float) -> list[float]:
    """Tip heights top - step_down, top - 2 step_down, ... above bottom, then bottom itself."""
    zs = [top - k * step_down for k in range(1, level_count(top, bottom, step_down))]
    return [z for z in zs if z > bottom + _LEVEL_EPS_MM] + [bottom]


def _range(mesh: TriMesh, params: WaterlineParams) -> tuple[float, float]:
    """(top, bottom) of the levels: the model's (or the params'), within the stock's (`stock_z`): a top above the
    stock's is the stock's (levels in air cut nothing), a bottom below the stock's bottom is refused."""
    lo, hi = mesh.bounds
    top = float(hi[2]) if params.top_z is None else float(params.top_z)
    bottom = float(lo[2]) if params.bottom_z is None else float(params.bottom_z)
    if params.stock_z is not None:
        floor, ceiling = params.stock_z
        if bottom < floor - 1e-6:
            what = "" if params.bottom_z is not None else " (the model's lowest point)"
            raise TmmError(f"bottom {bottom:g} mm{what} is below the stock's bottom {floor:g} mm")
        top = min(top, float(ceiling))
        if not top > bottom:
            raise TmmError(f"bottom {bottom:g} mm is not below the stock's top {top:g} mm: no level in the stock")
    return top, bottom


def count_work(params: WaterlineParams, cutter: Cutter, top: float, bottom: float) -> float:
    """Drops of the shared grid and loop points of all levels (an estimate; the levels counted, not made),
    refused above core.limits before anything is allocated."""
    params.validate()
    b = params.boundary
    step = wl.default_sample_step(cutter, b) if params.sample_step is None else params.sample_step
    count = len(params.z_levels) if params.z_levels else level_count(top, bottom, params.step_down)
    return wl.estimate_work(b, count, step, f"step-down {params.step_down:g} mm from {top:g} to {bottom:g} mm")


def estimate_work(params: WaterlineParams, cutter: Cutter, bounds: Box) -> Work:
    """The waterline's work over the model's box `bounds` (core.work): its levels from the top (or `top_z`) to the
    lowest point (or `bottom_z`), a level's loops as long as the box's outline offset by the tool radius."""
    top = bounds[5] if params.top_z is None else params.top_z
    bottom = bounds[2] if params.bottom_z is None else params.bottom_z
    count = count_work(params, cutter, top, bottom)
    n = len(levels(top, bottom, params.step_down))
    outline = 2 * (bounds[3] - bounds[0] + bounds[4] - bounds[1]) + 2 * math.pi * cutter.radius
    return Work(count, "waterline drops and points", n, n * outline, paces=(("waterline", count),))


def compute(mesh: TriMesh, cutter: Cutter, params: WaterlineParams, progress: Optional[Progress] = None,
            surface: Optional[DropSurface] = None) -> StrategyResult:
    """Gouge-free waterline finishing of `mesh` with `cutter` (tip positions; Z up) as cut segments, levels
    top-down. diagnostics: "levels" (count), "loops", "points", "joined" (pieces reached with the tool down
    from the previous one), "top" (highest tip), "repeats" (pieces left out: the same as one cut before)."""
    params.validate()
    if cutter.kind not in SUPPORTED_TOOLS:
        raise TmmError(f"the {cutter.describe()} cutter is not supported by waterline finishing")
    lo, hi = mesh.bounds
    b = params.boundary
    if b[2] <= lo[0] or b[0] >= hi[0] or b[3] <= lo[1] or b[1] >= hi[1]:
        raise TmmError(f"boundary x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g} lies outside the model "
                       f"(x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g})")
    top, bottom = _range(mesh, params)
    count_work(params, cutter, top, bottom)
    zs = list(params.z_levels) if params.z_levels else levels(top, bottom, params.step_down)
    s = params.stock_to_leave
    surface = surface or DropSurface(mesh)
    # Stock to leave: the cutter grown by s at tip heights z - s is exactly this cutter at z on the mesh
    # offset by s (Cutter.offset).
    found = wl.waterline_loops(surface, cutter.offset(s), [z - s for z in zs], b, sample_step=params.sample_step,
                               chord_tol=_LOOP_CHORD * params.chord_tol, progress=progress)
    found = [_clear_of_chords(level, b, _GROWTH * params.chord_tol) for level in found]
    segments: list[CutSegment] = []
    points = 0
    found_pieces = [[p for loop in level for p in _pieces(loop, params.direction == CLIMB)] for level in found]
    loops = sum(len(level) for level in found)
    for k, xy, closed in region_order(found_pieces, zs, 2.0 * cutter.radius):
        tips = np.column_stack([xy, np.full(len(xy), zs[k])])
        # The linker enters each segment from above onto its first tip (gouge-free, since every loop
        # point is free: its drop height is at most z), unless join_levels reaches it with the tool down.
        extra = {"closed": closed} if _HAS_CLOSED else {}
        segments.append(CutSegment(tips, SegmentKind.PASS, joined=False, pass_index=k, **extra))
        points += len(tips)
    joined = join_levels(segments, surface, cutter.offset(s), s, cutter.radius)
    if not segments and params.empty_ok:
        return StrategyResult([], {"levels": len(zs), "loops": loops, "points": 0, "joined": 0, "top": zs[0]})
    if not segments:
        raise TmmError(f"no waterline loop within the boundary x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g} "
                       f"between {bottom:g} and {top:g} mm: the model lies outside it or below the levels")
    diagnostics = {"levels": len(zs), "loops": loops, "points": points, "joined": joined,
                   "top": max(float(seg.tips[0, 2]) for seg in segments)}
    step = params.sample_step or wl.default_sample_step(cutter, b)
    segments = rest_filter.apply(params, cutter, segments, diagnostics)   # a rest: only where material is left
    if not segments and params.empty_ok:
        return StrategyResult([], diagnostics)
    if not segments:
        raise TmmError("no waterline loop takes off rest material: nothing is left for this tool on the walls")
    if getattr(params, "rest", None) is not None and params.join_rest:
        # the rest leaves short pieces of loops: the next one reached with the tool down where a join is clear
        segments, diagnostics["joins"] = rest_joins.join_pieces(mesh, cutter, params, segments, surface)
    segments = holder_guard.apply(mesh, params, segments, step, surface, diagnostics)
    segments, diagnostics["repeats"] = without_repeats(segments, zs)
    if params.assembly is not None:   # a move down to the loop below: the shank and holder clear of the walls too
        clear = rest_joins.bodies_clear(mesh, params.assembly, surface)
        for prev, seg in zip(segments, segments[1:]):
            if (seg.joined and prev.kind is seg.kind is SegmentKind.PASS
                    and not clear(np.vstack([prev.tips[-1], seg.tips[0]]))):
                seg.joined = False
                diagnostics["joined"] -= 1
    return StrategyResult(segments, diagnostics)


def without_repeats(segments: list[CutSegment], zs: list[float],
                    tol: float = REPEAT_MM) -> tuple[list[CutSegment], int]:
    """`segments` without the moves that repeat an earlier piece's: on a vertical wall the holder guard lifts the
    loops of every level below where the holder would meet the stock to the same heights, and the same lifted
    piece was entered and cut again at each of them, cutting nothing (ktoolcav: 536 of the waterline's 792
    entries, each fed 26 mm down). A move repeats one when both its ends lie within `tol` (XY) of two
    consecutive tips of one earlier lifted piece (a tip above its level `zs[pass_index]`: wheel_in_box's corners
    lifted whole to one height, 117 times), neither more than `tol` lower;
    a piece keeps the runs of its other moves (each entered; a segment joined to a left-out end entered too).
    The pieces left whole or in part, and the count of pieces changed."""
    seen: dict[tuple[int, int], list[tuple[int, int, float]]] = {}
    out: list[CutSegment] = []
    changed, entered = 0, False
    for k, seg in enumerate(segments):
        tips = seg.tips
        lifted = len(tips) > 1 and float(tips[:, 2].max()) > zs[seg.pass_index] + tol
        keep = _new_moves(seen, tips, tol) if lifted and seen else np.ones(max(len(tips) - 1, 1), dtype=bool)
        if lifted:
            for i, (x, y, z) in enumerate(tips.tolist()):
                seen.setdefault((round(x / tol), round(y / tol)), []).append((k, i, z))
        if keep.all():
            if entered and seg.joined:
                seg.joined = False
            out.append(seg)
            entered = False
            continue
        changed += 1
        runs = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(np.int8), [0]])))
        for a, b in zip(runs[::2], runs[1::2]):    # moves a..b-1: tips a..b
            part = dataclasses.replace(seg, tips=tips[a:b + 1].copy(), closed=False, entry_z=None,
                                       helix_centre=None, joined=seg.joined and a == 0 and not entered,
                                       arcs=None if seg.arcs is None else seg.arcs[a:b + 1])
            out.append(part)
        entered = not keep[-1]
    return out, changed


def _new_moves(seen: dict, tips: np.ndarray, tol: float) -> np.ndarray:
    """Which of the moves between `tips` repeat no earlier lifted piece's (see without_repeats)."""
    def matches(p: list) -> set:
        x, y, z = p
        ix, iy = round(x / tol), round(y / tol)
        found = set()
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for k, i, z0 in seen.get((ix + dx, iy + dy), ()):
                    if z >= z0 - tol:
                        found.add((k, i))
        return found
    at = [matches(p) for p in tips.tolist()]
    keep = np.ones(len(tips) - 1, dtype=bool)
    for i in range(len(tips) - 1):
        if at[i] and at[i + 1]:
            keep[i] = not any((k, j + d) in at[i + 1] for k, j in at[i] for d in (-1, 0, 1))
    return keep


def join_levels(segments: list[CutSegment], surface: DropSurface, grown: Cutter, s: float, radius: float) -> int:
    """Pieces that start within a tool radius of where the previous one ended, no higher, reached with the tool
    down (`joined`: a straight fed move, the next level's loop from the one above) where that move is clear of
    the model plus stock to leave (sampled as core.verify.linear_moves checks moves); the count. A lift, a rapid
    and the feed down through the clearance cost more than such a move on short loops."""
    from tmm_workbench.core.verify.linear_moves import deepest_cut

    count = 0
    for prev, seg in zip(segments, segments[1:]):
        a, b = prev.tips[-1], seg.tips[0]
        if float(np.hypot(*(b[:2] - a[:2]))) > radius or b[2] > a[2] + _LEVEL_EPS_MM:
            continue
        move = np.vstack([a, b]) - np.array([0.0, 0.0, s])   # the grown cutter's tips lie s lower
        if deepest_cut(surface, grown, move, np.array([False, True]))[0] <= 1e-6:
            seg.joined = True
            count += 1
    return count


def _clear_of_chords(level: list[wl.WaterlineLoop], bounds: Rect, grow: float) -> list[wl.WaterlineLoop]:
    """The level's loops grown away from the material by `grow` mm (the blocked region they bound, offset by
    Clipper with mitred joins): the kernel's loop points are exact contacts, but on a convex stretch the chords
    between them cut into the material by up to the loop's chord error (vertically many times that on a steep
    wall). Grown by more than that error, every move is clear of the exact loop, and at most
    `_LOOP_CHORD + _GROWTH` chord tolerances outside it. Points the growth carries onto or past the bounds'
    edges are no contacts (the pieces there are not cut, as the kernel's closing points)."""
    if not level:
        return level
    z = level[0].z
    grown = P.offset([lp.xy for lp in level], grow, miter=True)
    xmin, ymin, xmax, ymax = bounds
    out = []
    for xy in grown:
        contact = (xy[:, 0] > xmin) & (xy[:, 0] < xmax) & (xy[:, 1] > ymin) & (xy[:, 1] < ymax)
        out.append(wl.WaterlineLoop(xy, z, contact))
    return out


def _pieces(loop: wl.WaterlineLoop, climb: bool) -> list[tuple[np.ndarray, bool]]:
    """The loop's parts to cut, (xy, closed), in the cutting direction: the whole loop if every point is a
    contact, else the runs of contacts between points on the boundary (two points at least)."""
    xy, contact = loop.xy, loop.contact
    if climb:  # the kernel's loops keep the material on the left (conventional)
        xy, contact = xy[::-1], contact[::-1]
    if contact.all():
        return [(xy, True)]
    n = len(xy)
    first = int(np.flatnonzero(~contact)[0])
    order = (np.arange(n) + first) % n        # starting at a boundary point: runs do not wrap
    runs, run = [], []
    for i in order:
        if contact[i]:
            run.append(i)
        elif run:
            runs.append(run)
            run = []
    if run:
        runs.append(run)
    return [(xy[r], False) for r in runs if len(r) >= 2]


def region_order(levels: list[list[tuple[np.ndarray, bool]]], zs: list[float],
                 near: float) -> list[tuple[int, np.ndarray, bool]]:
    """The pieces of all levels (per level: (xy, closed)) in cutting order, (level, xy, closed), a closed loop
    rotated to start at its point nearest to where the tool is (its first point repeated at its end): nearest
    first (core.strategies.rest_order.cost: a rise counts more than a descent), a piece only after each piece of
    the level above that comes within `near` of it (the loop above on its wall). So the tool goes down one wall
    or pocket level after level rather than across the model at every level (ktoolcav: 80 moves of 110 mm
    between its two sides), and no loop is cut under the stock its wall still carries above it."""
    from scipy.spatial import cKDTree

    from tmm_workbench.core.strategies.rest_order import cost

    ids = [(k, i) for k, level in enumerate(levels) for i in range(len(level))]
    waiting = {key: 0 for key in ids}
    children: dict[tuple[int, int], list[tuple[int, int]]] = {key: [] for key in ids}
    for k in range(1, len(levels)):
        above, here = levels[k - 1], levels[k]
        if not above or not here:
            continue
        boxes = [(xy.min(axis=0) - near, xy.max(axis=0) + near) for xy, _ in above]
        trees: dict[int, Any] = {}
        for i, (xy, _) in enumerate(here):
            lo, hi = xy.min(axis=0), xy.max(axis=0)
            for j, (blo, bhi) in enumerate(boxes):
                if np.any(lo > bhi) or np.any(hi < blo):
                    continue
                if j not in trees:
                    trees[j] = cKDTree(above[j][0])
                if np.isfinite(trees[j].query(xy, distance_upper_bound=near)[0]).any():
                    children[(k - 1, j)].append((k, i))
                    waiting[(k, i)] += 1
    ready = [key for key in ids if waiting[key] == 0]
    out: list[tuple[int, np.ndarray, bool]] = []
    where: Optional[np.ndarray] = None
    while ready:
        best = (math.inf, 0, 0)
        for r, (k, i) in enumerate(ready):
            xy, closed = levels[k][i]
            if where is None:
                best = (0.0, r, 0)
                break
            heads = xy if closed else xy[:1]
            c = cost(where, np.column_stack([heads, np.full(len(heads), zs[k])]))
            m = int(np.argmin(c))
            if c[m] < best[0]:
                best = (float(c[m]), r, m)
        _, r, start = best
        k, i = ready.pop(r)
        xy, closed = levels[k][i]
        if closed:
            xy = np.vstack([xy[start:], xy[:start], xy[start:start + 1]])
        out.append((k, xy, closed))
        where = np.array([xy[-1, 0], xy[-1, 1], zs[k]])
        for child in children[(k, i)]:
            waiting[child] -= 1
            if waiting[child] == 0:
                ready.append(child)
    return out
