"""What FreeCAD's 3D Surface users expect of the 3-axis raster, around raster_drop's strategy: the step-over
in % of the tool diameter, a final depth (no tip below it), several finishing passes over a semi-finish stock
to leave (pass k of n leaves stock_to_leave + (n - 1 - k) * step_down, the last one the finish) and a start
point (each pass set begins at the corner of the raster nearest to it).

    fp = FinishParams(passes=3, step_down=0.5, start_xy=(0, 0))
    path = compute_finish_toolpath(mesh, cutter, surface_params, fp, policy)

With the defaults (one pass, no final depth, no start point) the tool path is raster_drop's, unchanged.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.linking import LinkPolicy, know_op_design, link
from tmm_workbench.core.params import Spec, StrategyParams, check_finite, param
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.segments import CutSegment, StrategyResult
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.raster_drop import STEPOVER, SurfaceParams
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

MAX_PASSES = 50
STEPOVER_PERCENT = Spec("step-over", "%", low=0.0, high=100.0, low_open=True)  # of the tool diameter


@dataclass
class FinishParams(StrategyParams):
    passes: int = param(1, "finishing passes", low=1, high=MAX_PASSES, integer=True)
    # the extra stock each earlier pass leaves over the next one (only used with passes > 1)
    step_down: float = param(0.5, "finishing step-down", "mm", low=0, low_open=True, kind="length")
    # no tool tip below it (None: the model's lowest point, raster_drop's floor)
    final_depth: Optional[float] = param(None, "final depth", "mm", optional=True)
    start_xy: Optional[tuple[float, float]] = None  # None: the raster's own order

    def validate(self) -> None:
        super().validate()
        if self.start_xy is not None:
            if len(self.start_xy) != 2:
                raise TmmError(f"start point must be two finite numbers x, y, got {self.start_xy!r}")
            check_finite("start point (x, y)", self.start_xy)

    def stock_levels(self, stock_to_leave: float) -> list[float]:
        """The stock to leave of each pass in cutting order: the semi-finish passes first, the finish last."""
        return [stock_to_leave + k * self.step_down for k in range(self.passes - 1, -1, -1)]


def stepover_of_percent(percent: float, cutter: Cutter) -> float:
    """The step-over in mm for `percent` of the tool diameter (roughing's rule, RoughingParams.stepover)."""
    if not (0.0 < percent <= 100.0):
        raise TmmError(f"step-over must be in (0, 100] % of the tool diameter, got {percent:g} %")
    return percent / 100.0 * cutter.diameter


def start_order(segments: list[CutSegment], start_xy: Optional[tuple[float, float]]) -> list[CutSegment]:
    """The segments of one pass set in the order that begins with the pass nearest `start_xy`, at its end
    nearest it: as they are or reversed as a whole (every path runs backwards too: links and joins stay), and
    when no segment is joined to the one before (one-way passes, lifts between them) also each run the other
    way or the set in reverse order. Ties keep the earlier candidate (as they are first)."""
    if start_xy is None or not segments:
        return segments
    candidates = [segments, reverse_path(segments)]
    if not any(s.joined for s in segments):
        candidates += [list(reversed(segments)), [_flipped(s, s.joined) for s in segments]]
    keys = [start_key(c[0].tips, start_xy) for c in candidates]
    return candidates[min(range(len(keys)), key=keys.__getitem__)]


def start_key(tips: np.ndarray, start_xy: tuple[float, float]) -> tuple[float, float]:
    """(distance of the start point from the line of the first pass, from its first point), mm: the nearest
    pass first, then its nearer end. Rounded to 1e-6 mm so that the two ends of one pass tie on the first."""
    target = np.asarray(start_xy, dtype=float)
    a, b = tips[0, :2], tips[-1, :2]
    point = float(np.hypot(*(a - target)))
    length = float(np.hypot(*(b - a)))
    d, t = b - a, target - a
    line = abs(float(d[0] * t[1] - d[1] * t[0])) / length if length > 1e-9 else point
    return round(line, 6), round(point, 6)


def reverse_path(segments: list[CutSegment]) -> list[CutSegment]:
    """The same cuts run backwards: segments in reverse order, each reversed (arcs too); a segment is joined
    when the one that followed it was joined to it, and the move into its first tip is then that one's first
    move backwards (the arc into that one's first tip, turned)."""
    n = len(segments)
    out = []
    for i in range(n):
        after = segments[n - i] if i > 0 else None  # the segment that followed this one
        joined = after is not None and after.joined
        into = after.arc(0) if joined and len(after) else None
        out.append(_flipped(segments[n - 1 - i], joined, None if into is None else into.reversed()))
    return out


def _flipped(seg: CutSegment, joined: bool, into_first: Optional[Arc] = None) -> CutSegment:
    """`seg` run backwards; `into_first`: the arc of the move that now ends at its first tip (joined)."""
    axes = None if seg.axes is None else seg.axes[::-1].copy()
    return replace(seg, tips=seg.tips[::-1].copy(), axes=axes, arcs=seg.reversed_arcs(into_first), joined=joined,
                   entry_z=None, helix_centre=None)


def estimate_work(params: SurfaceParams, finish: FinishParams) -> float:
    """CL points of all the passes (raster_drop's estimate per pass set), refused above the limits before any
    is made. The cusp spacings are estimated per pass set by raster_drop as it places them."""
    if params.stepover_mode != STEPOVER or finish.passes == 1:
        return 0.0
    per_set = raster_drop.count_points(params)
    check_work("CL points", per_set * finish.passes, raster_drop._BYTES_PER_POINT,
               f"{finish.passes} finishing passes of sample step {params.sample_step:g} mm and step-over "
               f"{params.stepover:g} mm")
    return per_set * finish.passes


def compute_finish_toolpath(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, finish: FinishParams,
                            policy: LinkPolicy, progress: Optional[Progress] = None,
                            surface: Optional[DropSurface] = None) -> Toolpath:
    """The raster's pass sets (one per stock level, the finish last), each from the end nearest the start
    point, linked into one tool path (retract between the sets)."""
    params.validate()
    finish.validate()
    policy.validate()
    know_op_design(policy, mesh, params)   # plunges fed only through what stands off the design
    if finish.passes == 1 and finish.final_depth is None and finish.start_xy is None:
        return raster_drop.compute_surface_toolpath(mesh, cutter, params, policy, progress, surface)  # as before
    estimate_work(params, finish)
    if finish.final_depth is not None:
        params = replace(params, floor_z=float(finish.final_depth))
    levels = finish.stock_levels(params.stock_to_leave)
    surface = surface or DropSurface(mesh)
    segments: list[CutSegment] = []
    top = -np.inf
    for i, stock in enumerate(levels):
        report = None
        if progress is not None:
            report = lambda f, i=i: progress((i + f) / len(levels))  # noqa: E731
        result, pass_set = _pass_set(mesh, cutter, replace(params, stock_to_leave=stock), finish.start_xy, report,
                                     surface)
        top = max(top, result.diagnostics["top"])
        if pass_set:
            pass_set[0] = replace(pass_set[0], joined=False)  # a retract between the sets
        segments += pass_set
    if policy.safe_height <= top:
        raise TmmError(f"safe height {policy.safe_height:g} mm is not above the highest tool position "
                       f"{top:.4g} mm")
    return link(segments, policy)


def _pass_set(mesh: TriMesh, cutter: Cutter, params: SurfaceParams, start_xy: Optional[tuple[float, float]],
              progress: Optional[Progress], surface: DropSurface
              ) -> tuple[StrategyResult, list[CutSegment]]:
    """(the raster's result, its segments begun nearest the start point) of one pass set. A zig-zag can only be
    run forwards or backwards; the raster turned by 180 degrees (the same passes in the other order, each run the
    other way) starts at the mirror image of these ends through the boundary's centre, and is computed when that
    would start nearer (an even pass count: the other two corners)."""
    result = raster_drop.compute(mesh, cutter, params, progress, surface)
    segments = start_order(result.segments, start_xy)
    if start_xy is None or not segments:
        return result, segments
    b = params.boundary
    centre = np.array([(b[0] + b[2]) / 2.0, (b[1] + b[3]) / 2.0, 0.0])
    best = start_key(segments[0].tips, start_xy)
    mirrored = [2.0 * centre - seg.tips for seg in (result.segments[0], reverse_path(result.segments)[0])]
    if min(start_key(m, start_xy) for m in mirrored) < best:
        other = raster_drop.compute(mesh, cutter, replace(params, angle_deg=params.angle_deg + 180.0), progress,
                                    surface)
        other_segments = start_order(other.segments, start_xy)
        if other_segments and start_key(other_segments[0].tips, start_xy) < best:
            return other, other_segments
    return result, segments
