"""The 3-axis Surface's shared declarations: its parameters (SurfaceParams), their mode and pattern names and the
raster's CL point count from the parameters alone (raster_points), below the stages that use them
(core.strategies.raster_drop, raster_region, raster_offset3d and this package's)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import MIN_CUSP
from tmm_workbench.core.footprint.raster import Rect, pass_count
from tmm_workbench.core.params import StrategyParams, check_finite, param
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.strategies.holder_guard import WholeToolParams
from tmm_workbench.core.strategies.rest_filter import RestParams

ZIGZAG = "zigzag"
ONEWAY = "oneway"
SPIRAL = "spiral"  # an Archimedean spiral from the region's centre (core.footprint.spiral)
PENCIL = "pencil"  # along concave creases, an outline or a footprint file (core.footprint.pencil)
PENCIL_CREASES, PENCIL_OUTLINE, PENCIL_FILE = "creases", "outline", "file"
PENCIL_CLEANUP = "cleanup"  # seed 000's clean-up strips, CL points by translation (core.footprint.cleanup)
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
# Per CL point: the xy, z and segment arrays, the kernel's copies and the tool path's moves after thinning.
_BYTES_PER_POINT = 400


@dataclass
class SurfaceParams(StrategyParams, WholeToolParams, RestParams):  # + the whole tool (holder_guard), the rest
    boundary: Rect = (0.0, 0.0, 0.0, 0.0)  # xmin, ymin, xmax, ymax of the tip positions (mm)
    stepover: float = param(1.0, "step-over", "mm", low=0, low_open=True, kind="length")
    sample_step: float = param(0.5, "sample step", "mm", low=0, low_open=True, kind="length")
    angle_deg: float = param(0.0, "raster angle", "deg")                # from +X
    pattern: str = param(ZIGZAG, "pattern", choices=(ZIGZAG, ONEWAY, SPIRAL, PENCIL))
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
    # --- machining region, spiral and slope range (core.strategies.raster_region) ---
    # polygons with holes (core.polygons Shape) where the tool centre may go; None: the boundary rectangle.
    # `boundary` is then the region's box.
    region: Optional[list] = None
    # 3D offset from a chosen curve: XY polylines (open or closed, (n, 2) each) the passes are
    # offset from, to both sides across the region; None: from the region's boundary inward
    offset_from: Optional[list] = None
    spiral_direction: str = param(OUTWARD, "spiral direction", choices=(OUTWARD, INWARD))
    # --- pencil (pattern PENCIL, core.strategies.surface.pencil_pattern): creases found on the model (CL valleys
    # deeper than `cusp`), an outline (`pencil_curves`: closed loops and open curves, XY) offset by the radius to
    # `pencil_side`, or a footprint file's curves (`pencil_curves`); `pencil_passes` outward, `stepover` apart
    pencil_source: str = param(PENCIL_CREASES, "pencil source",
                               choices=(PENCIL_CREASES, PENCIL_OUTLINE, PENCIL_FILE, PENCIL_CLEANUP))
    # the clean-up's finishing tool (pencil source PENCIL_CLEANUP): its normal jumps find the strips
    cleanup_reference: Optional[Any] = None
    pencil_curves: Optional[list] = None
    pencil_side: str = param("outside", "pencil side", choices=("outside", "inside", "both"))
    # 0: as many as cover the rest cells (Region Rest: 95 % of them within reach of a pass), else 1
    pencil_passes: int = param(1, "pencil passes", low=0, high=50, integer=True)
    # keep only CL points whose surface slope lies in [slope_min_deg, slope_max_deg] (0..90: all)
    slope_min_deg: float = param(0.0, "slope minimum", "deg", low=0, high=90)
    slope_max_deg: float = param(90.0, "slope maximum", "deg", low=0, high=90)
    # lean passes (core.strategies.raster_lean): the forward step by the chord tolerance
    forward_step: str = param(SAMPLED, "forward step", choices=(SAMPLED, TOLERANCE))
    arcs: bool = param(False, "arc fitting", choices=(True, False))  # G2/G3 in XZ/YZ (TOLERANCE only)
    # --- verification pass (core.strategies.surface.variable_step): the pass set cut in the simulation,
    # extra partial passes where its cusp exceeds `cusp`; each pass set's VerifyReport is appended to verify_notes
    # (and the pencil source 'cleanup''s CleanupReport: core.footprint.cleanup; a rest's SteepReport:
    # core.strategies.rest_steep)
    verify_cusp: bool = param(False, "verify cusp", choices=(True, False))
    verify_notes: Optional[list] = None
    # the cusp modes' pass set measured as the verification measures it, no passes added: cells left above the
    # cusp reported (diagnostics["cusp_check"], a CuspCheck appended to verify_notes; core.strategies.surface.cusp_check);
    # "auto": where it is cheap (a small region), "on": always, "off"
    cusp_check: str = param("auto", "cusp check", choices=("auto", "on", "off"))

    def validate(self) -> None:
        super().validate()
        if len(self.boundary) != 4:
            raise TmmError(f"boundary must be four finite numbers xmin, ymin, xmax, ymax, got {self.boundary!r}")
        check_finite("boundary (xmin, ymin, xmax, ymax)", self.boundary)
        validate_region(self)
        if self.verify_cusp:
            validate_verify(self)


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
    if params.pattern == PENCIL:  # the creases' grid of drops and the curves' points (a bound)
        return crease_points(params) + params.pencil_passes * 4 * diagonal / params.sample_step
    if params.pattern == SPIRAL:  # the spiral out to the region's farthest point (core.footprint.spiral)
        from tmm_workbench.core.footprint.spiral import spiral_length

        count = spiral_length(spiral_radius(params), params.stepover) / params.sample_step + 8 * passes
    return count


def crease_cell(params: SurfaceParams) -> float:
    """The pencil's creases are looked for on a grid of half the sample step."""
    return 0.5 * params.sample_step


