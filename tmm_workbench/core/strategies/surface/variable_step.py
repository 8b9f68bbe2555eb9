"""Variable side step (seed 003 section 4.1): the Surface's verification stage over a raster's pass set.

The pass set is cut into the stock simulation and its cusp measured as core.sim.cusp_field defines it (along the
normal, slopes up to the slope limit, reachable cells only). Cells whose cusp exceeds the tolerance are grouped
into buckets as the seed does: by the gap between two neighbouring passes they lie in (the passes that cover the
cell's position along the raster) and by the stretch along the passes (cells closer than two tool radii along
the gap join one stretch). Each bucket gets extra passes in its gap, evenly spaced at the smaller step its
largest cusp needs (the cusp grows about as the step squared), over its stretch only and extended by a tool
radius at both ends: partial passes, with lifts between them, clipped to the boundary. They are dropped like
the raster's own (same drop, gouge check between CL points, chord thinning), cut into the simulation strip by
strip (only the cells under the new pass are simulated again), and the round repeats until no measured cell
exceeds the tolerance or the round limit is reached; what stays is reported, as are the cells the tool cannot
reach (not cusps: pencil or a smaller tool's work) and the steep cells (waterline's).

The 3D offset's loops (step-over mode offset3d) are verified the same way; their gaps are read from the
arrival field whose level sets they are, and a bucket's extra pass is the level set half way between its two
loops, over its cells (`_Levels`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.cusp import check_cusp
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.geometry.ordering import nearest_first
from tmm_workbench.core.linking import LinkPolicy, heights_top, link
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import CutSegment, SegmentKind
from tmm_workbench.core.sim.cusp_field import CuspField, cusp_field
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.strategies import raster_refine
from tmm_workbench.core.strategies.surface.cusp_check import from_field
from tmm_workbench.core.strategies.surface.measure import (  # noqa: F401 - measure_cell: the measurement's
    Compute, dense_raster, estimate_work, measure_cell)
from tmm_workbench.core.strategies.surface.params import ONEWAY, validate_verify
from tmm_workbench.core.strategies.surface.segments import segments as cut_segments
from tmm_workbench.core.tools.cutter import Cutter

Drop = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # xy -> (tip z, air flags): raster_drop's drop
ROUNDS = 4
# Cells count as exceeding above this share of the tolerance (the cells sample the ridge: a finer grid finds it a
# little higher), and the extra passes aim at TARGET of it.
_EXCEED = 0.95
_TARGET = 0.8


@dataclass
class Bucket:
    round: int
    lower: float            # across-offsets of the gap's passes, mm
    upper: float
    start: float            # along the passes: the stretch's cells, mm (a raster's; NaN for the 3D offset's)
    end: float
    cells: int              # exceeding cells
    max_cusp: float         # mm
    added: int              # extra passes put in the gap over the stretch
    where: Optional[np.ndarray] = None   # the 3D offset's: the cells' tips (XY), the worst first


@dataclass
class VerifyReport:
    tolerance: float
    cell: float
    max_cusp_before: float        # mm, the cells' largest (core.sim.cusp_field: what the benchmarks measure)
    max_cusp_after: float = 0.0
    ridge_before: float = 0.0     # mm, with the crests between cells (CuspField.ridge_cusp: what decides)
    ridge_after: float = 0.0
    exceeding_before: int = 0     # measured cells above the tolerance
    exceeding_after: int = 0
    measured: int = 0             # cells measured
    unreachable: int = 0          # cells on the model, not steep, out of the tool's reach
    steep: int = 0                # cells steeper than the slope limit
    deepest: float = 0.0          # mm the simulated stock lies below the design at most (a gouge when > 0)
    rounds: int = 0
    passes_added: int = 0         # extra (partial) passes
    links: int = 0                # of them, reached from the previous one on the surface (no lift)
    link_length: float = 0.0      # mm of those links (cutting on the surface, not in length_added)
    length_added: float = 0.0     # mm of cutting along them
    buckets: list = field(default_factory=list)
    seconds: float = 0.0
    check: Any = None             # cusp_check.CuspCheck of the final measurement (where cells stay above)

    @property
    def within(self) -> bool:
        return self.exceeding_after == 0

    def summary(self) -> str:
        head = (f"verify cusp {self.tolerance:g} mm: simulated max cusp {self.max_cusp_before:.4f} -> "
                f"{self.max_cusp_after:.4f} mm (crests {self.ridge_before:.4f} -> {self.ridge_after:.4f}), "
                f"{self.passes_added} partial passes added ({self.length_added:.0f} mm) in "
                f"{len({(b.lower, b.upper) for b in self.buckets})} gaps, {self.rounds} rounds")
        tail = f"; {self.unreachable} cells out of the tool's reach, {self.steep} steeper than the slope limit " \
               f"(not measured, of {self.measured + self.unreachable + self.steep})"
        if not self.within:
            head += f"; {self.exceeding_after} cells still above the tolerance after the round limit"
        return head + tail

    def as_dict(self) -> dict:
        out = {k: v for k, v in self.__dict__.items() if k not in ("buckets", "check")}
        out["buckets"] = len(self.buckets)
        return out


def _nanmax(a: np.ndarray) -> float:
    return float(np.nanmax(a)) if np.isfinite(a).any() else 0.0


class _Passes:
    """A raster's gaps: the straight passes of the set, their across-offset and the along-range each covers (a
    pass split by air is several). A bucket's extra passes are evenly spaced in its gap, over its stretch."""

    serpentine = True   # consecutive partial passes alternate their direction
    join = 2.0          # tool diameters: partial passes closer than this are joined on the surface

    def __init__(self, angle_deg: float) -> None:
        a = math.radians(angle_deg)
        self.d = np.array([math.cos(a), math.sin(a)])
        self.n = np.array([-math.sin(a), math.cos(a)])
        self.rows: list[tuple[float, float, float]] = []  # (offset, u0, u1)

    def add(self, tips: np.ndarray) -> bool:
        xy = tips[:, :2]
        v = xy @ self.n
        if len(xy) < 2 or np.ptp(v) > 1e-6:
            return False
        u = xy @ self.d
        self.rows.append((float(np.median(v)), float(u.min()), float(u.max())))
        return True

    def gaps(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per point (u along, v across): the nearest covering pass's offset at or below v and above it (NaN
        when there is none on that side)."""
        lower = np.full(len(u), -np.inf)
        upper = np.full(len(u), np.inf)
        for c, u0, u1 in self.rows:
            cover = (u >= u0 - 1e-6) & (u <= u1 + 1e-6)
            below, above = cover & (c <= v), cover & (c > v)
            lower[below] = np.maximum(lower[below], c)
            upper[above] = np.minimum(upper[above], c)
        return np.where(np.isfinite(lower), lower, np.nan), np.where(np.isfinite(upper), upper, np.nan)

    def buckets(self, tips: np.ndarray, values: np.ndarray, round_: int, tolerance: float,
                join: float) -> list[Bucket]:
        """The exceeding cells' tips grouped by gap and by stretch along it (see the module)."""
        u, v = tips @ self.d, tips @ self.n
        lower, upper = self.gaps(u, v)
        inside = np.isfinite(lower) & np.isfinite(upper)
        out: list[Bucket] = []
        keys = np.column_stack([lower[inside], upper[inside]])
        u, values = u[inside], values[inside]
        if not len(keys):
            return out
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        for k, (lo, hi) in enumerate(uniq):
            sel = np.flatnonzero(inverse.ravel() == k)
            order = sel[np.argsort(u[sel])]
            breaks = np.flatnonzero(np.diff(u[order]) > join) + 1
            for part in np.split(order, breaks):
                top = float(values[part].max())
                # cusp ~ step^2: m sub-gaps of width w / m give top / m^2 <= TARGET x tolerance
                m = max(2, math.ceil(math.sqrt(top / (_TARGET * tolerance)) - 1e-9))
                out.append(Bucket(round_, float(lo), float(hi), float(u[part].min()), float(u[part].max()),
                                  len(part), top, m - 1))
        return sorted(out, key=lambda b: (b.lower, b.start))

    def lines(self, b: Bucket, boundary: Rect, run_on: float, sample_step: float) -> list[np.ndarray]:
        """The bucket's partial passes (XY, sampled), in its gap over its stretch and `run_on` beyond."""
        out = []
        for i in range(1, b.added + 1):
            c = b.lower + (b.upper - b.lower) * i / (b.added + 1)
            line = clip_line_to_rect(c * self.n, self.d, boundary)
            if line is None:
                continue
            ua, ub = line @ self.d
            ua, ub = max(min(ua, ub), b.start - run_on), min(max(ua, ub), b.end + run_on)
            if ub - ua > 1e-9:
                out.append(sample_segment(c * self.n + ua * self.d, c * self.n + ub * self.d, sample_step))
        return out


