"""Multipoint 5-axis positioning of a toroidal cutter on a Bézier/B-spline face (seed 001, Singh 2020).

The face is taken exactly (Bézier patches, B-splines split by knot insertion); the footprint is XY parallel
passes (side step across, forward step along, any feed direction; the side step even, fixed, or from a
scallop height on the simulated positions: pass_spacing "scallop", multipoint_scallop); at each footprint point the kernel
drops the tool vertically to a first contact P, then tilts it about the pseudo-insert's axis until it
touches a second point Q (methods "vcrf" and "drd" of the seed). Every position is checked for gouging.

    face = BezierFace.from_net(net)                   # or from_bspline(...), from_pieces(...)
    result = compute(face, Cutter.torus(6.7, 6.0), MultipointParams(side_step=18))   # the strategy
    path = link(result.segments, link_policy(tool, safe, clearance))                  # the one linker
    path, res = compute_multipoint_toolpath(face, tool, params)                       # both in one call

`res` (result.diagnostics["results"]) holds per footprint point: status ("two" / "one" / "failed"), the
reason, P, nP, Q, nQ, the tilt beta, tip, axis, centre. Segments are the runs of good positions of a pass
(tips and unit tool axes, tip -> spindle); failed positions are not cut: the pass is left and re-entered.
Work is estimated from the parameters before anything is allocated (core.limits).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.raster import EVEN, FIXED, Rect, pass_count, raster_lines, sample_segment
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.kernel import native
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.linking import ALONG_AXIS, LinkPolicy, link
from tmm_workbench.core.params import StrategyParams, check_finite, param
from tmm_workbench.core.segments import CutSegment, StrategyResult
from tmm_workbench.core.work import Box, Work
# the positioner's status codes, also read from here by the op, the pictures and the tests
from tmm_workbench.core.strategies.multipoint_status import (STATUS_FAILED, STATUS_NAMES, STATUS_ONE,  # noqa: F401
                                                             STATUS_TWO)
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]

METHODS = ("vcrf", "drd")
SHAPES = ("round_insert", "bull_nose")
ROTATIONS = ("pseudo_insert", "global_x")
ANCHORS = ("axis", "tip")
SUPPORTED_TOOLS = ("ball", "bull")  # Cutter.kind values: the toroidal view needs a corner radius > 0
SCALLOP = "scallop"
NOT_FINITE = "the kernel gave a tool position that is not a finite number: not cut"
_BYTES_PER_POSITION = 1200  # kernel results (about 40 doubles) and their numpy copies, per footprint point


@dataclass
class MultipointParams(StrategyParams):
    side_step: float = param(18.0, "side step", "mm", low=0, low_open=True, kind="length")
    # EVEN: spread evenly, at most side_step apart; FIXED: side_step apart from the start edge, the last
    # pass on the far edge (the seed's footprint); SCALLOP: each pass at the largest step whose simulated
    # scallop with the pass before is at most `scallop` (multipoint_scallop; side_step is the first guess)
    pass_spacing: str = param(EVEN, "pass spacing", choices=(EVEN, FIXED, SCALLOP))
    scallop: float = param(0.01, "scallop height", "mm", low=0, low_open=True, kind="length")
    scallop_row_spacing: float = param(0.0, "scallop row spacing", "mm", low=0)  # rows of needles read along
    #                                    the passes (0: twice the forward step, at least 1 mm and at most 4 mm)
    forward_step: float = param(2.0, "forward step", "mm", low=0, low_open=True, kind="length")
    feed_angle_deg: float = param(90.0, "feed angle", "deg")  # from +X (seed: along Y, side step along X)
    margin: float = param(0.0, "boundary margin", "mm")       # the face's XY extent grown by this (< 0 shrinks)
    boundary: Optional[Rect] = None  # explicit (xmin, ymin, xmax, ymax), overrides the face's extent
    zigzag: bool = True              # alternate pass directions
    method: str = param("vcrf", "method", choices=METHODS)
    shape: str = param("round_insert", "tool shape", choices=SHAPES)  # the seed's torus (hollow centre) or a bull-nose
    rotation: str = param("pseudo_insert", "rotation", choices=ROTATIONS)  # exact tilt; global_x: the seed's code
    beta_max_deg: float = param(45.0, "tilt limit", "deg", low=0, high=90, low_open=True, high_open=True)
    extend: float = param(0.0, "surface extension", "mm", low=0, kind="length")  # position against the face
    #                                                                       continued past its edges (0: off)
    anchor: str = param("axis", "footprint anchor", choices=ANCHORS)  # pre-tilt axis (seed) or tilted tip
    anchor_iterations: int = param(12, "anchor iterations", low=1, high=1000, integer=True)
    tol: float = param(1e-3, "tolerance", "mm", low=1e-9, high=1.0)   # contact and gouge tolerance
    sample_spacing: float = param(0.0, "sample spacing", "mm", low=0)  # surface samples (0: (Ro + Ri) / 8)
    divisions: int = param(6, "VCRF divisions", low=2, high=1000, integer=True)       # zoom grid (seed 32)
    refinements: int = param(1, "VCRF refinements", low=0, high=50, integer=True)     # zoom levels (seed 4)
    drd_divisions: int = param(10, "DRD divisions", low=2, high=1000, integer=True)   # rays per direction
    drd_refinements: int = param(5, "DRD refinements", low=0, high=50, integer=True)  # zoom levels (seed 5)
    drd_bisections: int = param(16, "DRD bisections", low=1, high=200, integer=True)  # bisections of the tilt
    threads: int = param(0, "threads", low=0, high=1024, integer=True)                # 0: all cores
    # no gouge and no chord error between positions (multipoint_refine): the deepest cut, and the largest gap
    # beyond the positions' own, allowed on the way from one position to the next (0: not checked), and how
    # many times positions are inserted halfway. 0.005: with the post's 0.005 mm of joint-interpolation
    # deviation the motion stays within 0.01 mm
    between_tol: float = param(0.005, "tolerance between positions", "mm", low=0)
    between_rounds: int = param(4, "refinement rounds", low=0, high=12, integer=True)
    # the whole tool (multipoint_holder): the assembly whose neck, shank and holder keep their clearance from the
    # face (None: the cutter alone), what is done where they would not ('tilt' away, else left out; or
    # 'leave_out'), the list its report is appended to, and a TarusMachine whose C limits bound the tilt
    assembly: Any = None
    holder_collision: str = param("tilt", "holder collision", choices=("tilt", "leave_out"))
    holder_notes: Optional[list] = None
    machine: Any = None

    def validate(self) -> None:
        super().validate()
        if self.boundary is not None:
            check_finite("boundary", self.boundary)
        if self.pass_spacing == SCALLOP:
            check_scallop(self.scallop, None)


def check_scallop(scallop: float, Ri: Optional[float]) -> None:
    """The scallop height must be > 0 and below the tool's corner radius (a larger one is never a scallop)."""
    if Ri is not None and not scallop < Ri:
        raise TmmError(f"scallop height must be > 0 and < the corner radius {Ri:g} mm, got {scallop:g} mm")


