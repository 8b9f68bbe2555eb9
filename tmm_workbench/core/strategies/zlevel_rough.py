"""Z-level roughing (seed 000 section 3.4): the stock cut down to the model plus stock to leave in 2.5-axis
layers; the linker (core.linking) makes the tool path.

    result = compute(mesh, Cutter.flat(6), RoughingParams(stock_box=(0, 0, 0, 100, 100, 30)))
    path = compute_roughing_toolpath(mesh, cutter, params, LinkPolicy(safe_height=35, clearance_height=40))

Per layer (tip height z, descending; zlevel_layers):
  blocked   where the tool would cut the model offset by the stock to leave: the exact waterline
            (core.query.waterline) of the cutter grown by the radial stock to leave, `Cutter.offset(s)`,
            at z - axial stock to leave, grown by `wall_margin` (the chords of the waterline and of the
            offsets lie within it of the exact loops). The seed offsets the mesh along vertex normals
            instead (3.4.3): that is not an exact offset (it shrinks concave corners and opens gaps at sharp
            edges); the grown cutter's drop is. Radial and axial differ: the grown cutter keeps s on walls,
            the level z - s_a keeps s_a on flats (on slopes a mix of the two);
  region    the tool-centre positions that touch material: the stock's XY grown by the tool radius less a
            step-over (so the first loop around the stock takes no more than a step-over; not grown at all
            for step-overs past the radius), minus blocked; and, where the model stands closer to the stock's
            edge than that so no position is left in a layer (a thin margin; a box stock only), the positions
            within a step-over of blocked that take more than the stock to leave of the material (the loop
            round the model then takes what the margin holds, less than a step-over).
            Every position in it is gouge-free at z and above (the blocked region only shrinks upwards);
  clearing  contour-parallel offsets (or zig-zag lines) of each region at the step-over (zlevel_clearing),
            climb or conventional;
  entries   a region open to the air outside the stock is entered from there: down through air beside the
            stock, then fed in at depth, and cut from the outside in; a closed one from its middle outwards,
            by a helix whose circle lies in the region, else a ramp along the first loop (at least a quarter
            of the tool diameter long), else, for a region whose outline is longer than that, a TmmError
            naming it. A spot where the tool centre just fits (a valley's bottom in the last layer that
            reaches it) is left uncut and named in the diagnostics ("not_entered"): on real models such
            spots come by chance, and refusing the whole roughing for one would leave none. The helix or
            ramp starts just above the material: the top of what earlier layers left over the entry's
            footprint (their swept areas are kept as polygons, so no air is cut over and over);
  links     tool down from one pass to the next inside a region when the straight link lies in the region
            (every point of it a gouge-free tool-centre position: no check against the model needed) and is
            no longer than the tool diameter (a longer one would slot through uncut material); else a
            retract to the safe height and a new entry.
Where the material is not a box (`stock_heights`: a cast or what an earlier op left), a layer cuts only where
the stock is above it.

Work (layers x loops x points) is estimated from the parameters and refused above core.limits before any
waterline is computed.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from tmm_workbench.core import polygons as P
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import FINEST_MM, check_work
from tmm_workbench.core.linking import HELIX, PLUNGE, RAMP, RAMP_ANGLE, LinkPolicy, link
from tmm_workbench.core.params import StrategyParams, check_finite, param
from tmm_workbench.core.query import waterline as wl
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import CutSegment, SegmentKind, StrategyResult
from tmm_workbench.core.strategies import holder_guard
from tmm_workbench.core.strategies import zlevel_clearing as clearing
from tmm_workbench.core.strategies.holder_guard import WholeToolParams
from tmm_workbench.core.strategies import zlevel_layers as layers_mod
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Box, Work

SUPPORTED_TOOLS = ("flat", "bull", "ball")
_AIR_MARGIN = 1.0           # mm: the tool-centre box reaches this far past the tool touching the stock
_ENTRY_CLEARANCE = 0.5      # mm: helices and ramps start this far above the material
_FLOOR_NOISE = 1e-4        # mm: stock heights this close above a layer are the floor an earlier layer cut
_MIN_REGION_AREA = 1e-6     # mm^2: tool-centre regions smaller than this are rounding, not room
_TOUCH = 0.05               # mm: a loop beside the model takes at least this more than the stock to leave
_SLIVER = 0.02              # mm: unreachable material thinner than this is the offsets' rounding
_MIN_RAMP = 0.25            # a ramp follows a pass at least this many tool diameters long; a region whose
                            # whole outline is shorter (its tool centre fits in a spot) is not entered
_BYTES_PER_POINT = 160      # a loop point: polygons (float and Clipper's integers), segments, moves
HELIX_MIN_PERCENT = 10.0    # a helix narrower than a tenth of the tool is a plunge turning on the spot


@dataclass
class RoughingParams(StrategyParams, WholeToolParams):  # + the whole tool (holder_guard)
    stock_box: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)   # xmin, ymin, zmin, xmax, ymax, zmax of the stock (mm)
    step_down: float = param(2.0, "step-down", "mm", low=0, low_open=True, kind="length")
    layer_mode: str = param("fixed", "layers", choices=("fixed", "tolerance"))   # tolerance: seed eq. 3.11
    remaining_height: float = param(0.1, "remaining material", "mm", low=0, low_open=True)  # delta of eq. 3.10
    flat_layers: bool = param(True, "extra layers on flat areas", choices=(True, False))
    stepover_percent: float = param(40.0, "step-over", "%", low=0, high=100, low_open=True, high_open=True)
    stock_to_leave: float = param(0.5, "stock to leave", "mm", low=0)                 # radial
    stock_to_leave_axial: Optional[float] = param(None, "axial stock to leave", "mm", optional=True, low=0)
    pattern: str = param("offset", "pattern", choices=("offset", "zigzag"))
    direction: str = param("climb", "direction", choices=("climb", "conventional"))
    entry: str = param("helix", "entry", choices=("helix", "ramp", "plunge"))       # plunge: the tool can
    ramp_angle_deg: float = param(3.0, "ramp angle", "deg", low=RAMP_ANGLE.low, high=RAMP_ANGLE.high)
    helix_diameter_percent: float = param(50.0, "helix diameter", "%", low=HELIX_MIN_PERCENT, high=100)
    final_z: Optional[float] = param(None, "final depth", "mm", optional=True)  # default: model's lowest + axial stock
    chord_tol: float = param(0.01, "chord tolerance", "mm", low=FINEST_MM, high=1.0)
    keep_tool_down: bool = param(True, "keep tool down", choices=(True, False))
    stock_heights: Optional[Any] = None   # optional (Grid, heights) of a stock that is not a box, or of what an
                                          # earlier op left (rest roughing): only where material lies is cut

    @property
    def axial(self) -> float:
        return self.stock_to_leave if self.stock_to_leave_axial is None else self.stock_to_leave_axial

    def validate(self) -> None:
        super().validate()
        if len(self.stock_box) != 6:
            raise TmmError(f"stock box must be six finite numbers xmin, ymin, zmin, xmax, ymax, zmax, "
                           f"got {self.stock_box!r}")
        check_finite("stock box (xmin, ymin, zmin, xmax, ymax, zmax)", self.stock_box)
        b = self.stock_box
        if not (b[3] > b[0] and b[4] > b[1] and b[5] > b[2]):
            raise TmmError(f"stock box is empty: x {b[0]:g}..{b[3]:g}, y {b[1]:g}..{b[4]:g}, "
                           f"z {b[2]:g}..{b[5]:g} mm")
        if self.stock_heights is not None:
            try:
                grid, heights = self.stock_heights
                heights = np.asarray(heights, dtype=float)
                shape_ok = heights.shape == (grid.ny, grid.nx)
            except (TypeError, ValueError, AttributeError):
                raise TmmError("stock heights must be a (Grid, heights) pair with heights of shape (ny, nx)")
            if not shape_ok:
                raise TmmError(f"stock heights have shape {heights.shape}, the grid {grid.ny} x {grid.nx}")
            if not np.isfinite(heights).all():
                raise TmmError("stock heights must be finite numbers of mm")

    def stepover(self, cutter: Cutter) -> float:
        return self.stepover_percent / 100.0 * cutter.diameter


def _check(mesh: TriMesh, cutter: Cutter, params: RoughingParams) -> tuple[float, float]:
    """(stock top, final layer height) after the checks that need the model and the tool."""
    if cutter.kind not in SUPPORTED_TOOLS:
        raise TmmError(f"the {cutter.describe()} cutter is not supported by z-level roughing "
                       f"(supported: {', '.join(SUPPORTED_TOOLS)})")
    for label, s in (("stock to leave", params.stock_to_leave), ("axial stock to leave", params.axial)):
        if s > cutter.diameter:
            raise TmmError(f"{label} {s:g} mm is larger than the tool (diameter {cutter.diameter:g} mm; "
                           f"allowed: 0 to {cutter.diameter:g} mm)")
    if math.isfinite(cutter.cutting_length) and params.step_down > cutter.cutting_length:
        raise TmmError(f"step-down {params.step_down:g} mm is larger than the cutting length "
                       f"{cutter.cutting_length:g} mm of the {cutter.describe()} cutter")
    b = params.stock_box
    lo, hi = mesh.bounds
    eps = 1e-6
    if lo[0] < b[0] - eps or lo[1] < b[1] - eps or hi[0] > b[3] + eps or hi[1] > b[4] + eps or lo[2] < b[2] - eps:
        raise TmmError(f"the model (x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}, z {lo[2]:g}..{hi[2]:g} mm) "
                       f"lies outside the stock (x {b[0]:g}..{b[3]:g}, y {b[1]:g}..{b[4]:g}, z {b[2]:g}..{b[5]:g})")
    if hi[2] > b[5] + eps:
        raise TmmError(f"the stock is not above the model: its top {b[5]:g} mm is below the model's top "
                       f"{hi[2]:g} mm")
    final = float(lo[2]) + params.axial + layers_mod.PLATEAU_LIFT if params.final_z is None else float(params.final_z)
    if final < b[2] - eps:
        raise TmmError(f"final depth {final:g} mm is below the stock's bottom {b[2]:g} mm")
    top = float(b[5])
    if params.stock_heights is not None:
        top = min(top, float(np.max(params.stock_heights[1])))
    if not top > final:
        raise TmmError(f"the stock is not above the model: its top {top:g} mm is not above the final depth "
                       f"{final:g} mm (the model's lowest point plus the axial stock to leave)")
    return top, final


def layer_heights(mesh: TriMesh, cutter: Cutter, params: RoughingParams, top: float, final: float) -> np.ndarray:
    """The layers' tip heights, descending (zlevel_layers)."""
    if params.layer_mode == "fixed":
        zs = layers_mod.fixed_layers(top, final, params.step_down)
    else:
        zs = layers_mod.tolerance_layers(mesh, cutter, top, final, params.step_down, params.remaining_height,
                                         params.axial)
    if params.flat_layers:
        zs = layers_mod.with_plateaus(zs, layers_mod.plateau_heights(mesh), top, final, params.axial,
                                      params.remaining_height)
    return zs


