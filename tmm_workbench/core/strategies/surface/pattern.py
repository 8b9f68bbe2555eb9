"""The Surface's first stage, the pattern: where the tool goes in XY. The raster's passes by the step-over mode
(pass_lines: the step-over, the constant cusp's section rule, the adaptive placement), turned for zig-zag, clipped
to a region or replaced by the spiral (core.strategies.raster_region) or by the 3D offset's loops (raster_offset3d),
and sampled into runs of XY points (passes and zig-zag links) for positioning (core.strategies.surface.
positioning). The work is counted from the parameters before anything is allocated (count_points)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.cancel import poll
from tmm_workbench.core.footprint.adaptive_raster import adaptive_pass_offsets
from tmm_workbench.core.footprint.cusp import check_cusp, steepest_crossing_deg, stepover_for_cusp
from tmm_workbench.core.footprint.raster import clip_line_to_rect, raster_lines, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.strategies.surface.params import (_BYTES_PER_POINT, ADAPTIVE, CUSP, INWARD, OFFSET3D, ONEWAY,
                                                          OUTWARD, PENCIL, SPIRAL, STEPOVER, ZIGZAG, SurfaceParams,
                                                          raster_points)
from tmm_workbench.core.tools.cutter import Cutter

Run = tuple[bool, np.ndarray]  # (is_link, xy)


@dataclass
class Pattern:
    runs: list[Run]                       # XY points: passes, and for zig-zag the links between them, in order
    passes: int                           # the raster's passes (a region's pieces, the 3D offset's loops)
    chains: Optional[list[list[Run]]]     # a region, the spiral or the 3D offset: runs in chains cut with the tool
                                          # down, jumps between them; None: the box's raster
    levels: Any = None                    # the 3D offset's arrival field (its loops are level sets of it)


def count_points(params: SurfaceParams) -> float:
    """raster_points, refused above the limits before any is made."""
    count = raster_points(params)
    b = params.boundary
    spacing = (f"step-over {params.stepover:g} mm" if params.stepover_mode == STEPOVER else
               f"cusp height {params.cusp:g} mm (a step-over down to {params.stepover:.3g} mm)")
    check_work("CL points", count, _BYTES_PER_POINT, f"sample step {params.sample_step:g} mm and {spacing} over a "
               f"{b[2] - b[0]:.6g} x {b[3] - b[1]:.6g} mm boundary")
    return count


def pattern(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, floor_z: float, diagnostics: dict,
            progress: Optional[Progress], surface: Optional[DropSurface]) -> tuple[Pattern, Optional[DropSurface]]:
    """The runs the tool follows (see the module), and the drop surface (made here for the 3D offset, which drops
    as it places its loops; otherwise as given)."""
    if params.pattern == PENCIL:  # curves along creases or an outline, each a chain (pencil_pattern)
        from tmm_workbench.core.strategies import raster_region
        from tmm_workbench.core.strategies.surface import pencil_pattern

        count_points(params)
        surface = surface or DropSurface(mesh)
        chains = pencil_pattern.chains(mesh, surface, cutter, params, floor_z, diagnostics)
        return Pattern(raster_region.flatten(chains), diagnostics["passes"], chains), surface
    lines = [] if params.stepover_mode == OFFSET3D else pass_lines(mesh, cutter, params, floor_z, diagnostics,
                                                                    progress)
    if params.pattern == ZIGZAG:
        lines = [ln if i % 2 == 0 else ln[::-1] for i, ln in enumerate(lines)]
    # Runs of XY points: passes, and for zig-zag the links between them, dropped in one batch.
    runs: list[Run] = []
    chains = None
    levels = None
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
        poll()   # thousands of passes sampled in Python: Cancel heard, the dialog repaints
        if i > 0 and params.pattern == ZIGZAG:
            link_xy = sample_segment(lines[i - 1][1], ln[0], params.sample_step)[1:-1]
            runs.append((True, link_xy))
        runs.append((False, sample_segment(ln[0], ln[1], params.sample_step)))
    passes = len(lines) if chains is None else diagnostics["passes"]
    return Pattern(runs, passes, chains, levels), surface


def pass_lines(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, floor_z: float, diagnostics: dict,
               progress: Optional[Progress]) -> list[np.ndarray]:
    """The raster's passes ((2, 2) start and end each, across the boundary in order) by the step-over mode;
    the work is estimated before any pass is dropped. diagnostics: "stepover" (the largest gap, mm) and, by
    cusp, "cusp_slope_deg" / "cusp_planar_stepover" / "cusp_section" / "cusp_limited" / "cusp_creases" (constant;
    the section rule's worst cusp, core.footprint.cusp_section) or "cusps" / "cusp_limited" / "cusp_unreachable"
    (adaptive)."""
    b = params.boundary
    mode = params.stepover_mode
    if mode != STEPOVER:
        check_cusp(cutter, params.cusp)
    if mode == STEPOVER:
        stepover = params.stepover
    elif mode == CUSP:
        slope = steepest_crossing_deg(mesh, b, params.angle_deg, params.max_slope_deg)
        # the planar rule at the steepest crossing ignores the curvature across the passes; the
        # step is the worst pair's over sampled CL sections (core.footprint.cusp_section)
        from tmm_workbench.core.footprint.cusp_section import section_stepover

        step = section_stepover(mesh, cutter, b, params.angle_deg, params.cusp, floor_z, params.stock_to_leave,
                                params.max_slope_deg, stepover_for_cusp(cutter, params.cusp, slope),
                                region=params.region)
        stepover = step.stepover
        diagnostics.update(cusp_slope_deg=slope, cusp_planar_stepover=step.planar, cusp_section=step.cusp,
                           cusp_limited=int(step.limited), cusp_creases=step.creases)
    else:
        # the adaptive placement drops its passes on the way (its own work estimate, then pass by pass)
        count_points(replace(params, stepover=stepover_for_cusp(cutter, params.cusp, params.max_slope_deg)))
        placed = adaptive_pass_offsets(mesh, cutter, b, params.angle_deg, params.cusp, params.sample_step,
                                       floor_z, params.stock_to_leave, params.max_slope_deg,
                                       None if progress is None else lambda f: progress(0.5 * f))
        diagnostics.update(cusps=placed.cusps, cusp_limited=placed.limited, cusp_unreachable=placed.unreachable,
                           stepover=float(np.diff(placed.offsets).max()))
        a = math.radians(params.angle_deg)
        d, n = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
        return [seg for seg in (clip_line_to_rect(c * n, d, b) for c in placed.offsets) if seg is not None]
    count_points(replace(params, stepover=stepover))
    diagnostics["stepover"] = stepover
    return raster_lines(b, stepover, params.angle_deg)


# --- the stage's declaration (core.stage) ---------------------------------------------------------------------
PATTERNS = {"ZigZag": ZIGZAG, "OneWay": ONEWAY, "Spiral": SPIRAL, "Pencil": PENCIL}
# the step-over modes; 3D offset: closed loops from the region's edge inward, CuspHeight apart across the surface
SPACINGS = {"StepOver": STEPOVER, "Cusp": CUSP, "Adaptive": ADAPTIVE, "Offset3D": OFFSET3D}
SPIRAL_DIRECTIONS = {"Outward": OUTWARD, "Inward": INWARD}


def ignored(args: Args) -> Optional[str]:
    """The spacing or pattern argument the chosen mode would not use."""
    mode = str(args.get("stepover_mode") or STEPOVER).lower()
    stepover, percent = args.get("stepover"), args.get("stepover_percent")
    if mode != STEPOVER and (stepover is not None or percent is not None):
        name = "stepover" if stepover is not None else "stepover_percent"
        return (f"{name} is not used with stepover_mode {args.get('stepover_mode')!r}: the spacing comes from the "
                "cusp height (cusp); leave it out, or use stepover_mode 'stepover'")
    if stepover is not None and percent is not None:
        return "give stepover (mm) or stepover_percent (of the tool diameter), not both"
    if mode == STEPOVER and args.get("cusp") is not None and args.get("verify_cusp") is False:
        return (f"cusp {args['cusp']!r} is not used with stepover_mode 'stepover' (passes `stepover` apart): give "
                "stepover_mode 'cusp', 'adaptive' or 'offset3d' to space the passes by it, or verify_cusp=True")
    if args.get("spiral_direction") is not None and str(args.get("pattern") or ZIGZAG).lower() != SPIRAL:
        return f"spiral_direction is used with pattern 'spiral' only, got pattern {args.get('pattern')!r}"
    return None


STAGE = Stage("pattern", (
    Field("StepOver", "length", "Surface", "Distance between raster passes", "stepover", "stepover",
          widget="stepOver"),
    Field("StepOverMode", "choice", "Surface",
          "StepOver: passes StepOver apart; Cusp: the step-over that keeps CuspHeight on the worst crossing of the "
          "boundary, slope and curvature (up to CuspSlopeLimit); Adaptive: each pass placed from the previous one's "
          "tool positions so that the cusp between them is CuspHeight", "stepover_mode", "stepover_mode",
          choices=SPACINGS, widget="stepOverMode"),
    Field("CuspHeight", "length", "Surface",
          "Largest scallop left between passes (Cusp and Adaptive spacing), along the surface normal", "cusp",
          "cusp", widget="cuspHeight"),
    Field("CuspSlopeLimit", "angle", "Surface",
          "Steeper places are not held to CuspHeight (walls are waterline's)", "max_slope_deg",
          widget="cuspSlopeLimit"),
    Field("RasterAngle", "angle", "Surface", "Direction of the passes, from +X", "angle_deg", "angle_deg",
          widget="rasterAngle"),
    Field("Pattern", "choice", "Surface",
          "ZigZag: cut both ways, linked over the surface; OneWay: cut one way, retract between passes; Spiral: "
          "from the region's centre (SpiralDirection)", "pattern", "pattern", choices=PATTERNS, widget="pattern"),
    Field("SpiralDirection", "choice", "Surface", "Spiral pattern: from the region's centre Outward, or Inward to it",
          "spiral_direction", "spiral_direction", choices=SPIRAL_DIRECTIONS, widget="spiralDirection"),
), ignored=ignored)