@dataclass
class MultipointResults:
    """Per footprint point (n = number of points), arrays from the kernel, plus the pass of each point."""
    xy: np.ndarray                   # (n, 2) footprint points
    passes: np.ndarray               # (n,) pass index
    data: dict = field(default_factory=dict)
    reasons: list = field(default_factory=list)

    def __getitem__(self, key: str) -> np.ndarray:
        return self.data[key]

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def status(self) -> np.ndarray:
        return self.data["status"]

    def status_names(self) -> list[str]:
        return [STATUS_NAMES[s] for s in self.data["status"]]

    def reason_texts(self) -> list[str]:
        return [self.reasons[r] for r in self.data["reason"]]

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.data["status"] == k)) for k, name in enumerate(STATUS_NAMES)}

    def records(self) -> list[dict]:
        """One dict per point (for reports and tables)."""
        out = []
        for i in range(len(self)):
            rec = {"x": float(self.xy[i, 0]), "y": float(self.xy[i, 1]), "pass": int(self.passes[i]),
                   "status": STATUS_NAMES[self.data["status"][i]], "reason": self.reasons[self.data["reason"][i]]}
            for k in ("beta", "gap_P", "gap_Q", "penetration", "seed_axis_angle"):
                rec[k] = float(self.data[k][i])
            for k in ("tip", "axis", "centre", "P", "nP", "Q", "nQ"):
                rec[k] = tuple(float(c) for c in self.data[k][i])
            out.append(rec)
        return out