class _Levels:
    """The 3D offset's gaps (core.footprint.offset_field): its loops are the level sets {T = k} of one arrival
    field, so the gap a tip lies in is read from T there. In round r the gaps are intervals of T 2^(1-r) wide
    (between loops k and k + 1 in the first round, halves in the second, ...) and a bucket's extra pass is the
    level set at its gap's middle (half way between its loops, in local steps), over the bucket's cells and
    `run_on` beyond. Buckets: a gap's cells closer than `join` to each other. The cusp falls as the step squared,
    so a halving brings a cusp up to 4 x TARGET within; a higher one is halved again in the next round."""

    serpentine = False  # the partial passes of a round in nearest-first order (nearest_first)
    join = 4.0          # tool diameters: partial passes closer than this are joined on the surface (the pieces
                        # are short and scattered: a lift costs more than a longer link)

    def __init__(self, field: Any) -> None:
        self.field = field
        self._lines: dict[float, list[np.ndarray]] = {}

    def add(self, tips: np.ndarray) -> bool:
        return True

    def buckets(self, tips: np.ndarray, values: np.ndarray, round_: int, tolerance: float,
                join: float) -> list[Bucket]:
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        from scipy.spatial import cKDTree

        t = self.field.at(tips)
        ok = np.isfinite(t)
        tips, values, t = tips[ok], values[ok], t[ok]
        width = 0.5 ** (round_ - 1)
        gap = np.floor(t / width)
        out: list[Bucket] = []
        for g in np.unique(gap):
            sel = np.flatnonzero(gap == g)
            pairs = cKDTree(tips[sel]).query_pairs(join, output_type="ndarray")
            graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(sel), len(sel)))
            _, label = connected_components(graph, directed=False)
            for part in (sel[label == k] for k in range(label.max() + 1)):
                part = np.roll(part, -int(np.argmax(values[part])))  # the worst cell first
                out.append(Bucket(round_, float(g * width), float((g + 1) * width), math.nan, math.nan, len(part),
                                  float(values[part[0]]), 1, where=tips[part]))
        return sorted(out, key=lambda b: (b.lower, float(b.where[:, 0].min())))

    def _level(self, level: float) -> list[np.ndarray]:
        if level not in self._lines:
            self._lines[level] = self.field.lines(level)
        return self._lines[level]

    def lines(self, b: Bucket, boundary: Rect, run_on: float, sample_step: float) -> list[np.ndarray]:
        """The level set at the gap's middle near the bucket's cells; where it does not come near them (a
        hilltop of T below the middle), the level set through the bucket's worst cell."""
        from scipy.spatial import cKDTree

        from tmm_workbench.core import polygons
        from tmm_workbench.core.footprint import offset_field
        from tmm_workbench.core.footprint.region import box_region

        flat = self.field.flat_step
        reach = run_on + 0.5 * flat   # the cells lie up to half a gap (at most half a flat step) from its middle
        lo, hi = b.where.min(axis=0) - reach, b.where.max(axis=0) + reach
        tree = cKDTree(b.where)
        for level in (0.5 * (b.lower + b.upper), float(self.field.at(b.where[:1])[0])):
            pieces = []
            for line in self._level(level):
                if np.any(line.max(axis=0) < lo) or np.any(line.min(axis=0) > hi):
                    continue
                near = tree.query(line, distance_upper_bound=reach)[0] <= reach
                edges = np.flatnonzero(np.diff(np.concatenate([[0], near.astype(np.int8), [0]])))
                for a, e in zip(edges[::2], edges[1::2]):
                    if e - a >= 2:
                        pieces.append(line[a:e])
            pieces = polygons.clip_open(pieces, box_region(boundary)) if pieces else []
            if pieces:
                tol = min(polygons.ARC_TOL, offset_field.SIMPLIFY * flat)
                return [offset_field.resampled(offset_field.simplified(p, tol), sample_step) for p in pieces
                        if float(np.hypot(*np.diff(p, axis=0).T).sum()) > 1e-6]
        return []