def layer_count(params: RoughingParams, cutter: Cutter) -> int:
    """Layers over the stock's height at the step-down (tolerance mode: the shallowest layer eq. 3.11
    allows), before the model is known: what the estimates count."""
    b = params.stock_box
    depth = params.step_down
    if params.layer_mode == "tolerance":
        depth = min(depth, layers_mod.tolerance_depth(cutter, params.remaining_height, 0.0))
    return max(1, math.ceil((b[5] - b[2]) / depth))


def count_work(params: RoughingParams, cutter: Cutter, layers: Optional[int] = None) -> float:
    """Loop points over all layers (layers x loops x points, an upper bound: every loop as long as the
    stock's outline, at the waterline's sample spacing), refused above the limits before any is made.
    `layers` when known; else from the step-down (tolerance mode: the shallowest layer eq. 3.11 allows)."""
    b = params.stock_box
    w, h = b[3] - b[0], b[4] - b[1]
    if layers is None:
        layers = layer_count(params, cutter)
    s = params.stepover(cutter)
    loops = math.ceil(min(w, h) / (2 * s)) + 2
    spacing = wl.default_sample_step(cutter, (0, 0, w + 2 * cutter.diameter, h + 2 * cutter.diameter))
    points = 2 * (w + h + 4 * cutter.diameter) / spacing * wl._REFINE_FACTOR
    # every loop may be entered (an upper bound), each entry's descent as the linker makes it
    count = float(layers) * loops * (points + entry_points(params, cutter))
    check_work("roughing loop points", count, _BYTES_PER_POINT,
               f"{layers} layers (step-down {params.step_down:g} mm), step-over {params.stepover_percent:g} % "
               f"of D{cutter.diameter:g} over a {w:.6g} x {h:.6g} mm stock, entry {params.entry} at ramp angle "
               f"{params.ramp_angle_deg:g} deg, helix diameter {params.helix_diameter_percent:g} %")
    return count


