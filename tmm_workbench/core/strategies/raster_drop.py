"""3-axis raster finishing: a raster footprint dropped on the mesh (the strategy); the linker
(core.linking) makes the tool path.

    result = compute(mesh, Cutter.ball(6), SurfaceParams(boundary=(0, 0, 100, 80), stepover=0.5))
    path = link(result.segments, LinkPolicy(safe_height=40, clearance_height=45))
    path = compute_surface_toolpath(mesh, cutter, params, policy)       # both in one call

Every cutting move, including the links between zig-zag passes, is made of dropped CL points, so straight
moves only join positions no more than `sample_step` apart: a zig-zag link is a LINK segment joined to its
passes (the tool stays down). Work is estimated from the parameters before anything is allocated.

The Surface's pipeline, one module per stage in core.strategies.surface: pattern (where the tool goes in XY) ->
positioning (the points dropped and refined) -> forward_step (segments in cutting order, the lean fit) ->
verification (variable_step's partial passes, given this module's compute for its dense raster; cusp_check's
report) -> linking (compute_surface_toolpath: core.linking). Its shared declarations (params: SurfaceParams, the
mode and pattern names, raster_points), the pass segments (segments) and the work (estimate: estimate_work, one
signature for every strategy, core.work) are re-exported here.
"""
from __future__ import annotations

import math
from typing import Optional

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import StrategyResult
from tmm_workbench.core.strategies import holder_guard, rest_filter, rest_order, rest_steep
from tmm_workbench.core.strategies.surface.params import (  # noqa: F401 - the Surface's names, used from here
    _BYTES_PER_POINT, ADAPTIVE, CUSP, INWARD, OFF_MODEL_FLOOR, OFF_MODEL_SKIP, OFFSET3D, ONEWAY, OUTWARD, SAMPLED,
    SPIRAL, STEPOVER, TOLERANCE, ZIGZAG, SurfaceParams, raster_points)
from tmm_workbench.core.strategies.surface import forward_step
from tmm_workbench.core.strategies.surface.estimate import estimate_work  # noqa: F401 - the strategy's work
from tmm_workbench.core.strategies.surface.pattern import count_points, pattern
from tmm_workbench.core.strategies.surface.positioning import _AIR_DEPTH_MM, Positioner, position  # noqa: F401
from tmm_workbench.core.strategies.surface.segments import _COLLINEAR_MM, reduce_chords  # noqa: F401
from tmm_workbench.core.strategies.surface.segments import segments as _segments  # noqa: F401
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

SUPPORTED_TOOLS = ("ball", "flat", "bull", "general")  # Cutter.kind values: any APT cutter drops
_LEAVE_SHARE = 0.1   # the cusp modes' moves pass at most this share of the cusp above the exact drop height (their
                     # spacing counts the tool at the CL points: material a move leaves above them is not in it)


def compute(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, progress: Optional[Progress] = None,
            surface: Optional[DropSurface] = None) -> StrategyResult:
    """Gouge-free raster finishing of `mesh` with `cutter` (tip positions; Z up) as cut segments.
    diagnostics: "points" (CL points dropped), "passes", "top" (highest tip on the model), and the spacing's
    (see core.strategies.surface.pattern.pass_lines). Its Python loops poll `progress` for cancel (core.cancel)."""
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
    # the model's lowest point, as far below it as a negative stock to leave cuts into the model (an explicit floor
    # is the user's final depth and stays)
    floor_z = float(lo[2]) + min(params.stock_to_leave, 0.0) if params.floor_z is None else float(params.floor_z)
    diagnostics: dict = {}
    placed, surface = pattern(mesh, cutter, params, floor_z, diagnostics, progress, surface)
    surface = surface or DropSurface(mesh)
    drop = Positioner(mesh, surface, cutter, params, floor_z)
    if progress is not None and params.stepover_mode != STEPOVER:  # the placement reported the first half
        report = progress
        progress = lambda f: report(0.5 + 0.5 * f)  # noqa: E731
    leave = _LEAVE_SHARE * params.cusp if params.stepover_mode != STEPOVER else math.inf
    runs, z, air = position(placed.runs, placed.passes, drop, cutter, params, leave, diagnostics, progress)
    lean = forward_step.is_lean(params)
    segments = forward_step.segments(runs, z, air, params, placed.chains)
    if lean:  # the kernel's fit (core.strategies.lean_kernel): lines, and arcs where the pass lies in XZ / YZ
        exact = drop.exact()
        segments, diagnostics["lean"] = forward_step.lean(segments, exact, params, progress)
    if params.verify_cusp:  # the verification stage
        from tmm_workbench.core.strategies.surface.variable_step import verify_params

        n = len(segments)
        segments = verify_params(mesh, cutter, params, segments, drop, surface, diagnostics, progress, placed.levels,
                                 compute)
        if lean and len(segments) > n:  # its partial passes (cut into its simulation as sampled) fitted as well
            extra, stats = forward_step.lean(segments[n:], exact, params, progress)
            segments = segments[:n] + extra
            for key, value in stats.items():
                diagnostics["lean"][key] = diagnostics["lean"].get(key, 0) + value
    segments = rest_filter.apply(params, cutter, segments, diagnostics)   # rest machining: only what is left
    # the whole tool: the shank and holder kept clear of the model
    segments = holder_guard.apply(mesh, params, segments, params.sample_step, surface, diagnostics)
    # a rest's slopes: waterline loops where the passes cannot hold the tolerance
    segments = rest_steep.finish(mesh, cutter, params, segments, surface, diagnostics)
    from tmm_workbench.core.strategies.surface import cusp_check

    if cusp_check.applies(params):  # (skipped, and said, when its work is above the limits)
        cusp_check.report_params(mesh, cutter, params, segments, surface, diagnostics)
    return StrategyResult(segments, diagnostics)


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
    return link(pieces_ordered(params, result.segments), policy)


def pieces_ordered(params: SurfaceParams, segments: list) -> list:
    """A zig-zag raster broken into pieces (a region's, a slope range's, the model's outline with off-model skip)
    in the rest's order (core.strategies.rest_order: nearest-first, each piece entered at its nearer end, 2-opt):
    pass by pass the tool crossed the steep parts between the pieces at every pass, lifted to the safe height
    (wheel_in_box's shallow raster: 1,434 entries, 58 m of rapids). A rest orders its own (rest_steep); offset
    passes (OFFSET3D) and one-way or spiral patterns keep theirs."""
    if params.pattern != ZIGZAG or params.stepover_mode == OFFSET3D or getattr(params, "rest", None) is not None:
        return segments
    return rest_order.ordered(segments, {id(seg) for seg in segments})