def _strip(grid: Grid, tips: np.ndarray, reach: float) -> Optional[tuple[Grid, slice, slice]]:
    """The sub-grid of the cells within `reach` of the tips' XY box (where a pass can lower the stock)."""
    i0 = max(0, int(math.floor((tips[:, 0].min() - reach - grid.x0) / grid.cell)))
    i1 = min(grid.nx, int(math.ceil((tips[:, 0].max() + reach - grid.x0) / grid.cell)))
    j0 = max(0, int(math.floor((tips[:, 1].min() - reach - grid.y0) / grid.cell)))
    j1 = min(grid.ny, int(math.ceil((tips[:, 1].max() + reach - grid.y0) / grid.cell)))
    if i1 <= i0 or j1 <= j0:
        return None
    sub = Grid(grid.x0 + i0 * grid.cell, grid.y0 + j0 * grid.cell, grid.cell, i1 - i0, j1 - j0)
    return sub, slice(j0, j1), slice(i0, i1)


def _extra_segments(xy: np.ndarray, drop: Drop, gouge_tol: float, chord_tol: float) -> list[CutSegment]:
    """One partial pass (XY points at the sample step), dropped and checked as raster_drop drops its own (split
    where it crosses air)."""
    z, air = drop(xy)
    runs = [(False, xy)]
    if gouge_tol > 0:
        runs, z, air, _ = raster_refine.refine(runs, z, air, drop, gouge_tol, chained=False)
    return cut_segments(runs, z, air, ONEWAY, chord_tol)