def multipoint_footprint(face: BezierFace, params: MultipointParams) -> list[np.ndarray]:
    """XY parallel passes over the boundary (the face's XY extent grown by `margin`, or `boundary`):
    passes running along `feed_angle_deg`, the first and last on the boundary, spread evenly at most
    `side_step` apart (pass_spacing EVEN) or exactly `side_step` apart from the start edge with the last
    strip narrower (FIXED: the seed keeps 18 mm and squeezes the last pass in at x = 150); points at most
    `forward_step` apart; zigzag optional. One (k, 2) array per pass, the first nearest the boundary's
    (xmin, ymin) corner. The work is estimated first and refused above the limits (core.limits)."""
    params.validate()
    if params.pass_spacing == SCALLOP:
        raise TmmError("pass spacing 'scallop' places passes from the tool positions: use compute()")
    rect = footprint_rect(face, params)
    count_positions(rect, params)
    lines = raster_lines(rect, params.side_step, params.feed_angle_deg, params.pass_spacing)
    # Start with the pass nearest the boundary's (xmin, ymin) corner.
    corner = np.array(rect[:2])
    if lines and np.linalg.norm(lines[-1].mean(0) - corner) < np.linalg.norm(lines[0].mean(0) - corner):
        lines = lines[::-1]
    passes = []
    for k, seg in enumerate(lines):
        pts = sample_segment(seg[0], seg[1], params.forward_step)
        if params.zigzag and k % 2 == 1:
            pts = pts[::-1]
        passes.append(pts)
    return passes


def footprint_rect(face: BezierFace, params: MultipointParams) -> Rect:
    """The boundary: `params.boundary`, or the face's XY extent grown by `params.margin`."""
    if params.boundary is not None:
        return tuple(map(float, params.boundary))
    x0, y0, x1, y1 = face.xy_extent()
    m = float(params.margin)
    return (x0 - m, y0 - m, x1 + m, y1 + m)


def count_positions(rect: Rect, params: MultipointParams) -> float:
    """Footprint points over `rect` (an upper bound), refused above the limits before any is made."""
    w, h = rect[2] - rect[0], rect[3] - rect[1]
    if not (w > 0 and h > 0):
        raise TmmError(f"boundary is empty: x {rect[0]:g}..{rect[2]:g}, y {rect[1]:g}..{rect[3]:g}")
    diagonal = math.hypot(w, h)
    count = pass_count(diagonal, params.side_step) * (diagonal / params.forward_step + 2)
    check_work("tool positions", count, _BYTES_PER_POSITION,
               f"side step {params.side_step:g} mm and forward step {params.forward_step:g} mm over a "
               f"{w:.6g} x {h:.6g} mm boundary", "max_positions")
    return count


def estimate_work(params: MultipointParams, cutter: Cutter, bounds: Box) -> Work:
    """The footprint's tool positions over the face's box `bounds` grown by the margin (core.work)."""
    params.validate()
    m = float(params.margin)
    rect = (bounds[0] - m, bounds[1] - m, bounds[3] + m, bounds[4] + m)
    count = count_positions(rect, params)
    w, h = rect[2] - rect[0], rect[3] - rect[1]
    return Work(count, "tool positions", pass_count(math.hypot(w, h), params.side_step), w * h / params.side_step,
                paces=(("multipoint_scallop" if params.pass_spacing == SCALLOP else "multipoint", count),))


def _torus(tool: Cutter) -> tuple[float, float]:
    if not isinstance(tool, Cutter):
        raise TmmError(f"tool must be a core Cutter, got {type(tool).__name__}")
    if tool.kind not in SUPPORTED_TOOLS:
        if tool.kind == "flat":
            tool.torus_radii  # raises its own message: no corner to tilt about
        raise TmmError(f"the {tool.describe()} cutter is not supported by multipoint positioning "
                       f"(supported: {', '.join(SUPPORTED_TOOLS)})")
    return tool.torus_radii


def make_positioner(face: BezierFace, Ro: float, Ri: float, params: Optional[MultipointParams] = None,
                    method: Optional[str] = None, progress: Optional[Progress] = None):
    """The kernel's positioner for the torus (Ro, Ri) (surface samples built once per face and tool: a second
    at a fine sample spacing, reported to `progress` or, without one, cancelled through core.cancel)."""
    params = params or MultipointParams()
    Cutter.torus(Ro, Ri)  # the one place that checks a torus' radii
    params.validate()
    method = params.method if method is None else method
    if method not in METHODS:
        raise TmmError(f"method must be 'vcrf' or 'drd', got {method!r}")
    options = native.MultipointOptions(
        Ro=float(Ro), Ri=float(Ri), shape=params.shape, method=method, rotation=params.rotation,
        beta_max=math.radians(params.beta_max_deg), tol=float(params.tol),
        sample_spacing=float(params.sample_spacing), divisions=int(params.divisions),
        refinements=int(params.refinements), drd_divisions=int(params.drd_divisions),
        drd_refinements=int(params.drd_refinements), drd_bisections=int(params.drd_bisections),
        extend=float(params.extend), anchor=params.anchor, anchor_iterations=int(params.anchor_iterations))
    try:
        return cancel.native_call(native.MultipointPositioner, face.native, options, progress=progress)
    except ValueError as exc:
        raise TmmError(str(exc)) from exc