def crease_points(params: SurfaceParams) -> float:
    """Drops of the pencil's creases grid (0 for the other pencil sources)."""
    if params.pencil_source not in (PENCIL_CREASES, PENCIL_CLEANUP):
        return 0.0
    b, c = params.boundary, crease_cell(params)
    return ((b[2] - b[0]) / c + 2) * ((b[3] - b[1]) / c + 2)


def validate_region(params: Any) -> None:
    """The region's polygons and the slope range, by name (core.strategies.raster_region)."""
    if params.region is not None:
        if not isinstance(params.region, (list, tuple)) or not params.region:
            raise TmmError(f"region must be a list of polygons ((n, 2) arrays, mm), got {params.region!r}")
        for k, p in enumerate(params.region):
            a = np.asarray(p, dtype=float)
            if a.ndim != 2 or a.shape[1] != 2 or len(a) < 3:
                raise TmmError(f"region polygon {k + 1} must be 3 or more XY points, got shape {a.shape}")
            if not np.isfinite(a).all():
                raise TmmError(f"region polygon {k + 1} has a point that is not finite")
    if params.slope_min_deg > params.slope_max_deg:
        raise TmmError(f"slope range: minimum {params.slope_min_deg:g} deg is above the maximum "
                       f"{params.slope_max_deg:g} deg (allowed: 0 <= minimum <= maximum <= 90)")
    if params.pattern == PENCIL:
        if params.stepover_mode not in (STEPOVER, CUSP):
            raise TmmError(f"the pencil pattern spaces its passes by the step-over or the cusp height, not "
                           f"step-over mode {params.stepover_mode!r}")
        if params.pencil_source == PENCIL_CLEANUP:
            if params.cleanup_reference is None:
                raise TmmError("pencil source 'cleanup' needs the finishing tool (cleanup_reference): its normal "
                               "jumps along its paths find the strips")
        elif params.pencil_source != PENCIL_CREASES and not params.pencil_curves:
            raise TmmError(f"pencil source {params.pencil_source!r} needs its curves (an outline or a footprint "
                           f"file), got none")
    if params.pattern == SPIRAL and params.stepover_mode == ADAPTIVE:
        raise TmmError("the adaptive step-over mode places raster passes; with the spiral pattern use the "
                       "step-over or cusp mode")


def validate_verify(params: Any) -> None:
    """What the verification pass (core.strategies.surface.variable_step) needs of SurfaceParams (refused before
    any work)."""
    if params.pattern == SPIRAL:
        raise TmmError("verify cusp works on straight raster passes or the 3D offset's loops (pattern zigzag or "
                       "oneway), not spiral")
    if params.region is not None:
        raise TmmError("verify cusp works on the boundary box only for now (region Box), not on a face or sketch "
                       "region")
    if params.slope_min_deg > 0 or params.slope_max_deg < 90:
        raise TmmError(f"verify cusp measures every slope up to the cusp slope limit: set the slope range to 0..90 "
                       f"deg (got {params.slope_min_deg:g}..{params.slope_max_deg:g})")


def shape_of(params: Any) -> Shape:
    """The region's polygons, or the boundary box's."""
    from tmm_workbench.core.footprint import region as region_mod

    return params.region if params.region is not None else region_mod.box_region(params.boundary)


def spiral_radius(params: Any) -> float:
    """How far the spiral goes from its centre: to the region's farthest vertex (for the work estimate)."""
    from tmm_workbench.core.footprint import spiral

    shape = shape_of(params)
    return float(np.hypot(*(np.vstack(shape) - spiral.centre_of(shape)).T).max())