def _surface_link(a: np.ndarray, b: np.ndarray, drop: Drop, sample_step: float,
                  gouge_tol: float) -> Optional[CutSegment]:
    """A LINK from tip a to tip b on the surface (dropped points, gouge-checked between them as raster_drop's
    zig-zag links; the tool stays down), or None where it crosses air."""
    xy = sample_segment(a[:2], b[:2], sample_step)
    z, air = drop(xy)
    if air.any():
        return None
    runs = [(True, xy)]
    if gouge_tol > 0:
        runs, z, air, _ = raster_refine.refine(runs, z, air, drop, gouge_tol, chained=False)
        if air.any():
            return None
    pts = np.column_stack([runs[0][1], z])
    # the ends are a's last and b's first tips (the same drop): only what lies between is the link's
    return CutSegment(pts[1:-1], SegmentKind.LINK, joined=True) if len(pts) > 2 else None


def verify_cusp(mesh: TriMesh, cutter: Cutter, segments: list[CutSegment], boundary: Rect, angle_deg: float,
                tolerance: float, drop: Drop, *, sample_step: float = 0.5, gouge_tol: float = 0.005,
                chord_tol: float = 0.001, stock_to_leave: float = 0.0, slope_limit_deg: float = 75.0,
                cell: Optional[float] = None, rounds: int = ROUNDS, surface: Optional[DropSurface] = None,
                progress: Optional[Progress] = None, levels: Any = None,
                compute: Optional[Compute] = None) -> tuple[list[CutSegment], VerifyReport]:
    """`segments` (a raster's pass set over `boundary`, passes along `angle_deg`; or the 3D offset's loops, the
    level sets of the arrival field `levels`, an offset_field.Field) with extra partial passes appended where the
    simulated cusp exceeds `tolerance`, and the report (see the module). `drop` drops the tool at XY points as the
    raster did (stock to leave, floor, air); `compute` makes the dense raster the cusp is measured against (the
    raster strategy's, core.strategies.raster_drop.compute). `progress` (fraction -> False to cancel) follows the dense raster,
    the bulk of the work, and is asked again before each round."""
    t0 = time.perf_counter()
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"verify cusp tolerance must be a length > 0 mm, got {tolerance!r}")
    if compute is None:
        raise TmmError("verify cusp needs the raster strategy that makes its dense raster (compute)")
    cell = measure_cell(cutter, tolerance) if cell is None else float(cell)
    estimate_work(boundary, cutter, tolerance, cell)
    surface = surface or DropSurface(mesh)
    passes: Any = _Passes(angle_deg) if levels is None else _Levels(levels)
    if levels is None:
        for seg in segments:
            if seg.kind is SegmentKind.PASS:
                passes.add(seg.tips)
        if not passes.rows:
            raise TmmError("verify cusp needs straight raster passes (ZigZag or OneWay), found none")
    # the envelope sampled a cell apart along its passes too: the path's own chords count as cusp
    fld: CuspField = cusp_field(mesh, cutter, boundary, tolerance, cell, slope_limit_deg, stock_to_leave, surface,
                                progress=progress,
                                dense=dense_raster(compute, mesh, cutter, boundary, cell, stock_to_leave))
    policy = LinkPolicy(fld.stock_top + 1.0, fld.stock_top + 5.0)
    heights = fld.cut(link(segments, policy), cutter)
    before = fld.ridge_cusp(heights)
    report = VerifyReport(tolerance, cell, fld.max_cusp(heights), ridge_before=_nanmax(before),
                          exceeding_before=int(np.sum(np.nan_to_num(before, nan=0.0) > tolerance)),
                          measured=int(fld.measured.sum()),
                          unreachable=int(fld.unreachable.sum()), steep=int(fld.steep.sum()))
    reach = cutter.native.max_radius
    to_tip = fld.contact_offset(cutter)
    # past a partial pass's end its tool still cuts the ridge beside it down to within the tolerance for about
    # sqrt(2 R tol) (the ball's end: a height (a^2 + t^2) / 2R); twice that, and a cell
    run_on = 2.0 * math.sqrt(2.0 * cutter.radius * tolerance) + cell
    extra: list[CutSegment] = []
    # consecutive partial passes (serpentine, mostly a gap's few passes over one stretch) closer than this are
    # joined on the surface instead of a lift (432 lifts on mount_rush)
    join_max = passes.join * cutter.diameter
    cusp = before
    for k in range(rounds):
        bad = np.nan_to_num(cusp, nan=0.0) > _EXCEED * tolerance
        if not bad.any():
            break
        if progress is not None and progress(1.0) is False:
            raise Cancelled("verify cusp cancelled")
        report.rounds = k + 1
        # a cell counts where the tool tip stands when it touches there (`to_tip`), since the passes are tips
        tips = fld.grid.centres()[bad.ravel()] + to_tip.reshape(-1, 2)[bad.ravel()]
        buckets = passes.buckets(tips, cusp.ravel()[bad.ravel()], k + 1, tolerance, 2 * cutter.radius)
        if not buckets:
            break
        report.buckets += buckets
        todo = [xy for b in buckets for xy in passes.lines(b, boundary, run_on, sample_step)]
        if passes.serpentine:  # the next partial pass starts near the last one's end
            todo = [xy[::-1] if i % 2 else xy for i, xy in enumerate(todo)]
        elif todo:  # from where the tool stands (the pass set is never empty here)
            todo = nearest_first(todo, (extra or segments)[-1].tips[-1, :2])
        for xy in todo:
            new = _extra_segments(xy, drop, gouge_tol, chord_tol)
            if new and extra and extra[-1].kind is SegmentKind.PASS and \
                    np.hypot(*(new[0].tips[0, :2] - extra[-1].tips[-1, :2])) <= join_max:
                bridge = _surface_link(extra[-1].tips[-1], new[0].tips[0], drop, sample_step, gouge_tol)
                if bridge is not None:
                    new[0] = CutSegment(new[0].tips, new[0].kind, joined=True, pass_index=new[0].pass_index)
                    extra.append(bridge)
                    report.links += 1
                    report.link_length += float(np.linalg.norm(np.diff(bridge.tips[:, :2], axis=0), axis=1).sum())
                    strip = _strip(fld.grid, bridge.tips, reach)
                    if strip is not None:
                        sub, rows, cols = strip
                        heights[rows, cols] = simulate(link([bridge], policy), cutter, sub,
                                                       heights[rows, cols]).heights
            for seg in new:
                if not seg.joined:  # entered from above: the rapid down ends just above what is already cut
                    seg.entry_z = _entry_top(fld, heights, cutter, seg.tips[0])
                passes.add(seg.tips)
                report.passes_added += 1
                report.length_added += float(np.linalg.norm(np.diff(seg.tips[:, :2], axis=0), axis=1).sum())
                strip = _strip(fld.grid, seg.tips, reach)
                if strip is None:
                    continue
                sub, rows, cols = strip
                heights[rows, cols] = simulate(link([seg], policy), cutter, sub, heights[rows, cols]).heights
            extra += new
        cusp = fld.ridge_cusp(heights)
    report.max_cusp_after, report.ridge_after = fld.max_cusp(heights), _nanmax(cusp)
    report.exceeding_after = int(np.sum(np.nan_to_num(cusp, nan=0.0) > tolerance))
    on_model = np.isfinite(fld.design)
    report.deepest = float(max(0.0, np.max(fld.design[on_model] + stock_to_leave - heights[on_model]))) \
        if on_model.any() else 0.0
    report.seconds = time.perf_counter() - t0
    report.check = from_field(fld, cusp, cutter.diameter)
    # the first extra segment follows the pass set after a lift; the others keep their own (joined: on the surface)
    return segments + [CutSegment(s.tips, s.kind, joined=s.joined and i > 0, pass_index=s.pass_index,
                                  entry_z=s.entry_z) for i, s in enumerate(extra)], report


