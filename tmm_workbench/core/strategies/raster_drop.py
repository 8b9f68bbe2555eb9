"""3-axis raster finishing: a raster footprint dropped on the mesh (the strategy); the linker
(core.linking) makes the tool path.

    result = compute(mesh, Cutter.ball(6), SurfaceParams(boundary=(0, 0, 100, 80), stepover=0.5))
    path = link(result.segments, LinkPolicy(safe_height=40, clearance_height=45))
    path = compute_surface_toolpath(mesh, cutter, params, policy)       # both in one call

Every cutting move, including the links between zig-zag passes, is made of dropped CL points, so straight
moves only join positions no more than `sample_step` apart: a zig-zag link is a LINK segment joined to its
passes (the tool stays down). Work is estimated from the parameters before anything is allocated.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.adaptive_raster import adaptive_pass_offsets
from tmm_workbench.core.footprint.cusp import MIN_CUSP, check_cusp, steepest_crossing_deg, stepover_for_cusp
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, pass_count, raster_lines, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.params import StrategyParams, check_finite, param
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import CutSegment, SegmentKind, StrategyResult
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

ZIGZAG = "zigzag"
ONEWAY = "oneway"
SPIRAL = "spiral"  # an Archimedean spiral from the region's centre (core.footprint.spiral)
OUTWARD, INWARD = "outward", "inward"
# Where no triangle lies under the cutter ("air": beside an open surface or a relief without a base, in a
# hole): FLOOR runs the tool along the floor there, as a drop-cutter does; SKIP does not cut there: the pass
# is split, the tool lifts to the safe height and plunges again where the model resumes.
STEPOVER, CUSP, ADAPTIVE = "stepover", "cusp", "adaptive"
OFFSET3D = "offset3d"  # closed loops from the region's edge inward by the cusp height (core.strategies.raster_offset3d)
OFF_MODEL_FLOOR = "floor"
OFF_MODEL_SKIP = "skip"
# The forward step along a pass: SAMPLED keeps the samples (reduce_chords thins them, above only); TOLERANCE
# replaces them by the fewest moves within +-chord_tol of the exact CL path (core.strategies.raster_lean).
SAMPLED, TOLERANCE = "sample", "tolerance"
SUPPORTED_TOOLS = ("ball", "flat", "bull", "general")  # Cutter.kind values: any APT cutter drops
_AIR_DEPTH_MM = 1e6  # SKIP drops onto a floor this far below the model: only air points end there
_COLLINEAR_MM = 1e-7  # points this close to the chord of their neighbours add nothing to the path
# Per CL point: the xy, z and segment arrays, the kernel's copies and the tool path's moves after thinning.
_BYTES_PER_POINT = 400
_LEAVE_SHARE = 0.1   # the cusp modes' moves pass at most this share of the cusp above the exact drop height (their
                     # spacing counts the tool at the CL points: material a move leaves above them is not in it)


@dataclass
class SurfaceParams(StrategyParams):
    boundary: Rect = (0.0, 0.0, 0.0, 0.0)  # xmin, ymin, xmax, ymax of the tip positions (mm)
    stepover: float = param(1.0, "step-over", "mm", low=0, low_open=True, kind="length")
    sample_step: float = param(0.5, "sample step", "mm", low=0, low_open=True, kind="length")
    angle_deg: float = param(0.0, "raster angle", "deg")                # from +X
    pattern: str = param(ZIGZAG, "pattern", choices=(ZIGZAG, ONEWAY, SPIRAL))
    stock_to_leave: float = param(0.0, "stock to leave", "mm")        # material left on the surface
    floor_z: Optional[float] = param(None, "floor", "mm", optional=True)  # default: the model's lowest point
    off_model: str = param(OFF_MODEL_FLOOR, "off-model", choices=(OFF_MODEL_FLOOR, OFF_MODEL_SKIP))
    # the deepest a straight move may pass below the exact drop height between its CL points (raster_refine;
    # 0: not checked)
    gouge_tol: float = param(0.005, "gouge tolerance between CL points", "mm", low=0)
    # how far above the CL points a longer straight move may pass where it replaces them (flats and even
    # slopes become a few long moves; never below a CL point: 0 keeps every point off a straight line)
    chord_tol: float = param(0.001, "chord tolerance", "mm", low=0, high=1.0)
    # how the passes are spaced: STEPOVER (the step-over above), CUSP (constant: the step-over that keeps the
    # cusp height at the region's worst crossing, slope and curvature, up to max_slope_deg;
    # core.footprint.cusp_section) or
    # ADAPTIVE (each pass placed from the previous one's CL points so the cusp between them is the cusp height;
    # core.footprint.adaptive_raster)
    stepover_mode: str = param(STEPOVER, "step-over mode", choices=(STEPOVER, CUSP, ADAPTIVE, OFFSET3D))
    cusp: float = param(0.01, "cusp height", "mm", low=MIN_CUSP)
    max_slope_deg: float = param(75.0, "cusp slope limit", "deg", low=0, high=90, low_open=True, high_open=True)
    # --- machining region, spiral and slope range (issue 14 item 3: core.strategies.raster_region) ---
    # polygons with holes (core.polygons Shape) where the tool centre may go; None: the boundary rectangle.
    # `boundary` is then the region's box.
    region: Optional[list] = None
    # 3D offset from a chosen curve (issue 14 item 1): XY polylines (open or closed, (n, 2) each) the passes are
    # offset from, to both sides across the region; None: from the region's boundary inward
    offset_from: Optional[list] = None
    spiral_direction: str = param(OUTWARD, "spiral direction", choices=(OUTWARD, INWARD))
    # keep only CL points whose surface slope lies in [slope_min_deg, slope_max_deg] (0..90: all)
    slope_min_deg: float = param(0.0, "slope minimum", "deg", low=0, high=90)
    slope_max_deg: float = param(90.0, "slope maximum", "deg", low=0, high=90)
    # lean passes (issue 14 item 2, core.strategies.raster_lean): the forward step by the chord tolerance
    forward_step: str = param(SAMPLED, "forward step", choices=(SAMPLED, TOLERANCE))
    arcs: bool = param(False, "arc fitting", choices=(True, False))  # G2/G3 in XZ/YZ (TOLERANCE only)
    # --- verification pass (issue 14 item 4, core.footprint.variable_step): the pass set cut in the simulation,
    # extra partial passes where its cusp exceeds `cusp`; each pass set's VerifyReport is appended to verify_notes
    verify_cusp: bool = param(False, "verify cusp", choices=(True, False))
    verify_notes: Optional[list] = None
    # the cusp modes' pass set measured as the verification measures it, no passes added: cells left above the
    # cusp reported (diagnostics["cusp_check"], a CuspCheck appended to verify_notes; core.footprint.cusp_check);
    # "auto": where it is cheap (a small region), "on": always, "off"
    cusp_check: str = param("auto", "cusp check", choices=("auto", "on", "off"))

    def validate(self) -> None:
        super().validate()
        if len(self.boundary) != 4:
            raise TmmError(f"boundary must be four finite numbers xmin, ymin, xmax, ymax, got {self.boundary!r}")
        check_finite("boundary (xmin, ymin, xmax, ymax)", self.boundary)
        from tmm_workbench.core.strategies import raster_region

        raster_region.validate(self)
        if self.verify_cusp:
            from tmm_workbench.core.footprint.variable_step import validate_params

            validate_params(self)


def raster_points(params: SurfaceParams) -> float:
    """CL points of the raster (passes and zig-zag links, an upper bound), from the parameters alone."""
    b = params.boundary
    w, h = b[2] - b[0], b[3] - b[1]
    if not (w > 0 and h > 0):
        raise TmmError(f"boundary is empty: x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g}")
    diagonal = math.hypot(w, h)
    passes = pass_count(diagonal, params.stepover)
    count = passes * (diagonal / params.sample_step + 2)
    if params.pattern == ZIGZAG:
        count += passes * (params.stepover / params.sample_step + 2)
    if params.pattern == SPIRAL:  # the spiral out to the region's farthest point (core.footprint.spiral)
        from tmm_workbench.core.footprint.spiral import spiral_length
        from tmm_workbench.core.strategies.raster_region import spiral_radius

        count = spiral_length(spiral_radius(params), params.stepover) / params.sample_step + 8 * passes
    return count


def estimate_work(params: SurfaceParams) -> float:
    """raster_points, refused above the limits before any is made."""
    count = raster_points(params)
    b = params.boundary
    spacing = (f"step-over {params.stepover:g} mm" if params.stepover_mode == STEPOVER else
               f"cusp height {params.cusp:g} mm (a step-over down to {params.stepover:.3g} mm)")
    check_work("CL points", count, _BYTES_PER_POINT, f"sample step {params.sample_step:g} mm and {spacing} over a "
               f"{b[2] - b[0]:.6g} x {b[3] - b[1]:.6g} mm boundary")
    return count


def compute(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, progress: Optional[Progress] = None,
            surface: Optional[DropSurface] = None) -> StrategyResult:
    """Gouge-free raster finishing of `mesh` with `cutter` (tip positions; Z up) as cut segments.
    diagnostics: "points" (CL points dropped), "passes", "top" (highest tip on the model), and the spacing's
    (see _pass_lines). Its Python loops poll `progress` for cancel (core.cancel)."""
    with cancel.watching(progress) as report:
        return _compute(mesh, cutter, params, report, surface)


def _compute(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, progress: Optional[Progress],
             surface: Optional[DropSurface]) -> StrategyResult:
    params.validate()
    if cutter.kind not in SUPPORTED_TOOLS:
        raise TmmError(f"the {cutter.describe()} cutter is not supported by 3-axis raster finishing")
    lo, hi = mesh.bounds
    b = params.boundary
    if params.region is not None:  # said in the region's terms before the box's
        from tmm_workbench.core.footprint.region import check_overlap

        check_overlap(params.region, lo, hi)
    if b[2] <= lo[0] or b[0] >= hi[0] or b[3] <= lo[1] or b[1] >= hi[1]:
        raise TmmError(f"boundary x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g} lies outside the model "
                       f"(x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g})")
    if params.verify_cusp:  # its measurement refused before minutes of placing passes, not after
        from tmm_workbench.core.footprint.variable_step import estimate_params

        estimate_params(cutter, params)
    floor_z = float(lo[2]) if params.floor_z is None else float(params.floor_z)
    diagnostics: dict = {}
    lines = [] if params.stepover_mode == OFFSET3D else _pass_lines(mesh, cutter, params, floor_z, diagnostics, progress)
    if params.pattern == ZIGZAG:
        lines = [ln if i % 2 == 0 else ln[::-1] for i, ln in enumerate(lines)]
    # Runs of XY points: passes, and for zig-zag the links between them, dropped in one batch.
    runs: list[tuple[bool, np.ndarray]] = []  # (is_link, xy)
    chains = None  # a region or the spiral: runs in chains cut with the tool down, jumps between them
    levels = None  # the 3D offset's arrival field (its loops are level sets of it)
    if params.stepover_mode == OFFSET3D:  # 3D offset: loops from the region's edge inward
        from tmm_workbench.core.strategies import raster_offset3d, raster_region

        surface = surface or DropSurface(mesh)
        chains, levels = raster_offset3d.chains(mesh, surface, cutter, params, floor_z, diagnostics,
                                                None if progress is None else lambda f: progress(0.5 * f))
        runs = raster_region.flatten(chains)
    elif params.region is not None or params.pattern == SPIRAL:
        from tmm_workbench.core.strategies import raster_region

        chains = raster_region.chains(lines, cutter, params, diagnostics)
        runs = raster_region.flatten(chains)
    for i, ln in enumerate(lines if chains is None else ()):
        if i > 0 and params.pattern == ZIGZAG:
            link_xy = sample_segment(lines[i - 1][1], ln[0], params.sample_step)[1:-1]
            runs.append((True, link_xy))
        runs.append((False, sample_segment(ln[0], ln[1], params.sample_step)))
    xy = np.concatenate([r for _, r in runs])

    s = params.stock_to_leave
    surface = surface or DropSurface(mesh)
    skip = params.off_model == OFF_MODEL_SKIP
    air_floor = float(lo[2]) - _AIR_DEPTH_MM

    def drop(points: np.ndarray, report: Optional[Progress] = None) -> tuple[np.ndarray, np.ndarray]:
        """Tip heights (on the floor at least) and air flags of the cutter dropped at `points`."""
        zz = surface.drop(cutter.offset(s), points, (air_floor if skip else floor_z) - s, report) + s
        aa = zz <= air_floor + 1.0 if skip else np.zeros(len(zz), dtype=bool)
        return np.maximum(zz, floor_z), aa

    if progress is not None and params.stepover_mode != STEPOVER:  # the placement reported the first half
        report = progress
        progress = lambda f: report(0.5 + 0.5 * f)  # noqa: E731
    z, air = drop(xy, progress)
    if air.all():
        raise TmmError("the cutter is over no part of the model anywhere in the boundary (off-model: skip)")
    diagnostics.update(points=len(xy), passes=len(lines) if chains is None else diagnostics["passes"])
    leave = _LEAVE_SHARE * params.cusp if params.stepover_mode != STEPOVER else math.inf
    if params.gouge_tol > 0 or math.isfinite(leave):
        from tmm_workbench.core.strategies import raster_refine

        runs, z, air, diagnostics["between"] = raster_refine.refine(
            runs, z, air, drop, params.gouge_tol or math.inf, chained=params.pattern in (ZIGZAG, SPIRAL),
            leave_tol=leave)
    if params.slope_min_deg > 0 or params.slope_max_deg < 90:
        from tmm_workbench.core.strategies import raster_region

        air = raster_region.slope_flags(runs, z, air, drop, cutter, params, diagnostics)
    diagnostics["top"] = float(z[~air].max())
    lean = params.forward_step == TOLERANCE and params.chord_tol > 0
    if chains is None:
        segments = _segments(runs, z, air, params.pattern, 0.0 if lean else params.chord_tol)
    else:  # lean passes start from the unthinned points
        segments = raster_region.segments(runs, z, air, replace(params, chord_tol=0.0) if lean else params, chains,
                                          _segments)
    if lean:  # the kernel's fit (core.strategies.lean_kernel): lines, and arcs where the pass lies in XZ / YZ
        from tmm_workbench.core.strategies.lean_kernel import ExactDrop, lean_segments_kernel

        exact = ExactDrop(surface.index, cutter.offset(s), (air_floor if skip else floor_z) - s, s, floor_z,
                          air_floor + 1.0 if skip else -math.inf)
        segments, diagnostics["lean"] = lean_segments_kernel(
            segments, exact, params.chord_tol, params.sample_step / 2, progress=progress, arcs=params.arcs)
    if params.verify_cusp:  # issue 14 item 4
        from tmm_workbench.core.footprint.variable_step import verify_params

        n = len(segments)
        segments = verify_params(mesh, cutter, params, segments, drop, surface, diagnostics, progress, levels)
        if lean and len(segments) > n:  # its partial passes (cut into its simulation as sampled) fitted as well
            extra, stats = lean_segments_kernel(segments[n:], exact, params.chord_tol, params.sample_step / 2,
                                                progress=progress, arcs=params.arcs)
            segments = segments[:n] + extra
            for key, value in stats.items():
                diagnostics["lean"][key] = diagnostics["lean"].get(key, 0) + value
    from tmm_workbench.core.footprint import cusp_check

    if cusp_check.applies(params):  # (skipped, and said, when its work is above the limits)
        cusp_check.report_params(mesh, cutter, params, segments, surface, diagnostics)
    return StrategyResult(segments, diagnostics)


def _pass_lines(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, floor_z: float, diagnostics: dict,
                progress: Optional[Progress]) -> list[np.ndarray]:
    """The raster's passes ((2, 2) start and end each, across the boundary in order) by the step-over mode;
    the work is estimated before any pass is dropped. diagnostics: "stepover" (the largest gap, mm) and, by
    cusp, "cusp_slope_deg" / "cusp_planar_stepover" / "cusp_section" / "cusp_limited" / "cusp_creases" (constant; the
    section rule's worst cusp, core.footprint.cusp_section) or "cusps" / "cusp_limited" / "cusp_unreachable" (adaptive)."""
    b = params.boundary
    mode = params.stepover_mode
    if mode != STEPOVER:
        check_cusp(cutter, params.cusp)
    if mode == STEPOVER:
        stepover = params.stepover
    elif mode == CUSP:
        slope = steepest_crossing_deg(mesh, b, params.angle_deg, params.max_slope_deg)
        # issue 14 item 1: the planar rule at the steepest crossing ignores the curvature across the passes; the
        # step is the worst pair's over sampled CL sections (core.footprint.cusp_section)
        from tmm_workbench.core.footprint.cusp_section import section_stepover

        step = section_stepover(mesh, cutter, b, params.angle_deg, params.cusp, floor_z, params.stock_to_leave,
                                params.max_slope_deg, stepover_for_cusp(cutter, params.cusp, slope))
        stepover = step.stepover
        diagnostics.update(cusp_slope_deg=slope, cusp_planar_stepover=step.planar, cusp_section=step.cusp,
                           cusp_limited=int(step.limited), cusp_creases=step.creases)
    else:
        # the adaptive placement drops its passes on the way (its own work estimate, then pass by pass)
        estimate_work(replace(params, stepover=stepover_for_cusp(cutter, params.cusp, params.max_slope_deg)))
        placed = adaptive_pass_offsets(mesh, cutter, b, params.angle_deg, params.cusp, params.sample_step,
                                       floor_z, params.stock_to_leave, params.max_slope_deg,
                                       None if progress is None else lambda f: progress(0.5 * f))
        diagnostics.update(cusps=placed.cusps, cusp_limited=placed.limited, cusp_unreachable=placed.unreachable,
                           stepover=float(np.diff(placed.offsets).max()))
        a = math.radians(params.angle_deg)
        d, n = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
        return [seg for seg in (clip_line_to_rect(c * n, d, b) for c in placed.offsets) if seg is not None]
    estimate_work(replace(params, stepover=stepover))
    diagnostics["stepover"] = stepover
    return raster_lines(b, stepover, params.angle_deg)


def compute_surface_toolpath(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, policy: LinkPolicy,
                             progress: Optional[Progress] = None,
                             surface: Optional[DropSurface] = None) -> Toolpath:
    """The strategy and the linker (3-axis: vertical retracts) in one call."""
    policy.validate()
    result = compute(mesh, cutter, params, progress, surface)
    top = result.diagnostics["top"]
    if policy.safe_height <= top:
        raise TmmError(f"safe height {policy.safe_height:g} mm is not above the highest tool position "
                       f"{top:.4g} mm")
    return link(result.segments, policy)


def _segments(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray,
              pattern: str, chord_tol: float = 0.0) -> list[CutSegment]:
    """Segments in cutting order. A pass is split where it crosses air; a zig-zag link that crosses air is
    left out. A segment is `joined` when the tool reaches it without a retract."""
    out: list[CutSegment] = []
    detach = True
    k = 0
    index = -1  # pass number (a link belongs to the pass it leads to)
    for is_link, xy in runs:
        index += 0 if is_link else 1
        pts, gap = np.column_stack([xy, z[k:k + len(xy)]]), air[k:k + len(xy)]
        k += len(xy)
        if is_link:
            if gap.any():
                detach = True
            elif len(pts):
                out.append(CutSegment(pts, SegmentKind.LINK, joined=not detach, pass_index=index + 1))
                detach = False
            continue
        if pattern == ONEWAY:
            detach = True
        # consecutive on-model points: [start, end) index pairs
        edges = np.flatnonzero(np.diff(np.concatenate([[True], gap, [True]]).astype(np.int8)))
        for start, end in zip(edges[::2], edges[1::2]):
            out.append(CutSegment(reduce_chords(pts[start:end], chord_tol), joined=not (detach or start > 0),
                                  pass_index=index))
            detach = False
        if len(gap) and gap[-1]:
            detach = True
    return out


def reduce_chords(pts: np.ndarray, tol: float) -> np.ndarray:
    """The points of one straight pass (XY on one line, in order) thinned so that each straight move that
    replaces some passes no more than `tol` above any of them and never below one (by more than
    _COLLINEAR_MM): the exact CL path is the sampled one, and a chord above all its vertices is above the
    sampled polyline everywhere (both linear in between), so nothing gouges that did not before. Greedy
    from each kept point: the feasible slopes of the chord form an interval that every skipped point
    narrows (a sleeve), O(n)."""
    n = len(pts)
    if n < 3:
        return pts
    xy = pts[:, :2]
    d = xy[-1] - xy[0]
    length = float(np.hypot(*d))
    if length <= 0:  # all on one XY point (a closed 3D offset loop also ends where it starts: kept as it is)
        return pts[[0, -1]] if np.ptp(pts[:, 2]) <= _COLLINEAR_MM and np.ptp(xy, axis=0).max() <= _COLLINEAR_MM else pts
    u = d / length
    s = (xy - xy[0]) @ u                                   # distance along the pass
    off = np.abs((xy - xy[0]) @ np.array([-u[1], u[0]]))  # off the pass line (none, for a raster pass)
    if off.max() > _COLLINEAR_MM or np.any(np.diff(s) < 0):
        return pts  # not one straight, ordered pass: keep it as it is
    steps = np.flatnonzero(np.diff(s) <= _COLLINEAR_MM)  # vertical moves (raster_refine's cliff corners)
    if len(steps):  # each side reduced on its own, the vertical moves kept
        cuts = np.concatenate([[0], steps + 1, [n]])
        return np.vstack([reduce_chords(pts[a:b], tol) for a, b in zip(cuts[:-1], cuts[1:])])
    z = pts[:, 2]
    keep = [0]
    a = 0
    lo, hi = -math.inf, math.inf
    for j in range(1, n):
        ds = s[j] - s[a]
        m = (z[j] - z[a]) / ds
        if j > a + 1 and not (lo <= m <= hi):
            keep.append(j - 1)                               # the chord a -> j - 1 was the last that held
            a = j - 1
            ds = s[j] - s[a]
            lo, hi = -math.inf, math.inf
        # j becomes a point a later chord from a must pass: on or above it, within tol
        lo = max(lo, (z[j] - _COLLINEAR_MM - z[a]) / ds)
        hi = min(hi, (z[j] + tol - z[a]) / ds)
    keep.append(n - 1)
    return pts[np.unique(keep)]