def position_points(face: BezierFace, Ro: float, Ri: float, xy: np.ndarray,
                    params: Optional[MultipointParams] = None, method: Optional[str] = None,
                    progress: Optional[Progress] = None) -> MultipointResults:
    """Multipoint positions of the torus (Ro, Ri) at the (n, 2) footprint points (method: params.method
    unless given)."""
    params = params or MultipointParams()
    with cancel.watching(progress) as report:  # the samples are built before any position: they ask it
        return _position(make_positioner(face, Ro, Ri, params, method), xy, params, report)


def _position(mp, xy: np.ndarray, params: MultipointParams, progress: Optional[Progress] = None
              ) -> MultipointResults:
    """The positioner `mp`'s positions at the (n, 2) footprint points."""
    pts = np.ascontiguousarray(xy, dtype=np.float64).reshape(-1, 2)
    if not np.isfinite(pts).all():
        raise TmmError("footprint points contain a non-finite coordinate")
    check_work("tool positions", len(pts), _BYTES_PER_POSITION, f"{len(pts)} footprint points", "max_positions")
    try:
        data = mp.position_batch(pts, int(params.threads), progress)
    except native.Cancelled as exc:
        raise Cancelled("multipoint tool path computation cancelled") from exc
    reasons = list(native.multipoint_reasons()) + [NOT_FINITE]
    # a position whose tip or axis is not a usable number is not cut (no NaN may reach a tool path)
    axis_len = np.linalg.norm(data["axis"], axis=1)
    bad = ~(np.isfinite(data["tip"]).all(1) & np.isfinite(data["axis"]).all(1) & (axis_len > 0.5))
    bad &= data["status"] != STATUS_FAILED
    if bad.any():
        data["status"] = np.where(bad, STATUS_FAILED, data["status"])
        data["reason"] = np.where(bad, len(reasons) - 1, data["reason"])
    return MultipointResults(pts, np.zeros(len(pts), dtype=int), data, reasons)


def compute(surface: BezierFace, tool: Cutter, params: MultipointParams,
            progress: Optional[Progress] = None) -> StrategyResult:
    """The strategy: multipoint positions over the footprint, as cut segments (runs of good positions of
    one pass); diagnostics: "results" (MultipointResults per footprint point), "counts",
    "unreached_positions" ((k, 2) XY of the footprint points no position was found for: not cut), "between"
    (multipoint_refine), with an assembly "holder" (multipoint_holder's report: positions tilted, unreachable),
    and with the scallop rule "scallop" (its ScallopPlacement: `unreached` lists the
    areas where the scallop is not held). What cannot be reached is reported, never a failure of the op."""
    with cancel.watching(progress) as report:  # the scallop meter's Python loops poll it (core.cancel)
        return _compute(surface, tool, params, report)


def _compute(surface: BezierFace, tool: Cutter, params: MultipointParams,
             progress: Optional[Progress]) -> StrategyResult:
    if not isinstance(surface, BezierFace):
        raise TmmError(f"surface must be a BezierFace, got {type(surface).__name__}")
    Ro, Ri = _torus(tool)
    diagnostics: dict = {}
    if params.pass_spacing == SCALLOP:
        positioner = make_positioner(surface, Ro, Ri, params)
        res, diagnostics["scallop"] = _scallop_passes(surface, tool, params, positioner, progress)
        pass_index, xy = res.passes, res.xy
    else:
        passes = multipoint_footprint(surface, params)
        if not passes:
            raise TmmError("the footprint is empty")
        xy = np.vstack(passes)
        pass_index = np.concatenate([np.full(len(p), k) for k, p in enumerate(passes)])
        positioner = make_positioner(surface, Ro, Ri, params)  # for the footprint and any positions inserted
        res = _position(positioner, xy, params, progress)
        res.passes = pass_index
    good = res.status != STATUS_FAILED
    runs: list[list[int]] = []
    run: list[int] = []  # a segment ends at a new pass or a failed position
    for i in range(len(xy)):
        if run and (pass_index[i] != pass_index[run[-1]] or not good[i]):
            runs.append(run)
            run = []
        if good[i]:
            run.append(i)
    if run:
        runs.append(run)
    diagnostics["results"] = res
    if params.between_tol > 0 and params.between_rounds > 0:
        from tmm_workbench.core.strategies import multipoint_refine

        diagnostics["between"] = multipoint_refine.refine(
            positioner, params, runs, res, lambda pts: _position(positioner, pts, params))
    if params.assembly is not None:  # after the refinement: its inserted positions are checked too
        from tmm_workbench.core.strategies import multipoint_holder

        runs, diagnostics["holder"] = multipoint_holder.guard(surface, positioner, params, res, runs, progress)
        if params.holder_notes is not None:
            params.holder_notes.append(diagnostics["holder"])
    diagnostics["counts"] = res.counts()
    # what is not machined, for the report: footprint points the tool could not be placed at
    diagnostics["unreached_positions"] = res.xy[res.status == STATUS_FAILED]
    tip, axis = res["tip"], res["axis"]
    cut = [CutSegment(tip[r], axes=axis[r], pass_index=int(res.passes[r[0]])) for r in runs]
    return StrategyResult(cut, diagnostics)