def _entry_top(fld: CuspField, heights: np.ndarray, cutter: Cutter, tip: np.ndarray) -> Optional[float]:
    """The top of the material under the tool at a partial pass's first tip: the surface the pass set and the
    partial passes before it left (the simulated `heights`, the model plus the cusp), the tool dropped on it;
    None (not known: entered from the safe height) where the tool reaches a cell they did not cut (the
    simulation's stock there is a stand-in) or the grid's edge."""
    g, reach = fld.grid, cutter.radius + fld.grid.cell * 2
    i0, i1 = math.floor((tip[0] - reach - g.x0) / g.cell), math.ceil((tip[0] + reach - g.x0) / g.cell)
    j0, j1 = math.floor((tip[1] - reach - g.y0) / g.cell), math.ceil((tip[1] + reach - g.y0) / g.cell)
    if i0 < 0 or j0 < 0 or i1 > g.nx or j1 > g.ny:
        return None
    window = heights[j0:j1, i0:i1]
    known = np.where(window < fld.stock_top - 1e-9, window, np.inf)
    sub = Grid(g.x0 + i0 * g.cell, g.y0 + j0 * g.cell, g.cell, i1 - i0, j1 - j0)
    top = float(heights_top(sub, known, cutter.radius, cutter.native.height)(tip[None, :2])[0])
    return top if math.isfinite(top) else None


