"""The steep part of a rest, cut by waterline loops. Passes s apart in XY leave on a flat a cusp c = s^2 / 8 r
(r the corner radius); across a slope a_n the step along the surface is s / cos a_n, so the cusp along the
normal c / cos^2 a_n, and its vertical height (what the rest and the simulation judge) that over cos a, a the
slope: on the steep parts of a rest the passes cannot hold the tolerance (and on curved ones they leave more
than that). So the Surface's passes run over the whole rest as before, and the sloped rest cells (steeper than
FLATTEST_DEG, where the tool's envelope comes within the tolerance: elsewhere no spacing holds it) they leave
above the tolerance, found by cutting their z-map with the passes, are cut by waterline loops
(core.strategies.waterline), group by group of nearby cells, kept only where they cut that material and linked
with the other passes. The loops' levels are spaced by the cusp on the wall: two loops dz apart on a slope a
leave dz^2 / (8 r sin^2 a) along the normal (dz^2 / (8 r sin^2 a cos a) vertically), so dz = sin a sqrt(8 r c)
under the cells of each height band, the cusp judged along the normal as the planner's left check judges it
(spaced for the vertical cusp, the levels on an 85 deg wall were 3.4 times closer: a D3 rest after a D10 raster
went 2.4 times the length of a full D3 raster; a capped at STEEPEST_DEG).

Measured (docs/rest_pencil.md): loops over every cell the passes cannot hold by the formula, the passes only over
the others, made the rest 1.4 times longer on sphere_on_plate and 2.2 times on mount_rush than this (a large
tool's cusps on a slope lie scattered along its passes, and a loop crossing them cuts little); loops only over the
cells the formula calls steep left 2.3 times the cells above the tolerance on mount_rush.

The pieces of passes and loops are then reached with the tool down from the one before where a join passes its
checks (core.strategies.rest_joins): each entered by a hop and a plunge, the loops' short pieces took a third of
the rest's time on mount_rush.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.footprint.reach import gentle_cosine, reach_excess
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import native
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.simulate import CUT, RAPID
from tmm_workbench.core.strategies import rest_joins, rest_order, rest_touchup, waterline
from tmm_workbench.core.strategies.surface.params import ONEWAY
from tmm_workbench.core.tools.cutter import Cutter

FLATTEST_DEG = 15.0    # the waterline's levels on flatter cells would be too close: what passes leave there stays
STEEPEST_DEG = 85.0    # the levels' spacing is that of this slope on anything steeper
WALL_CUSP = 0.8        # of the rest tolerance: the waterline's vertical cusp on the wall
CHORD_TOL = 0.002      # the loops' chord tolerance, mm: their growth off the wall times tan a is left on it
BRIDGE = 1.0           # tool diameters of a loop's gap cut through (the raster's 3): the steep cells lie scattered
#                        along a large tool's passes, a loop crossing many of them; the hop over a gap is 1 mm


@dataclass
class SteepReport:
    """What the rest's passes and loops leave (their cut of the rest cells' z-map), for the op's RestReport."""
    tolerance: float
    sloped: float         # mm^2 of sloped rest the passes left above the tolerance (the loops' cells)
    groups: int
    levels: int
    sloped_after: float   # mm^2 of sloped rest the tool reaches still above it after the loops
    flat_after: float     # mm^2 flatter than FLATTEST_DEG it reaches the passes leave above it (no loops there)
    edge: float = 0.0     # mm^2 of both where its envelope stands more than half the tolerance above the design
    touch_ups: int = 0    # pieces put where the tool reaches what passes and loops left (core.strategies.rest_touchup)

    def summary(self) -> str:
        text = (f"the passes left {self.sloped:.1f} mm2 of sloped rest above {self.tolerance:g} mm: waterline loops "
                f"over it ({self.groups} group(s), {self.levels} levels)" if self.sloped else
                f"the passes left no sloped rest above {self.tolerance:g} mm")
        if self.touch_ups:
            text += f"; {self.touch_ups} touch-up(s) where the tool reaches what passes and loops left above it"
        if self.sloped_after > 0 or self.flat_after > 0:
            text += (f"; where this tool reaches, {self.sloped_after:.1f} mm2 sloped and {self.flat_after:.1f} mm2 "
                     f"flatter than {FLATTEST_DEG:g} deg (no loops there) stay above it, {self.edge:.1f} mm2 of them "
                     f"at the edge of its reach (its envelope more than half the tolerance above the design)")
        return text


