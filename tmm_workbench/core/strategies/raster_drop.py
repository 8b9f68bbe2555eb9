"""3-axis raster finishing: a raster footprint dropped on the mesh (the strategy); the linker
(core.linking) makes the tool path.

    result = compute(mesh, Cutter.ball(6), SurfaceParams(boundary=(0, 0, 100, 80), stepover=0.5))
    path = link(result.segments, LinkPolicy(safe_height=40, clearance_height=45))
    path = compute_surface_toolpath(mesh, cutter, params, policy)       # both in one call

Every cutting move, including the links between zig-zag passes, is made of dropped CL points, so straight
moves only join positions no more than `sample_step` apart: a zig-zag link is a LINK segment joined to its
passes (the tool stays down). Work is estimated from the parameters before anything is allocated.

The Surface's shared declarations (SurfaceParams, its mode and pattern names, raster_points) are
core.strategies.surface.params's, the pass segments core.strategies.surface.segments's, re-exported here; the
verification stage (surface.variable_step) and the check (surface.cusp_check) run after positioning, given this
module's compute for their dense raster.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.adaptive_raster import adaptive_pass_offsets
from tmm_workbench.core.footprint.cusp import check_cusp, steepest_crossing_deg, stepover_for_cusp
from tmm_workbench.core.footprint.raster import clip_line_to_rect, raster_lines, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import StrategyResult
from tmm_workbench.core.strategies.surface.params import (  # noqa: F401 - the Surface's names, used from here
    _BYTES_PER_POINT, ADAPTIVE, CUSP, INWARD, OFF_MODEL_FLOOR, OFF_MODEL_SKIP, OFFSET3D, ONEWAY, OUTWARD, SAMPLED,
    SPIRAL, STEPOVER, TOLERANCE, ZIGZAG, SurfaceParams, raster_points)
from tmm_workbench.core.strategies.surface.segments import _COLLINEAR_MM, reduce_chords  # noqa: F401
from tmm_workbench.core.strategies.surface.segments import segments as _segments
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

SUPPORTED_TOOLS = ("ball", "flat", "bull", "general")  # Cutter.kind values: any APT cutter drops
_AIR_DEPTH_MM = 1e6  # SKIP drops onto a floor this far below the model: only air points end there
_LEAVE_SHARE = 0.1   # the cusp modes' moves pass at most this share of the cusp above the exact drop height (their
                     # spacing counts the tool at the CL points: material a move leaves above them is not in it)


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
        from tmm_workbench.core.strategies.surface.variable_step import estimate_params

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
        from tmm_workbench.core.strategies.surface.variable_step import verify_params

        n = len(segments)
        segments = verify_params(mesh, cutter, params, segments, drop, surface, diagnostics, progress, levels,
                                 compute)
        if lean and len(segments) > n:  # its partial passes (cut into its simulation as sampled) fitted as well
            extra, stats = lean_segments_kernel(segments[n:], exact, params.chord_tol, params.sample_step / 2,
                                                progress=progress, arcs=params.arcs)
            segments = segments[:n] + extra
            for key, value in stats.items():
                diagnostics["lean"][key] = diagnostics["lean"].get(key, 0) + value
    from tmm_workbench.core.strategies.surface import cusp_check

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
