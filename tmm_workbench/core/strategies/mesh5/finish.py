"""5-axis finishing of a mesh by the 3D C-space (seed 000 section 3.5.5): the strategy the op runs.

The adaptive passes (stepover.adaptive_passes: drive planes across the mesh, the C-space at every CC point,
the posture chosen for the Tarus motion time, each pass placed so that the scallop stays within the
tolerance) become cut segments, one per CC path (the tool's tips and axes of its chosen postures, and the
overruns beyond its ends, each lifted clear of the mesh), in pass
order, every other pass reversed when zig-zag. The one linker joins them (multipoint.link_policy: out and in
along the tool axis, transit above the tilted tool's lowest point), as the 5-axis multipoint op does.

    result = compute(mesh, Cutter.flat(10), Mesh5Params(tolerance=0.05))
    path = link(result.segments, link_policy(cutter, safe, clearance, axis_retract))

What no pass could finish (no posture of any gap finishes it: a groove narrower than the cutter) is never a
silent hole: `diagnostics["unfinished"]` lists its strips (feed from, to, across from, to; mm),
`diagnostics["strip_corners"]` their XY corners, `diagnostics["empty_points"]` the CC points of the strips'
middle planes that lie in them (k, 3) and `diagnostics["cleanup_points"]` points on the mesh covering them
(planes 1 mm apart), marked for clean-up; `report(diagnostics)` says them. With a tool assembly (params.assembly)
the shank and holder bound every C-space, and the cut moves are checked against the model (mesh5.holder):
`diagnostics["holder"]` says what they changed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.params import StrategyParams, param
from tmm_workbench.core.query.height_sample import HeightSample
from tmm_workbench.core.report_text import within
from tmm_workbench.core.segments import CutSegment, StrategyResult
from tmm_workbench.core.strategies.mesh5 import estimate, holder
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths, plane_normal
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid
from tmm_workbench.core.strategies.mesh5.stepover import AdaptivePlan, adaptive_passes
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.work import Box, Work

Progress = Callable[[float], bool]
SUPPORTED_TOOLS = ("flat", "bull")  # Cutter.kind values: a tilted flat bottom cuts the wide strip
_BYTES_PER_CC_POINT = 400_000       # the C-space of one CC point: its grid's lifts, tops and reach copies
CLEANUP_SPACING = 1.0               # mm between the points marking an unfinished strip
# a C-space with the shank and holder costs this many times the cutter's alone (their drop takes what lies
# under the holder's radius: one pass of seed 000's convex surface, 4.6 s against 0.77 s of CPU)
HOLDER_COST = 6.0


@dataclass
class Mesh5Params(StrategyParams):
    tolerance: float = param(0.01, "tolerance", "mm", low=0, low_open=True, high=10.0, kind="length")
    feed_angle_deg: float = param(0.0, "feed angle", "deg", low=-360.0, high=360.0)  # from +X, seen from above
    forward_step: float = param(2.0, "forward step", "mm", low=0.01, high=1000.0, kind="length")
    chord_tol: float = param(0.01, "chord tolerance", "mm", low=1e-4, high=1.0)
    tilt_min_deg: float = param(0.0, "least tilt", "deg", low=0.0, high=89.0)      # lambda, from the normal
    tilt_max_deg: float = param(45.0, "tilt limit", "deg", low=0.0, high=89.0)
    yaw_limit_deg: float = param(45.0, "yaw limit", "deg", low=0.0, high=180.0)    # omega: -limit..limit
    grid_step_deg: float = param(3.0, "posture grid step", "deg", low=0.1, high=45.0)
    zigzag: bool = True
    machine: Any = None  # the TarusMachine whose limits bound the postures (None: the TPI-2000 defaults)
    # the whole tool (core.tools.assembly): its shank and holder bound every C-space (None: the cutter alone);
    # what they changed is appended to holder_notes (app.tool_assembly.report shows it)
    assembly: Any = None
    holder_notes: Optional[list] = None

    def validate(self) -> None:
        super().validate()
        if not self.tilt_min_deg <= self.tilt_max_deg:
            raise TmmError(f"least tilt {self.tilt_min_deg:g} deg must not be above the tilt limit "
                           f"{self.tilt_max_deg:g} deg")

    def the_machine(self) -> TarusMachine:
        return TarusMachine() if self.machine is None else self.machine

    def grid(self) -> PostureGrid:
        """The (lambda, omega) grid, refused where its tilts leave the machine's C range (the tilt from the
        normal is the machine's C on a level surface)."""
        self.validate()
        lo, hi = (math.degrees(c) for c in self.the_machine().c_limits)
        for name, v in (("least tilt", self.tilt_min_deg), ("tilt limit", self.tilt_max_deg)):
            if not lo - 1e-9 <= v <= hi + 1e-9:
                raise TmmError(f"{name} {v:g} deg is outside the machine's tilt range C {lo:g}..{hi:g} deg")
        return PostureGrid.degrees((self.tilt_min_deg, self.tilt_max_deg),
                                   (-self.yaw_limit_deg, self.yaw_limit_deg), self.grid_step_deg)

    def direction(self) -> tuple[float, float]:
        a = math.radians(self.feed_angle_deg)
        return math.cos(a), math.sin(a)