validate_params = validate_verify  # what the verification needs of SurfaceParams (core.strategies.surface.params)


def estimate_params(cutter: Cutter, params: Any) -> float:
    """verify_params's measurement estimated (and refused above the limits) before the passes are placed."""
    check_cusp(cutter, params.cusp)
    return estimate_work(params.boundary, cutter, params.cusp, measure_cell(cutter, params.cusp))


def verify_params(mesh: TriMesh, cutter: Cutter, params: Any, segments: list[CutSegment], drop: Drop,
                  surface: Optional[DropSurface], diagnostics: dict, progress: Optional[Progress] = None,
                  levels: Any = None, compute: Optional[Compute] = None) -> list[CutSegment]:
    """raster_drop's call: its pass set verified against `params.cusp` (diagnostics["verify"]; the report is
    appended to params.verify_notes when given); `levels` the 3D offset's arrival field (its loops'), `compute` the
    raster strategy (its dense raster is the measurement's reference)."""
    check_cusp(cutter, params.cusp)
    segments, report = verify_cusp(mesh, cutter, segments, params.boundary, params.angle_deg, params.cusp, drop,
                                   sample_step=params.sample_step, gouge_tol=params.gouge_tol,
                                   chord_tol=params.chord_tol, stock_to_leave=params.stock_to_leave,
                                   slope_limit_deg=params.max_slope_deg, surface=surface, progress=progress,
                                   levels=levels, compute=compute)
    diagnostics["verify"] = report.as_dict()
    diagnostics["cusp_check"] = report.check.as_dict()   # the final measurement: no second one by the check
    if params.verify_notes is not None:
        params.verify_notes += [report, report.check]
    return segments