def estimate_work(params: RoughingParams, cutter: Cutter, bounds: Box) -> Work:
    """Roughing's work (core.work; its stock is the params', `bounds` the model's box, unused): an upper bound,
    every layer clearing the whole stock outline at the step-over."""
    params.validate()
    layers = layer_count(params, cutter)
    b = params.stock_box
    count = count_work(params, cutter, layers)
    return Work(count, "roughing loop points", None, layers * (b[3] - b[0]) * (b[4] - b[1]) / params.stepover(cutter),
                paces=(("roughing", count),))


def entry_points(params: RoughingParams, cutter: Cutter) -> float:
    """Points of one entry's descent through a layer (the step-down and the clearance above the material) as
    core.linking makes them: a helix's chords at the arc tolerance; a ramp's walk along a loop, at most as dense
    as the chords of the shortest loop a ramp follows (a circle _MIN_RAMP tool diameters round)."""
    if params.entry == PLUNGE:
        return 1.0
    run = (params.step_down + _ENTRY_CLEARANCE) / math.tan(math.radians(params.ramp_angle_deg))
    tol = max(1e-4, params.chord_tol / 2)
    r = params.helix_diameter_percent / 100.0 * cutter.diameter / 2.0
    dt = 2.0 * math.acos(1.0 - tol / r) if tol < r else math.pi / 4
    helix = (run / r + 2 * math.pi) / dt
    shortest = _MIN_RAMP * cutter.diameter / (2 * math.pi)
    ramp = run / math.sqrt(8.0 * shortest * tol) + 2
    return helix + ramp   # a helix that finds no room falls back to a ramp