def check_tool(cutter: Cutter) -> None:
    """A flat end mill or a bull-nose; anything else refused naming it."""
    if not isinstance(cutter, Cutter):
        raise TmmError(f"tool must be a core Cutter, got {type(cutter).__name__}")
    if cutter.kind not in SUPPORTED_TOOLS:
        raise TmmError(f"the {cutter.describe()} cutter is not taken by 5-axis mesh finishing: it needs a flat "
                       "end mill or a bull-nose (a tilted flat bottom cuts the wide strip)")


def count_points(extent: float, length: float, params: Mesh5Params, cutter: Cutter) -> tuple[float, int]:
    """CC points (an upper bound: passes a quarter diameter apart, the seed's first guess, each as long as
    the mesh along the feed) and passes, refused above the limits before any C-space is built."""
    passes = max(1, math.ceil(extent / (0.25 * cutter.diameter)) + 1)
    count = passes * (length / params.forward_step + 2)
    check_work("CC points", count, _BYTES_PER_CC_POINT,
               f"forward step {params.forward_step:g} mm, passes {0.25 * cutter.diameter:g} mm apart over a "
               f"{extent:.6g} x {length:.6g} mm model", "max_positions")
    return count, passes


def _extents(lo: np.ndarray, hi: np.ndarray, params: Mesh5Params) -> tuple[float, float]:
    """(across, along) the feed of the box lo..hi (its XY corners on the plane normal and the feed)."""
    d = np.array(params.direction())
    m = np.array([-d[1], d[0]])
    corners = np.array([[x, y] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
    return float(np.ptp(corners @ m)), float(np.ptp(corners @ d))


def estimate_work(params: Mesh5Params, cutter: Cutter, bounds: Box, sample: Optional[HeightSample] = None,
                  left_cell: Optional[float] = None) -> Work:
    """The CC points over the model's box `bounds` (core.work), refused above the limits on the upper bound
    (count_points); each costs a C-space and its rebuilds (with params.assembly, HOLDER_COST times as much).
    `sample`: the model's needle heights (estimate.surface_sample): the passes from the tilted cutter's width
    over its slopes (mesh5.estimate), else the upper bound's. `left_cell`: the op simulates what the finish leaves
    on cells of this size (SimulateLeft; mesh5.cleanup.left_above), its compute counted too."""
    params.validate()
    check_tool(cutter)
    across, along = _extents(np.array(bounds[:3]), np.array(bounds[3:]), params)
    count, passes = count_points(across, along, params, cutter)
    told = None if sample is None else estimate.predict_passes(
        sample, cutter, params.tolerance, params.feed_angle_deg, (params.tilt_min_deg, params.tilt_max_deg),
        params.forward_step)
    climb = 1.0
    if told is not None:
        climb = estimate.climb(sample, params.feed_angle_deg)
        passes, count = told, told * (climb * along / params.forward_step + 2)
    cells = params.grid().shape
    holder = params.assembly is not None
    cut = passes * along * climb
    said = ["passes told from the tilted cutter's width over the model's curvature" if told is not None else
            "at most: passes a quarter diameter apart (the model not at hand)",
            f"a C-space of {cells[0] * cells[1]} postures at each" + (
                f", the shank and holder in it (about {HOLDER_COST:g}x the compute)" if holder else "")]
    paces = (("mesh5", count * (HOLDER_COST if holder else 1.0)),)
    if left_cell is not None:
        said.append(f"the finish simulated on {left_cell:g} mm cells")
        paces += estimate.left_paces(bounds, left_cell, cut, cutter)
    return Work(count, "CC points", passes, cut, note=f"({'; '.join(said)})", paces=paces)


def _segments(plan: AdaptivePlan, zigzag: bool) -> list[CutSegment]:
    """One segment per CC path (its tool positions with the overruns the plan counted on), passes in order,
    odd ones reversed."""
    out = []
    for k, p in enumerate(plan.passes):
        runs = [CutSegment(tips, axes=axes, pass_index=k) for tips, axes in p.tool_positions() if len(tips)]
        if zigzag and k % 2 == 1:
            runs = [CutSegment(s.tips[::-1], axes=s.axes[::-1], pass_index=k) for s in runs[::-1]]
        out.extend(runs)
    return out


def _strip_frame(params: Mesh5Params) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(feed direction as given, the drive planes' normal m, the feed along the planes): the strips' axes."""
    d = np.array(params.direction())
    m = plane_normal(d)
    return d, m, np.array([m[1], -m[0], 0.0])


def _strip_points(mesh: TriMesh, plan: AdaptivePlan, params: Mesh5Params, spacing: Optional[float]) -> np.ndarray:
    """(k, 3) CC points within the unfinished strips' feed spans, on each strip's middle drive plane (`spacing`
    None, at the forward step) or on planes at most `spacing` mm apart across it (and along)."""
    d, _, feed = _strip_frame(params)
    found = []
    for f0, f1, a0, a1 in plan.unfinished:
        if spacing is None:
            planes, step = np.array([0.5 * (a0 + a1)]), params.forward_step
        else:
            n = max(1, math.ceil((a1 - a0) / spacing))
            planes, step = a0 + (a1 - a0) * (np.arange(n) + 0.5) / n, min(params.forward_step, spacing)
        for p in cc_paths(mesh, d, planes, step, params.chord_tol):
            f = p.points @ feed
            found.append(p.points[(f >= f0 - 1e-9) & (f <= f1 + 1e-9)])
    return np.vstack(found) if found else np.zeros((0, 3))


def empty_points(mesh: TriMesh, plan: AdaptivePlan, params: Mesh5Params) -> np.ndarray:
    """(k, 3) CC points no pass finishes: those of each unfinished strip's middle plane within its feed span."""
    return _strip_points(mesh, plan, params, None)


def strip_corners(plan: AdaptivePlan, params: Mesh5Params) -> np.ndarray:
    """(k, 4, 2) XY corners of the unfinished strips (feed from, to x across from, to)."""
    _, m, feed = _strip_frame(params)
    return np.array([[f * feed[:2] + a * m[:2] for f, a in ((f0, a0), (f1, a0), (f1, a1), (f0, a1))]
                     for f0, f1, a0, a1 in plan.unfinished]).reshape(-1, 4, 2)


def cleanup_points(mesh: TriMesh, plan: AdaptivePlan, params: Mesh5Params, spacing: float = CLEANUP_SPACING
                   ) -> np.ndarray:
    """(k, 3) points on the mesh covering the unfinished strips, for clean-up and for the view: the CC points
    of drive planes at most `spacing` mm apart across each strip, within its feed span (no pass finishes them)."""
    return _strip_points(mesh, plan, params, spacing)


def compute(mesh: TriMesh, cutter: Cutter, params: Mesh5Params,
            progress: Optional[Progress] = None) -> StrategyResult:
    """The strategy (module doc): cut segments and diagnostics "plan" (the AdaptivePlan), "unfinished",
    "empty_points", "passes", "cc_points"."""
    if not isinstance(mesh, TriMesh):
        raise TmmError(f"model must be a TriMesh, got {type(mesh).__name__}")
    params.validate()
    check_tool(cutter)
    grid = params.grid()
    lo, hi = mesh.bounds
    count_points(*_extents(lo, hi, params), params, cutter)
    plan = adaptive_passes(mesh, cutter, params.tolerance, params.direction(), params.the_machine(), grid,
                           params.forward_step, params.chord_tol, progress=progress, assembly=params.assembly)
    segments, note = holder.optional_guard(mesh, cutter, params.assembly, plan, _segments(plan, params.zigzag))
    if not segments:
        raise TmmError(f"no pass could be placed on the mesh ({plan.report()}" +
                       (f"; {note.summary()})" if note is not None else ")"))
    empty = empty_points(mesh, plan, params)
    diagnostics = {"plan": plan, "unfinished": list(plan.unfinished), "empty_points": empty,
                   "strip_corners": strip_corners(plan, params), "cleanup_points": cleanup_points(mesh, plan, params),
                   "passes": len(plan.passes), "cc_points": int(sum(len(q.tips) for p in plan.passes
                                                                    for q in p.postures))}
    if note is not None:
        diagnostics["holder"] = note
        if params.holder_notes is not None:
            params.holder_notes.append(note)
    return StrategyResult(segments, diagnostics)


def report(diagnostics: dict) -> str:
    """What the op says: passes, CC points, and what is left for clean-up (never silently)."""
    plan = diagnostics["plan"]
    text = f"{diagnostics['passes']} passes, {diagnostics['cc_points']} CC points cut ({plan.report()})"
    empty = diagnostics["empty_points"]
    if len(plan.unfinished):
        marks = diagnostics["cleanup_points"]
        xy = marks[:, :2] if len(marks) else diagnostics["strip_corners"].reshape(-1, 2)
        text += (f"; {len(empty)} CC points with an empty C-space (no posture finishes them within the tolerance) "
                 f"in {len(plan.unfinished)} strips, {within(xy)}: not "
                 f"finished, marked for clean-up ({len(marks)} points on the mesh)")
    for key in ("left", "holder", "links"):
        if key in diagnostics:
            text += f"; {diagnostics[key].summary()}"
    return text