def _scallop_passes(surface: BezierFace, tool: Cutter, params: MultipointParams, positioner,
                    progress: Optional[Progress]) -> tuple[MultipointResults, object]:
    """Passes placed by the scallop rule (multipoint_scallop), as one MultipointResults in cutting order
    (odd passes reversed for zigzag), and the placement's report."""
    from tmm_workbench.core.strategies import multipoint_scallop as ms

    params.validate()
    Ro, Ri = tool.torus_radii
    check_scallop(params.scallop, Ri)
    rect = footprint_rect(surface, params)
    count_positions(rect, params)
    ms.estimate_work(rect, params, Ri)
    frame = ms.Frame.of(rect, params.feed_angle_deg)
    rows = params.scallop_row_spacing or min(4.0, max(1.0, 2.0 * params.forward_step))
    max_step = min(0.5, math.sqrt(0.08 * Ri * params.scallop))  # the cusp between instances: a tenth of it
    meter = ms.ScallopMeter(surface, Ro, Ri, params.shape, frame, rows, max_step, STATUS_FAILED,
                            int(params.threads))
    placed, report = ms.place_passes(surface, rect, params, Ri, lambda xy: _position(positioner, xy, params),
                                     meter, STATUS_FAILED, progress)
    order, xy, passes = [], [], []
    base = 0
    for k, p in enumerate(placed):
        idx = np.arange(len(p.xy))
        if params.zigzag and k % 2 == 1:
            idx = idx[::-1]
        order.append(base + idx)
        base += len(p.xy)
        xy.append(p.xy[idx])
        passes.append(np.full(len(idx), k))
    data = {key: np.concatenate([p.res.data[key] for p in placed])[np.concatenate(order)]
            for key in placed[0].res.data}
    res = MultipointResults(np.vstack(xy), np.concatenate(passes), data, placed[0].res.reasons)
    return res, report


def link_policy(tool: Cutter, safe_height: float, clearance_height: float,
                axis_retract: float = 5.0) -> LinkPolicy:
    """5-axis linking: along the tool axis, transit heights from the tilted tool's lowest point."""
    return LinkPolicy(safe_height, clearance_height, ALONG_AXIS, axis_retract,
                      lowest_below_tip=tool.lowest_below_tip)


def face_top(face: BezierFace, samples: int = 64) -> float:
    """Highest point of the face (sampled densely; the control net's box is loose)."""
    u0, u1, v0, v1 = face.domain
    U, V = np.meshgrid(np.linspace(u0, u1, samples + 1), np.linspace(v0, v1, samples + 1), indexing="ij")
    return float(face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"][:, 2].max())


def compute_multipoint_toolpath(surface: BezierFace, tool: Cutter, params: Optional[MultipointParams] = None,
                                policy: Optional[LinkPolicy] = None, progress: Optional[Progress] = None
                                ) -> tuple[Toolpath, MultipointResults]:
    """The strategy and the linker in one call: the 5-axis tool path over `surface` and the per-point
    results. `policy` defaults to linking along the tool axis with the safe height 5 mm above the face's
    top. progress(fraction) -> bool; False cancels (raises Cancelled)."""
    params = params or MultipointParams()
    result = compute(surface, tool, params, progress)
    if policy is None:
        safe = face_top(surface) + 5.0
        policy = link_policy(tool, safe, safe)
    return link(result.segments, policy), result.diagnostics["results"]