def wall_margin(params: RoughingParams) -> float:
    """mm (horizontal) the blocked region is grown by before it is taken from the tool-centre box: the
    waterline's chords lie within chord_tol of the exact loop, on either side (this growth is mitred: it
    reaches at least as far as the round one), and Clipper's round joins of the erosions within half of
    it, so no pass comes nearer the model than the stock to leave. Walls keep up to this much more.
    (Growing the cutter instead would not do: on a slope a cutter grown by m moves its waterline by less
    than m; found by simulation on sphere_on_plate.)"""
    return 2.0 * params.chord_tol + 1e-4


def _profile_height(cutter: Cutter, rho: float) -> float:
    """Height of the cutter's lower surface above its tip at radius rho (ball, flat, bull-nose)."""
    R, r = cutter.radius, cutter.corner_radius
    rho = min(max(rho, 0.0), R)
    flat = R - r
    if rho <= flat:
        return 0.0
    return r - math.sqrt(max(0.0, r * r - (rho - flat) ** 2))


class _Steps:
    """Progress over the phases (waterlines, then layers) with cancel."""

    def __init__(self, progress: Optional[Progress]) -> None:
        self.progress = progress
        self.last = 0.0          # the fraction reached (the layers' loop sets it)

    def part(self, lo: float, hi: float) -> Optional[Progress]:
        if self.progress is None:
            return None
        return lambda f: self.progress(lo + (hi - lo) * min(max(f, 0.0), 1.0))

    def at(self, f: float) -> None:
        if self.progress is not None and self.progress(f) is False:
            raise Cancelled("roughing cancelled")

    def cancelled(self) -> bool:
        """For the long loops inside a layer: the progress callback answered False."""
        return self.progress is not None and self.progress(self.last) is False


