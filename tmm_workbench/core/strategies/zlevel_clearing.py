"""Clearing one region of tool-centre positions at one z-level: contour-parallel offsets or zig-zag lines.

The region is where the tool centre may go at that height (gouge-free everywhere in it). Offsets: the
region eroded by 0, s, 2s, ... (each level from the region itself, not from the previous level, so arcs do
not accumulate error). Every point of the region lies within s of some level's boundary (a point outside
level i + 1 is closer than s to the outside of level i), so with s at most the cutter radius the loops
sweep the whole region; where s is larger, what the loops miss is cleared by loops around the missed
pieces (`fill_gaps`).

Order and direction. Climb milling (spindle clockwise) keeps the material on the right of the travel:
  inside-out (a closed pocket entered in its middle): the material is outside the level being cut, so
  loops run with the region on their left (outer boundaries counter-clockwise, holes clockwise);
  outside-in (a region open to the air, entered from outside the stock): the outer boundaries' offsets
  have the material inside, so they run the other way; the loops round islands come last, from the
  farthest in towards the island, with the material outside them again. Conventional milling reverses all.
Zig-zag lines alternate direction (climb and conventional by turns); the region's boundary loops follow
them as a contour pass in the chosen direction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from tmm_workbench.core import polygons as P
from tmm_workbench.core.errors import Cancelled


@dataclass
class Pass:
    xy: np.ndarray            # (n, 2) tool-centre XY
    closed: bool              # a loop (its first point is not repeated)
    level: int = 0            # offset level (0: the region's boundary); zig-zag lines: -1
    outer: bool = False       # the region's own outer boundary


@dataclass
class _Node:
    region: P.Region
    level: int
    children: list["_Node"] = field(default_factory=list)


def _levels(region: P.Region, stepover: float, arc_tol: float, cancelled=None) -> _Node:
    """The tree of eroded levels: each piece of level i + 1 under the piece of level i that holds it."""
    root = _Node(region, 0)
    frontier = [root]
    k = 1
    while frontier:
        if cancelled is not None and cancelled():
            raise Cancelled("roughing cancelled")
        eroded = P.regions(P.offset(region.shape, -k * stepover, arc_tol))
        if not eroded:
            break
        nxt: list[_Node] = []
        for piece in eroded:
            node = _Node(piece, k)
            probe = piece.outer[0]
            parent = next((f for f in frontier if P.contains_point(f.region.shape, probe)), frontier[0])
            parent.children.append(node)
            nxt.append(node)
        frontier = nxt
        k += 1
    return root


def _loops_of(node: _Node, material_inside: bool, climb: bool, holes: bool = True) -> list[Pass]:
    # region on the left (Clipper's orientation) is climb when the material lies outside the level
    keep = climb != material_inside
    out = []
    for i, poly in enumerate(node.region.shape if holes else node.region.shape[:1]):
        xy = poly if keep else poly[::-1].copy()
        if len(xy) >= 3:
            out.append(Pass(np.asarray(xy, float), True, node.level, node.level == 0 and i == 0))
    return out


def _hole_loops(node: _Node, climb: bool) -> list[Pass]:
    """The loops round the region's islands, from the farthest level in to the island: each takes the
    step-over between it and the one before (the material lies towards the island: outside the level)."""
    found: list[Pass] = []

    def visit(n: _Node) -> None:
        for poly in n.region.holes:
            if len(poly) >= 3:
                found.append(Pass(np.asarray(poly if climb else poly[::-1].copy(), float), True, n.level))
        for child in n.children:
            visit(child)

    visit(node)
    return sorted(found, key=lambda p: -p.level)


def offset_passes(region: P.Region, stepover: float, *, climb: bool = True, outside_in: bool = False,
                  arc_tol: float = P.ARC_TOL, cancelled=None) -> list[Pass]:
    """Contour-parallel loops of `region` in cutting order: inside-out (children before their parent
    level), or outside-in (a region open to the air: the outer boundaries' offsets from the outside in,
    parents first, then the loops round the islands from the farthest in to the island, so none slots
    through full material)."""
    root = _levels(region, stepover, arc_tol, cancelled)
    out: list[Pass] = []

    def visit(node: _Node) -> None:
        if outside_in:
            out.extend(_loops_of(node, True, climb, holes=False))
        for child in node.children:
            visit(child)
        if not outside_in:
            out.extend(_loops_of(node, False, climb))

    visit(root)
    if outside_in:
        out.extend(_hole_loops(root, climb))
    return out


def zigzag_passes(region: P.Region, stepover: float, *, climb: bool = True, angle_deg: float = 0.0,
                  arc_tol: float = P.ARC_TOL) -> list[Pass]:
    """Lines `stepover` apart across the region (at `angle_deg` from +X), clipped to it, in alternating
    directions, then the region's boundary as a contour pass."""
    shape = region.shape
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    # in the rotated frame (u along the lines, v across them)
    pts = np.vstack(shape)
    u, v = pts @ np.array([c, s]), pts @ np.array([-s, c])
    length = (u.max() - u.min()) + 2.0
    count = max(1, math.ceil((v.max() - v.min()) / stepover))
    offsets = v.min() + (v.max() - v.min()) / count * (np.arange(count) + 0.5) if count > 1 else \
        np.array([(v.max() + v.min()) / 2])
    lines = []
    for k, vk in enumerate(offsets):
        a = np.array([u.min() - 1.0, vk]), np.array([u.min() - 1.0 + length, vk])
        seg = np.array([a[0][0] * c - a[0][1] * s, a[0][0] * s + a[0][1] * c,
                        a[1][0] * c - a[1][1] * s, a[1][0] * s + a[1][1] * c]).reshape(2, 2)
        for piece in P.clip_open([seg], shape):
            forward = np.dot(piece[-1] - piece[0], [c, s]) >= 0
            if forward != (k % 2 == 0):
                piece = piece[::-1]
            lines.append((k, Pass(piece.copy(), False, -1)))
    out = [p for _, p in lines]
    out.extend(_loops_of(_Node(region, 0), False, climb))
    return out


def fill_gaps(region: P.Region, passes: list[Pass], reach: float, arc_tol: float = P.ARC_TOL,
              min_area: float = 1e-4) -> list[Pass]:
    """Loops around the pieces of `region` farther than `reach` from every pass (a step-over larger than
    the reach leaves them), repeated until none is left (at most a few rounds)."""
    extra: list[Pass] = []
    for _ in range(4):
        loops = [p.xy for p in passes + extra if p.closed]
        lines = [p.xy for p in passes + extra if not p.closed]
        swept = P.union(P.offset_open(loops, reach, arc_tol, closed=True), P.offset_open(lines, reach, arc_tol))
        missed = [r for r in P.regions(P.difference(region.shape, swept)) if r.area > min_area]
        if not missed:
            break
        for r in missed:
            extra.append(Pass(r.outer.copy(), True, -2))
    return extra


def order_from(passes: list[Pass], start: Optional[np.ndarray]) -> list[Pass]:
    """Each closed pass rotated to begin at its vertex nearest the end of the pass before (the first:
    nearest `start`, if given)."""
    out = []
    here = start
    for p in passes:
        xy = p.xy
        if p.closed and here is not None:
            k = int(np.argmin(np.sum((xy - here) ** 2, axis=1)))
            xy = np.roll(xy, -k, axis=0)
        out.append(Pass(xy, p.closed, p.level, p.outer))
        here = xy[0] if p.closed else xy[-1]
    return out