def gradient(design: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """(gy, gx) of the design's heights, a cell without design taking its nearest neighbour's height (at the
    model's edge the slope is read one-sided, not lost)."""
    missing = ~np.isfinite(design)
    if missing.any() and not missing.all():
        from scipy import ndimage

        idx = ndimage.distance_transform_edt(missing, return_distances=False, return_indices=True)
        design = design[tuple(idx)]
    gy, gx = np.gradient(design, cell)
    return gy, gx


def slope_deg(design: np.ndarray, cell: float) -> np.ndarray:
    """(ny, nx) the design's slope on the grid, degrees."""
    gy, gx = gradient(design, cell)
    return np.degrees(np.arctan(np.hypot(gx, gy)))


def in_reach(rest: RestStock, radius: float) -> np.ndarray:
    """(ny, nx) the cells where the tool's envelope (of corner `radius`) comes within the rest tolerance of the
    design along its normal beyond the grid's own cusp, as the planner's reach tests and left check judge
    (core.footprint.reach.reach_excess): on a wall the vertical gap is many times the depth along the normal, and
    judged vertically an 80 deg wall the tool reaches was called out of its reach (no loops, no touch-ups there).
    Everywhere without an envelope."""
    if rest.envelope is None or rest.design is None:
        return np.ones(rest.heights.shape, dtype=bool)
    with np.errstate(invalid="ignore"):
        return reach_excess(rest.envelope, rest.design, rest.grid.cell, radius) <= rest.within


def steep_cells(rest: RestStock, radius: float) -> Optional[RestStock]:
    """The rest's sloped part: steeper than FLATTEST_DEG, where the tool's envelope (of corner `radius`) comes
    within the rest tolerance (in_reach: elsewhere no spacing holds it); None when no cell is."""
    if rest.design is None:
        return None
    steep = np.isfinite(rest.heights) & (slope_deg(rest.design, rest.grid.cell) > FLATTEST_DEG)
    steep &= in_reach(rest, radius)
    return replace(rest, heights=np.where(steep, rest.heights, -np.inf)) if steep.any() else None


def level_step(radius: float, cusp: float, slope: np.ndarray) -> np.ndarray:
    """The z-step between loops that leaves `cusp` (along the normal) on slopes `slope` (radians) for a corner
    radius."""
    a = np.minimum(slope, math.radians(STEEPEST_DEG))
    return np.sin(a) * np.sqrt(8 * radius * cusp)


def levels(steep: RestStock, radius: float, cusp: float) -> list[float]:
    """Tip heights top-down for the steep rest cells: a cell at height h on a slope a is touched by the corner
    from the level h - r (1 - cos a), and spans the wall's rise across it (cell tan a, a capped at STEEPEST_DEG);
    each level a step below the last, the step of the steepest cells within one of it, a gap without steep
    cells jumped to the next one's top."""
    cells = np.isfinite(steep.heights)
    a = np.minimum(np.radians(np.nan_to_num(slope_deg(steep.design, steep.grid.cell)[cells])),
                   math.radians(STEEPEST_DEG))
    z = steep.design[cells] - radius * (1 - np.cos(a))
    half = 0.5 * steep.grid.cell * np.tan(a)
    top, bottom, dz = z + half, z - half, level_step(radius, cusp, a)
    big = float(dz.max())
    out = [float(top.max())]
    while True:
        below = bottom < out[-1] - 1e-9
        if not below.any():
            return out
        near = below & (top >= out[-1] - big)
        out.append(out[-1] - float(dz[near].min()) if near.any() else float(top[below].max()))


def after_cut(rest: RestStock, segments: list[CutSegment], cutter: Cutter) -> np.ndarray:
    """(ny, nx) the rest cells' heights after `segments` (cut in order, each entered straight down from above all
    and left straight up: a rapid cuts in the z-map too); -inf off the rest."""
    cells = np.isfinite(rest.heights)
    if not segments or not cells.any():
        return rest.heights
    g = rest.grid
    floor = float(np.nanmin(rest.design)) - 1.0
    zmap = native.ZMap(g.x0, g.y0, g.cell, g.nx, g.ny, 0.0)
    zmap.heights[:] = np.where(cells, rest.heights, floor)
    top = max(float(rest.heights[cells].max()), max(float(seg.tips[:, 2].max()) for seg in segments)) + 1.0
    tips = np.vstack([np.vstack([[*seg.tips[0, :2], top], seg.tips, [*seg.tips[-1, :2], top]])
                      for seg in segments])
    kinds = np.concatenate([[CUT] * len(seg.tips) + [RAPID, RAPID] for seg in segments])[:-1]
    native.cut_3axis(zmap, cutter.native, np.ascontiguousarray(tips, dtype=float), kinds.astype(np.uint8), 1e-3, 0,
                     None)
    return np.where(cells, np.array(zmap.heights), -np.inf)


def residue(rest: RestStock, segments: list[CutSegment], cutter: Cutter) -> Optional[RestStock]:
    """The cells of `rest` (with the design) that `segments` leave more than the rest tolerance above the design
    along its normal (the vertical gap times the cosine of the design's slope, the gentler one-sided one: a floor
    cell at a wall's foot is judged as the floor), at the heights they leave; None when none is."""
    after = after_cut(rest, segments, cutter)
    with np.errstate(invalid="ignore"):
        left = np.isfinite(after) & ((after - rest.design) * gentle_cosine(rest.design, rest.grid.cell)
                                     > rest.within)
    return replace(rest, heights=np.where(left, after, -np.inf)) if left.any() else None


def finish(mesh: TriMesh, cutter: Cutter, params: Any, segments: list[CutSegment], surface: Optional[DropSurface],
           diagnostics: dict) -> list[CutSegment]:
    """A rest's passes (`segments`, the Surface's pattern) and after them the waterline loops over the sloped rest
    cells they leave above the tolerance (not after a pencil's), ordered (rest_order) and joined (rest_joins;
    diagnostics "joins"); what they leave (params.rest) as a SteepReport appended to params.verify_notes (the op's
    RestReport) when it is a list."""
    rest = getattr(params, "rest", None)
    if rest is None or rest.design is None:
        return segments
    if params.pattern == "pencil":   # no loops along creases: its pieces (either way) in order, joined
        return _joined(mesh, cutter, params, rest_order.ordered(segments, {id(seg) for seg in segments}),
                       surface or DropSurface(mesh), diagnostics)
    sloped = of_params(params, cutter)
    left = None if sloped is None else residue(sloped, segments, cutter)
    loops = [] if left is None else passes(mesh, cutter, params, left, surface, diagnostics)
    # where passes and loops leave the rest above the tolerance, the tool put where it reaches it
    surface = surface or DropSurface(mesh)
    touch = rest_touchup.pieces(mesh, cutter, params, residue(rest, segments + loops, cutter), surface)
    diagnostics["touch_ups"] = len(touch)
    # passes, loops and touch-ups in one order (nearest-first, then 2-opt): in the raster's own order a rest of many pieces was
    # crossed line by line (a link over the gaps between the pieces on every pass: the sign's clean-up, 12 pieces)
    # (the pattern's passes either way but a one-way raster's, the touch-ups either way; the loops keep their sense)
    either = {id(seg) for seg in touch + (segments if params.pattern != ONEWAY else [])}
    cut = _joined(mesh, cutter, params, rest_order.ordered(segments + loops + touch, either), surface, diagnostics)
    if params.verify_notes is not None:
        a = rest.grid.cell_area
        after = residue(rest, cut, cutter)
        still = np.zeros(rest.heights.shape, dtype=bool) if after is None else np.isfinite(after.heights)
        still &= in_reach(rest, cutter.radius)   # (beyond the tool's reach: the rest's own report)
        flat = slope_deg(rest.design, rest.grid.cell) <= FLATTEST_DEG
        edge = np.zeros_like(flat) if rest.envelope is None else rest.envelope - rest.design > 0.5 * rest.within
        steep = diagnostics.get("steep", {})
        params.verify_notes.append(SteepReport(
            rest.within, 0.0 if left is None else float(np.isfinite(left.heights).sum() * a),
            int(steep.get("groups", 0)), int(steep.get("levels", 0)), float(np.sum(still & ~flat) * a),
            float(np.sum(still & flat) * a), float(np.sum(still & edge) * a), len(touch)))
    return cut


def _joined(mesh: TriMesh, cutter: Cutter, params: Any, pieces: list[CutSegment], surface: DropSurface,
            diagnostics: dict) -> list[CutSegment]:
    """The pieces reached with the tool down where a join from the one before passes its checks (rest_joins;
    diagnostics "joins", "top")."""
    cut, diagnostics["joins"] = rest_joins.join_pieces(mesh, cutter, params, pieces, surface)
    if cut:   # a join lifted over a ridge between two pieces may stand above both
        diagnostics["top"] = max(diagnostics.get("top", -math.inf), max(float(seg.tips[:, 2].max()) for seg in cut))
    return cut


def of_params(params: Any, cutter: Cutter) -> Optional[RestStock]:
    """The sloped part of the Surface params' rest (None: no rest, a pencil, a flat end mill or nothing
    sloped)."""
    rest = getattr(params, "rest", None)
    if rest is None or params.pattern == "pencil" or cutter.corner_radius <= 0:
        return None
    return steep_cells(rest, cutter.radius)


def patches(steep: RestStock, reach: float) -> list[RestStock]:
    """The steep cells in groups (cells within about `reach` of one another together), each a RestStock."""
    from scipy import ndimage

    cells = np.isfinite(steep.heights)
    grown = ndimage.binary_dilation(cells, iterations=max(1, int(math.ceil(0.5 * reach / steep.grid.cell))))
    labels, n = ndimage.label(grown, structure=np.ones((3, 3), dtype=bool))
    labels = np.where(cells, labels, 0)
    return [replace(steep, heights=np.where(labels == k, steep.heights, -np.inf)) for k in range(1, n + 1)
            if (labels == k).any()]


def passes(mesh: TriMesh, cutter: Cutter, params: Any, steep: RestStock, surface: Optional[DropSurface],
           diagnostics: dict) -> list[CutSegment]:
    """Waterline loops over the steep rest cells, group by group (each group's levels top-down), within the
    Surface params' boundary, kept where they cut that material, in the order `rest_order.ordered` takes them, none joined
    (finish joins them) (diagnostics "steep": levels, segments, cells, groups)."""
    surface = surface or DropSurface(mesh)
    segments: list[CutSegment] = []
    count = 0
    groups = patches(steep, cutter.diameter)
    for group in groups:
        cancel.poll()
        found = _group_passes(mesh, cutter, params, group, surface)
        count += len(found[1])
        segments += found[0]
    segments = rest_order.ordered(segments)   # the loops' pieces: each keeps its sense
    for seg in segments:   # joined again in the new order (rest_joins: finish)
        seg.joined = False
    diagnostics["steep"] = {"levels": count, "segments": len(segments), "groups": len(groups),
                            "cells": int(np.isfinite(steep.heights).sum())}
    if segments:
        diagnostics["top"] = max(diagnostics.get("top", -math.inf), max(float(seg.tips[:, 2].max())
                                                                         for seg in segments))
    return segments



def estimate(params: Any, cutter: Cutter) -> Optional[tuple[float, float, int]]:
    """The waterline loops a rest's slopes may get, before any is made (None: no rest, a pencil, a flat end mill
    or nothing sloped): (drops and loop points, loop length mm, levels) as if the passes left every sloped rest
    cell above the tolerance (they leave a part of them: an upper bound). Each group's levels and box as passes
    makes them, its drops and points as the waterline counts them (core.query.waterline.estimate_work: refused
    above the limits, as the waterline would refuse it); the length: each cell's area times tan a over its
    levels' step, the contacts' length (the tip runs a corner radius times sin a off them: around a convex slope
    of plan radius rho longer by r sin a / rho, in a concave corner shorter)."""
    from tmm_workbench.core.query import waterline as wl

    steep = of_params(params, cutter)
    if steep is None:
        return None
    cusp = WALL_CUSP * steep.within
    count, n = 0.0, 0
    for group in patches(steep, cutter.diameter):
        zs = levels(group, cutter.corner_radius, cusp)
        box = _group_box(group, cutter, params.boundary)
        if box is None:
            continue
        count += wl.estimate_work(box, len(zs), wl.default_sample_step(cutter, box),
                                  f"the rest's sloped cells: {len(zs)} levels spaced by the cusp on the wall")
        n += len(zs)
    cells = np.isfinite(steep.heights)
    a = np.radians(np.clip(np.nan_to_num(slope_deg(steep.design, steep.grid.cell)[cells]), FLATTEST_DEG,
                           STEEPEST_DEG))
    length = float(np.sum(steep.grid.cell_area * np.tan(a) / level_step(cutter.corner_radius, cusp, a)))
    return count, length, n


def _group_box(group: RestStock, cutter: Cutter, boundary: tuple) -> Optional[tuple[float, float, float, float]]:
    """The box of a group's loops: its cells' grown by the tool diameter (the tool centre is within a radius of
    its contact: the loop well inside it), within the boundary; None when nothing is left of it."""
    g, cells = group.grid, np.isfinite(group.heights)
    xy = g.centres().reshape(g.ny, g.nx, 2)[cells]
    grow, b = cutter.diameter, boundary
    box = (max(b[0], float(xy[:, 0].min()) - grow), max(b[1], float(xy[:, 1].min()) - grow),
           min(b[2], float(xy[:, 0].max()) + grow), min(b[3], float(xy[:, 1].max()) + grow))
    return box if box[2] > box[0] and box[3] > box[1] else None


def _group_passes(mesh: TriMesh, cutter: Cutter, params: Any, group: RestStock,
                  surface: DropSurface) -> tuple[list[CutSegment], list[float]]:
    """(segments, levels) of one group of steep cells, in its box (_group_box)."""
    zs = levels(group, cutter.corner_radius, WALL_CUSP * group.within)
    lo = float(mesh.bounds[0][2])
    zs = [z for z in zs if z >= lo]
    box = _group_box(group, cutter, params.boundary)
    if not zs or box is None:
        return [], []
    wp = waterline.WaterlineParams(boundary=box, step_down=1.0, top_z=zs[0] + 1e-6,
                                   bottom_z=min(zs[-1], zs[0] - 1e-5), chord_tol=CHORD_TOL, z_levels=zs,
                                   stock_to_leave=max(params.stock_to_leave, 0.0), empty_ok=True,
                                   assembly=params.assembly, holder_collision=params.holder_collision,
                                   holder_notes=params.holder_notes, join_rest=False)   # finish joins them
    wp.rest, wp.rest_bridge = group, BRIDGE
    return waterline.compute(mesh, cutter, wp, cancel.asker(), surface).segments, zs