class _Context:
    """What the layers share: the tool, the stock, the swept areas of the layers above (for entry heights)."""

    def __init__(self, cutter: Cutter, params: RoughingParams, top: float) -> None:
        self.cutter = cutter
        self.params = params
        self.top = top
        self.R = cutter.radius
        self.D = cutter.diameter
        self.s = params.stepover(cutter)
        self.arc_tol = max(1e-4, params.chord_tol / 2)
        self.climb = params.direction == "climb"
        # after a layer, its regions swept by this much are down to the layer plus `floor_cusp`
        self.reach = min(self.s, self.R)
        self.floor_cusp = _profile_height(cutter, self.reach)
        self.swept: list[tuple[float, P.Shape]] = []
        self.helix_r = params.helix_diameter_percent / 100.0 * cutter.diameter / 2.0
        self.not_entered: list[str] = []    # regions and passes too small to enter (see _MIN_RAMP)

    def material_xy(self, z: float) -> P.Shape:
        b = self.params.stock_box
        if self.params.stock_heights is None:
            return [P.rectangle(b[0], b[1], b[3], b[4])]
        grid, heights = self.params.stock_heights
        heights = np.asarray(heights, dtype=float)
        rects = []
        xs0 = grid.x0 + np.arange(grid.nx) * grid.cell
        for j in range(grid.ny):
            above = np.concatenate([[False], heights[j] > z + _FLOOR_NOISE, [False]]).astype(np.int8)
            edges = np.flatnonzero(np.diff(above))
            y0 = grid.y0 + j * grid.cell
            for a, e in zip(edges[::2], edges[1::2]):
                rects.append(P.rectangle(xs0[a], y0, xs0[e - 1] + grid.cell, y0 + grid.cell))
        return P.intersection(P.union(rects), [P.rectangle(b[0], b[1], b[3], b[4])]) if rects else []

    def material_top(self, footprint: P.Shape) -> float:
        """The highest the material can be over `footprint` now: the lowest earlier layer whose swept area
        covers it (plus the floor cusp), else the stock's top there."""
        top = self.top
        if self.params.stock_heights is not None:
            grid, heights = self.params.stock_heights
            x0, y0, x1, y1 = P.bounds(footprint)
            i0, i1 = int((x0 - grid.x0) // grid.cell) - 1, int((x1 - grid.x0) // grid.cell) + 2
            j0, j1 = int((y0 - grid.y0) // grid.cell) - 1, int((y1 - grid.y0) // grid.cell) + 2
            sub = np.asarray(heights)[max(0, j0):max(0, j1), max(0, i0):max(0, i1)]
            if sub.size:
                top = min(top, float(sub.max()))
        for z, swept in reversed(self.swept):   # the lowest layer first
            if P.covers(swept, footprint):
                return min(top, z + self.floor_cusp)
        return top


def _region_label(z: float, region: P.Region) -> str:
    x0, y0, x1, y1 = P.bounds([region.outer])
    return (f"the region at z {z:.4g} mm, x {x0:.4g}..{x1:.4g}, y {y0:.4g}..{y1:.4g} mm "
            f"({region.area:.3g} mm^2 of tool-centre positions)")


def _helix_centre(ctx: _Context, region: P.Region, pas: clearing.Pass
                  ) -> Optional[tuple[np.ndarray, np.ndarray, clearing.Pass]]:
    """(centre, helix end, the pass rotated to start at its vertex next to the end) with the helix disc in
    the region and the straight move from the helix end to the pass inside it; None if there is no room."""
    rh = ctx.helix_r
    room = P.offset(region.shape, -(rh + 1e-3), ctx.arc_tol)
    if not room:
        return None
    cands = np.vstack(room)
    mid = pas.xy.mean(axis=0)
    order = np.argsort(np.sum((cands - mid) ** 2, axis=1))[:24]
    for c in cands[order]:
        k = int(np.argmin(np.sum((pas.xy - c) ** 2, axis=1))) if pas.closed else 0
        q = pas.xy[k]
        d = q - c
        n = float(np.hypot(*d))
        end = c + (rh * d / n if n > 1e-9 else np.array([rh, 0.0]))
        if P.segment_inside(end, q, region.shape):
            xy = np.roll(pas.xy, -k, axis=0)
            return c, end, clearing.Pass(xy, pas.closed, pas.level, pas.outer)
    return None


def _tips(xy: np.ndarray, z: float, closed: bool) -> np.ndarray:
    pts = np.vstack([xy, xy[:1]]) if closed else xy
    return np.column_stack([pts, np.full(len(pts), z)])


def _enter(ctx: _Context, z: float, region: P.Region, pas: clearing.Pass, joined: bool) -> CutSegment:
    """The segment of `pas` with its entry (or joined to the previous one)."""
    p = ctx.params
    if joined:
        return CutSegment(_tips(pas.xy, z, pas.closed), joined=True, closed=pas.closed)
    if p.entry == PLUNGE:   # the linker's rapid down ends above what earlier layers left over the tool
        top = ctx.material_top([P.circle(pas.xy[0], ctx.R + ctx.arc_tol)])
        return CutSegment(_tips(pas.xy, z, pas.closed), entry=PLUNGE, entry_z=top, closed=pas.closed)
    if p.entry == HELIX:
        found = _helix_centre(ctx, region, pas)
        if found is not None:
            c, end, pas = found
            tips = np.vstack([[[end[0], end[1], z]], _tips(pas.xy, z, pas.closed)])
            footprint = [P.circle(c, ctx.helix_r + ctx.R + ctx.arc_tol)]
            top = ctx.material_top(footprint) + _ENTRY_CLEARANCE
            return CutSegment(tips, entry=HELIX, entry_z=top, helix_centre=(float(c[0]), float(c[1])),
                              helix_ccw=ctx.climb, closed=False)
    length = _length(pas)
    if length >= _MIN_RAMP * ctx.D:
        footprint = P.offset_open([pas.xy], ctx.R + ctx.arc_tol, ctx.arc_tol, closed=pas.closed)
        top = ctx.material_top(footprint) + _ENTRY_CLEARANCE
        return CutSegment(_tips(pas.xy, z, pas.closed), entry=RAMP, entry_z=top, closed=pas.closed)
    what = f"no room for a helix of diameter {2 * ctx.helix_r:g} mm and " if p.entry == HELIX else ""
    raise _NoEntry(f"cannot enter {_region_label(z, region)}: {what}its pass is {length:.3g} mm long, shorter "
                   f"than the {_MIN_RAMP * ctx.D:g} mm ({_MIN_RAMP:g} tool diameter) a ramp needs; use a smaller "
                   f"helix diameter, a smaller tool, or entry 'plunge' if the tool can cut straight down")


class _NoEntry(TmmError):
    """No helix fits and the pass is too short to ramp along."""


def _length(pas: clearing.Pass) -> float:
    xy = np.vstack([pas.xy, pas.xy[:1]]) if pas.closed else pas.xy
    return float(np.hypot(*np.diff(xy, axis=0).T).sum())


def _air_approach(ctx: _Context, z: float, region: P.Region, tool_centres: P.Shape, material_reach: P.Shape
                  ) -> Optional[tuple[np.ndarray, int]]:
    """(a point beside the stock where the tool stands in air, the index of the outer loop's vertex it is
    fed to) if the region is open to the outside; the straight move between them lies in the tool-centre
    region, so it is gouge-free, and the tool there touches no material at any height."""
    outer = region.outer
    n = len(outer)
    step = max(1, n // 48)
    d = ctx.s + _AIR_MARGIN
    for k in range(0, n, step):
        a, b = outer[k - 1], outer[(k + 1) % n]
        t = b - a
        tl = float(np.hypot(*t))
        if tl <= 0:
            continue
        normal = np.array([t[1], -t[0]]) / tl   # outward of a counter-clockwise loop
        p = outer[k] + d * normal
        if not P.contains_point(material_reach, p) and P.segment_inside(p, outer[k], tool_centres):
            return p, k
    return None


def _clear_region(ctx: _Context, z: float, region: P.Region, tool_centres: P.Shape, material_reach: P.Shape,
                  steps: _Steps) -> list[CutSegment]:
    p = ctx.params
    approach = _air_approach(ctx, z, region, tool_centres, material_reach)
    open_region = approach is not None
    if p.pattern == "offset":
        passes = clearing.offset_passes(region, ctx.s, climb=ctx.climb, outside_in=open_region,
                                        arc_tol=ctx.arc_tol, cancelled=steps.cancelled)
    else:
        passes = clearing.zigzag_passes(region, ctx.s, climb=ctx.climb, arc_tol=ctx.arc_tol)
    passes += clearing.fill_gaps(region, passes, ctx.R, ctx.arc_tol)
    start = None
    if open_region:
        air, k = approach
        start = region.outer[k]
        # the outer boundary goes first, from the vertex the air approach reaches
        first = next(i for i, q in enumerate(passes) if q.outer)
        passes.insert(0, passes.pop(first))
    passes = clearing.order_from(passes, start)
    out: list[CutSegment] = []
    prev_end: Optional[np.ndarray] = None
    for i, pas in enumerate(passes):
        joined = False
        if i > 0 and p.keep_tool_down and prev_end is not None:
            q = pas.xy[0]
            joined = float(np.hypot(*(q - prev_end))) <= ctx.D and P.segment_inside(prev_end, q, region.shape)
        if i == 0 and open_region:
            tips = np.vstack([[[air[0], air[1], z]], _tips(pas.xy, z, pas.closed)])
            # down through air beside the material: none at or above z under the tool there (material_reach)
            seg = CutSegment(tips, entry=PLUNGE, entry_z=z, closed=False)
        else:
            try:
                seg = _enter(ctx, z, region, pas, joined)
            except _NoEntry as exc:
                # a spot where the tool centre just fits (a valley's bottom, a fill of a gap): left, and
                # reported; anything larger has room for a ramp along its outline, so this is an error
                if i == 0 and _length(clearing.Pass(region.outer, True)) >= _MIN_RAMP * ctx.D:
                    raise TmmError(str(exc)) from None
                ctx.not_entered.append(str(exc).split(": ")[0].replace("cannot enter ", ""))
                if i == 0:
                    return []
                prev_end = None
                continue
        seg.kind = SegmentKind.PASS
        out.append(seg)
        prev_end = seg.tips[-1, :2]
    return out


def _has_room(shape: P.Shape) -> bool:
    return any(r.area > _MIN_REGION_AREA for r in P.regions(shape))


def compute(mesh: TriMesh, cutter: Cutter, params: RoughingParams, progress: Optional[Progress] = None,
            surface: Optional[DropSurface] = None) -> StrategyResult:
    """Z-level roughing of the stock down to `mesh` plus stock to leave with `cutter`, as cut segments with
    their entries. diagnostics: "layers" (count), "layer_z" (their heights), "regions", "points" (tips),
    "unreachable" (mm^2 summed over layers: stock the tool cannot reach above the model plus stock to leave,
    narrower than the tool), "top" (highest tip), "entries" (count per kind), "not_entered" (the regions and
    passes too small for any entry (a spot the tool centre just fits), left uncut)."""
    params.validate()
    top, final = _check(mesh, cutter, params)
    count_work(params, cutter)
    zs = layer_heights(mesh, cutter, params, top, final)
    count_work(params, cutter, len(zs))
    steps = _Steps(progress)
    steps.at(0.0)
    b = params.stock_box
    s_r, s_a = params.stock_to_leave, params.axial
    grow = cutter.radius + s_r + _AIR_MARGIN + params.stepover(cutter)
    outer = P.rectangle(b[0] - grow, b[1] - grow, b[3] + grow, b[4] + grow)
    bounds = (b[0] - grow, b[1] - grow, b[3] + grow, b[4] + grow)
    surface = surface or DropSurface(mesh)
    grown = cutter.offset(s_r)
    sample = wl.default_sample_step(cutter, bounds)
    levels = [float(z) - s_a for z in zs]
    loops = wl.waterline_loops(surface, grown, levels, bounds, sample_step=sample, chord_tol=params.chord_tol,
                               progress=steps.part(0.0, 0.45))
    # the model plus stock to leave sliced at each layer (a ball of radius s dropped, raised by s, is the top
    # of the model offset by s; a needle for s = 0): what is left outside the tool's reach and is not model
    needle = Cutter.flat(2e-3).offset(s_r)
    slices = wl.waterline_loops(surface, needle, levels, bounds, sample_step=sample, chord_tol=params.chord_tol,
                                progress=steps.part(0.45, 0.6))
    ctx = _Context(cutter, params, top)
    segments: list[CutSegment] = []
    unreachable = 0.0
    region_count = 0
    for k, z in enumerate(zs):
        steps.last = 0.6 + 0.4 * k / len(zs)
        steps.at(steps.last)
        blocked = P.offset(P.union([lp.xy for lp in loops[k]]), wall_margin(params), ctx.arc_tol, miter=True)
        tool_centres = P.difference([outer], blocked)
        material = ctx.material_xy(float(z))
        if not material or not tool_centres:
            continue
        # where the tool standing touches material at or above z: a descent outside it is through air (the
        # stock is a height field; what earlier layers or ops cleared below the top is air too)
        material_reach = P.offset(material, ctx.R + 1e-3, ctx.arc_tol)
        # the first loop round the material takes a step-over of it (or the tool's radius, for step-overs
        # past half the diameter: an erosion by s - R would cut the stock's corners off)
        touching = P.offset(material, max(ctx.R - ctx.s, 0.0), ctx.arc_tol)
        cut_shape = P.intersection(tool_centres, touching)
        if params.stock_heights is None and not _has_room(cut_shape):
            # no room there, the model standing closer to the box stock's edge than that (a thin margin, a
            # block in a box): the positions within a step-over of the model's offset that take more than the
            # stock to leave of the material (the loop round the model takes what the margin holds, less than a
            # step-over; a thinner strip is left to the finishing as the stock to leave is). Not on a stock of
            # heights: its cells' edges stand past what an earlier op left on the walls
            hugging = P.intersection(P.offset(material, ctx.R - s_r - _TOUCH, ctx.arc_tol),
                                     P.offset(blocked, ctx.s, ctx.arc_tol))
            cut_shape = P.intersection(tool_centres, hugging)
        regions = [r for r in P.regions(cut_shape) if r.area > _MIN_REGION_AREA]
        for region in regions:
            segments += _clear_region(ctx, float(z), region, tool_centres, material_reach, steps)
        region_count += len(regions)
        swept = P.offset(cut_shape, ctx.reach, ctx.arc_tol) if cut_shape else []
        ctx.swept.append((float(z), swept))
        model = P.union([lp.xy for lp in slices[k]])
        reach = P.offset(cut_shape, ctx.R, ctx.arc_tol) if cut_shape else []
        left = P.difference(P.difference(material, reach), model)
        opened = P.offset(P.offset(left, -_SLIVER, ctx.arc_tol), _SLIVER, ctx.arc_tol)
        unreachable += P.area(opened)
    steps.at(1.0)
    kinds: dict[str, int] = {}
    for seg in segments:
        if not seg.joined:
            kinds[seg.entry or PLUNGE] = kinds.get(seg.entry or PLUNGE, 0) + 1
    pts = sum(len(sg) for sg in segments)
    diagnostics = {"layers": len(zs), "layer_z": [float(z) for z in zs], "regions": region_count, "points": pts,
                   "unreachable": unreachable, "top": float(max(zs)) if len(zs) else top, "entries": kinds,
                   "stock_top": top, "not_entered": list(ctx.not_entered)}
    step = wl.default_sample_step(cutter, params.stock_box[:2] + params.stock_box[3:5])
    return StrategyResult(holder_guard.apply(mesh, params, segments, step, surface, diagnostics), diagnostics)


def compute_roughing_toolpath(mesh: TriMesh, cutter: Cutter, params: RoughingParams, policy: LinkPolicy,
                              progress: Optional[Progress] = None,
                              surface: Optional[DropSurface] = None) -> Toolpath:
    """The strategy and the linker (vertical retracts; the entries the segments carry, at the params'
    ramp angle) in one call."""
    policy = dataclasses.replace(policy, entry=params.entry, ramp_angle_deg=params.ramp_angle_deg,
                                 arc_tol=params.chord_tol)
    policy.validate()
    params.validate()
    top = float(params.stock_box[5])
    if policy.safe_height <= top:
        raise TmmError(f"safe height {policy.safe_height:g} mm is not above the stock top {top:g} mm")
    result = compute(mesh, cutter, params, progress, surface)
    return link(result.segments, policy)

