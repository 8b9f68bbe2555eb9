"""Side step from a scallop height for multipoint 5-axis finishing (issue 14 item 5).

Passes are placed one after the other across the boundary: the first on the start edge, each next one at the
largest side step for which the scallop left between it and the passes before it, measured on the real tool
positions, is at most `MultipointParams.scallop`; the last on the far edge. The scallop of a trial pass is
read by cutting the swept tool (the kernel's 5-axis z-map cut: tip linear, axis by slerp, sub-stepped) into
rows of vertical needles laid across the strip from the previous pass's first contact (P or Q, whichever is
nearer the start edge) to the trial pass's last contact, both passes' contact bands included, one row every
`scallop_row_spacing` along the passes: the largest height above the design surface on those
needles. Needles are `NEEDLE_SPACING` apart, then `FINE_SPACING` around the highest peaks (the cusp is a
sharp ridge). The design height is the face itself (its XY parametrisation inverted by Newton).

The search per pass brackets the step (the scallop grows about with the square of the step, so the next trial
interpolates in sqrt(scallop)), keeps the largest step found within the tolerance and stops when the scallop is
within SCALLOP_REL of it or the bracket is narrower than STEP_TOL. Rows where one of the two passes has no
good position near them (failed positions, the ends of the passes) are not measured and are counted.

Where the tolerance cannot be held the placement degrades instead of failing: rows still above it at the
smallest step tried (material the pass leaves by itself, where the tool does not reach the face: a rim, an
edge, a steep flank past the tilt limit) are left out of the strip's measure; a strip none of whose rows can
be held gets the step of the work estimate (`ball_step`) and is measured as it is. Both are reported as
`LeftArea`s (where, how high), never silently accepted.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, sample_segment
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.kernel import native
from tmm_workbench.core.limits import check_work

NEEDLE_SPACING = 0.05   # mm, needles across a strip (first reading)
FINE_SPACING = 0.002    # mm, needles around the highest peaks (second reading)
FINE_ROWS = 4           # rows whose peak is read finely
SCALLOP_REL = 0.02      # a pass is accepted once its scallop is within 2 % below the tolerance
STEP_TOL = 0.005        # mm: or once the bracket on the step is this narrow
MAX_TRIALS = 14         # trial passes per placed pass
_STOCK_ABOVE = 50.0     # mm: needles start this far above the face's top (an uncut needle reads huge)
_BYTES_PER_NEEDLE = 64


@dataclass
class Frame:
    """Across (c) and along (f, the feed direction) unit vectors of the passes, orthonormal, and the boundary's
    extent in them: passes at across a in [a0, a1], advancing in +c from the start edge a0."""
    c: np.ndarray
    f: np.ndarray
    a0: float
    a1: float

    @classmethod
    def of(cls, rect: Rect, feed_angle_deg: float) -> "Frame":
        a = math.radians(feed_angle_deg)
        d = np.array([math.cos(a), math.sin(a)])
        n = np.array([-math.sin(a), math.cos(a)])
        corners = np.array([[rect[0], rect[1]], [rect[2], rect[1]], [rect[2], rect[3]], [rect[0], rect[3]]])
        across = corners @ n
        # start on the side nearest the (xmin, ymin) corner, as raster_lines' FIXED spacing does
        if abs(corners[0] @ n - across.max()) < abs(corners[0] @ n - across.min()):
            n = -n
        across = corners @ n  # (n, d) may be a reflection: the tool, a solid of revolution, is symmetric
        return cls(n, d, float(across.min()), float(across.max()))

    def to_frame(self, p: np.ndarray) -> np.ndarray:
        """(k, 2|3) world points -> frame (across, along[, z])."""
        out = np.array(p, dtype=float, copy=True)
        out[:, 0], out[:, 1] = p[:, :2] @ self.c, p[:, :2] @ self.f
        return out

    def to_world(self, q: np.ndarray) -> np.ndarray:
        out = np.array(q, dtype=float, copy=True)
        out[:, 0] = q[:, 0] * self.c[0] + q[:, 1] * self.f[0]
        out[:, 1] = q[:, 0] * self.c[1] + q[:, 1] * self.f[1]
        return out


class DesignHeights:
    """z of the face above world (x, y) points (NaN off the face): the face's XY map inverted by Newton from
    the nearest of a grid of samples."""

    def __init__(self, face: BezierFace, samples: int = 32) -> None:
        self.face = face
        u0, u1, v0, v1 = face.domain
        U, V = np.meshgrid(np.linspace(u0, u1, samples + 1), np.linspace(v0, v1, samples + 1), indexing="ij")
        self.uv = np.column_stack([U.ravel(), V.ravel()])
        self.xy = face.evaluate(self.uv)["S"][:, :2]
        self.domain = (u0, u1, v0, v1)

    def __call__(self, xy: np.ndarray, iterations: int = 12, tol: float = 1e-7) -> np.ndarray:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        uv = np.empty_like(xy)
        for k in range(0, len(xy), 2048):  # nearest sample, in chunks
            cancel.poll()
            d = ((xy[k:k + 2048, None, :] - self.xy[None, :, :]) ** 2).sum(-1)
            uv[k:k + 2048] = self.uv[np.argmin(d, axis=1)]
        u0, u1, v0, v1 = self.domain
        for _ in range(iterations):
            cancel.poll()
            ev = self.face.evaluate(uv)
            r = ev["S"][:, :2] - xy
            a, b, c, d = ev["Su"][:, 0], ev["Sv"][:, 0], ev["Su"][:, 1], ev["Sv"][:, 1]
            det = a * d - b * c
            det = np.where(np.abs(det) < 1e-300, 1e-300, det)
            uv[:, 0] -= (d * r[:, 0] - b * r[:, 1]) / det
            uv[:, 1] -= (-c * r[:, 0] + a * r[:, 1]) / det
            uv[:, 0] = np.clip(uv[:, 0], u0, u1)
            uv[:, 1] = np.clip(uv[:, 1], v0, v1)
        ev = self.face.evaluate(uv)
        z = ev["S"][:, 2].copy()
        z[np.linalg.norm(ev["S"][:, :2] - xy, axis=1) > tol] = np.nan  # off the face (clamped at its edge)
        return z


@dataclass
class PassPositions:
    """One pass positioned: footprint across offset `a`, its footprint points (k, 2) in feed order from the
    pass's start, and the kernel's results for them (a MultipointResults)."""
    a: float
    xy: np.ndarray
    res: Any

    def good(self, failed: int) -> np.ndarray:
        return self.res["status"] != failed


NOT_REACHED = "not reached"    # rows no side step holds: left out of the strip's measure
OVER_SCALLOP = "over scallop"  # a strip none of whose rows a side step holds: placed at the estimate's step


@dataclass
class LeftArea:
    """Part of a strip between two passes where the scallop tolerance is not held: across from `start` to
    `end` (mm from the start edge), along the passes from `along[0]` to `along[1]` (the feed coordinate),
    `outline` its (4, 2) XY corners; `height` the highest value measured there above the face (inf: a needle
    the tool never cut), at XY `at`; `rows` the needle rows it covers; `reason` NOT_REACHED or OVER_SCALLOP."""
    start: float
    end: float
    along: tuple[float, float]
    outline: np.ndarray
    height: float
    at: tuple[float, float]
    rows: int
    reason: str

    def describe(self) -> str:
        x0, y0 = self.outline.min(0)
        x1, y1 = self.outline.max(0)
        what = ("no side step removes it: the tool does not reach the face there" if self.reason == NOT_REACHED
                else "no side step holds the scallop on this strip: placed at the estimate's step")
        return (f"{self.rows} rows of the strip {self.start:.4g}..{self.end:.4g} mm from the start edge keep up "
                f"to {self.height:.4g} mm above the face (highest at x {self.at[0]:.4g}, y {self.at[1]:.4g} mm; "
                f"area x {x0:.4g}..{x1:.4g}, y {y0:.4g}..{y1:.4g} mm): {what}")


@dataclass
class ScallopPlacement:
    """What the placement did: per placed pass its across offset and the scallop measured against the pass
    before it (0 for the first; above the tolerance on an OVER_SCALLOP strip); trial passes positioned; rows
    not measured; `unreached`: the LeftAreas where the tolerance is not held."""
    offsets: list = field(default_factory=list)
    scallops: list = field(default_factory=list)
    trials: int = 0
    rows_skipped: int = 0
    unreached: list = field(default_factory=list)

    @property
    def steps(self) -> list:
        return [b - a for a, b in zip(self.offsets, self.offsets[1:])]

    @property
    def max_scallop(self) -> float:
        return max(self.scallops, default=0.0)


def _runs(res: Any, failed: int) -> list[np.ndarray]:
    """Row indices of the runs of consecutive good positions."""
    good = res["status"] != failed
    out, run = [], []
    for i, g in enumerate(good):
        if g:
            run.append(i)
        elif run:
            out.append(np.array(run))
            run = []
    if run:
        out.append(np.array(run))
    return out


def ball_step(Ri: float, scallop: float) -> float:
    """The side step of a ball of half the corner radius leaving `scallop` on a plane (a tilted torus on a
    surface it fits leaves less for the same step): the estimate's step."""
    r = 0.5 * Ri
    h = min(scallop, r)
    return 2.0 * math.sqrt(max(2.0 * r * h - h * h, 1e-12))


def estimate_passes(width: float, Ri: float, scallop: float) -> int:
    """An upper bound of the passes over `width` at the ball_step."""
    return int(math.ceil(width / ball_step(Ri, scallop))) + 1


def estimate_work(rect: Rect, params: Any, Ri: float) -> float:
    """Tool positions the placement may compute (every trial of every pass), refused above the limits."""
    frame = Frame.of(rect, params.feed_angle_deg)
    width = frame.a1 - frame.a0
    length = math.hypot(rect[2] - rect[0], rect[3] - rect[1])
    passes = estimate_passes(width, Ri, params.scallop)
    count = passes * MAX_TRIALS * (length / params.forward_step + 2)
    check_work("tool positions", count, 1200,
               f"scallop {params.scallop:g} mm (corner radius {Ri:g} mm: up to {passes} passes, {MAX_TRIALS} "
               f"trials each) and forward step {params.forward_step:g} mm over a {width:.6g} mm wide boundary",
               "max_positions")
    return count


class ScallopMeter:
    """Reads the scallop between passes: rows of needles across the strip, cut by the kernel's z-map."""

    def __init__(self, face: BezierFace, Ro: float, Ri: float, shape: str, frame: Frame, row_spacing: float,
                 max_step: float, failed: int, threads: int = 0) -> None:
        self.face, self.Ro, self.Ri, self.shape, self.frame = face, Ro, Ri, shape, frame
        self.row_spacing, self.max_step, self.failed, self.threads = row_spacing, max_step, failed, threads
        self.design = DesignHeights(face)
        (_, _, _), (_, _, ztop) = face.bounds
        self.top = float(ztop) + _STOCK_ABOVE
        self.rows_skipped = 0
        self._design_rows: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        reach = Ro + Ri
        self.lattice = np.arange(frame.a0 - reach, frame.a1 + reach + NEEDLE_SPACING, NEEDLE_SPACING)

    def row_positions(self, t_lo: float, t_hi: float) -> np.ndarray:
        """The rows read between t_lo and t_hi: on a fixed lattice (multiples of the row spacing, so the
        design along each is computed once), at least the corner radius Ri inside the passes' ends (what a pass
        leaves at its end is made by the boundary, not by the side step)."""
        lo, hi = t_lo + self.Ri, t_hi - self.Ri
        if hi < lo:
            lo = hi = 0.5 * (t_lo + t_hi)
        k0, k1 = math.ceil(lo / self.row_spacing - 1e-9), math.floor(hi / self.row_spacing + 1e-9)
        rows = np.arange(k0, k1 + 1) * self.row_spacing
        return rows if len(rows) else np.array([0.5 * (lo + hi)])

    def design_row(self, t_row: float, xs: np.ndarray) -> np.ndarray:
        """The design height at (across xs, along t_row): the face inverted once per row on needles
        NEEDLE_SPACING apart, interpolated linearly between them (the error, curvature x spacing^2 / 8, is
        2e-6 mm for a 150 mm radius)."""
        key = round(float(t_row), 9)
        if key not in self._design_rows:
            world = self.frame.to_world(np.column_stack([self.lattice, np.full(len(self.lattice), t_row)]))
            self._design_rows[key] = (self.lattice, self.design(world))
        lat, z = self._design_rows[key]
        return np.interp(xs, lat, z, left=np.nan, right=np.nan)

    def _paths(self, passes: list[PassPositions], t_row: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """The good runs of `passes` near the row (frame coordinates), as (tips, axes)."""
        reach = self.Ro + self.Ri + 1e-6
        out = []
        for p in passes:
            tips = self.frame.to_frame(p.res["tip"])
            axes = self.frame.to_frame(p.res["axis"])
            for run in _runs(p.res, self.failed):
                near = run[np.abs(tips[run, 1] - t_row) <= reach + self.row_spacing]
                if len(near) == 0:
                    continue
                lo, hi = max(near[0] - 1, run[0]), min(near[-1] + 1, run[-1])  # the moves into the row too
                idx = np.arange(lo, hi + 1)
                out.append((tips[idx], axes[idx]))
        return out

    def _cut_row(self, paths, t_row: float, x0: float, n: int, cell: float) -> np.ndarray:
        zmap = native.ZMap(x0, t_row - 0.5 * cell, cell, n, 1, self.top)
        for tips, axes in paths:
            kinds = np.zeros(max(len(tips) - 1, 0), dtype=np.uint8)
            native.cut_5axis(zmap, self.Ro, self.Ri, self.shape, np.ascontiguousarray(tips),
                             np.ascontiguousarray(axes), kinds, self.max_step, 1e9, self.threads)
        return np.array(zmap.heights).reshape(-1)

    def _deviation(self, paths, t_row: float, x0: float, n: int, cell: float) -> tuple[np.ndarray, np.ndarray]:
        xs = x0 + (np.arange(n) + 0.5) * cell
        z = self._cut_row(paths, t_row, x0, n, cell)
        return xs, z - self.design_row(t_row, xs)

    def _contact_band(self, p: PassPositions) -> np.ndarray:
        """(k, 3) per position: its first contact's across coordinate, the along coordinate of its tip, its
        last contact's across coordinate (P and Q; P alone with one contact): what the pass cuts lies
        between them, the scallop between the bands of two passes."""
        P = self.frame.to_frame(p.res["P"])
        Q = self.frame.to_frame(p.res["Q"])
        qa = np.where(np.isfinite(Q[:, 0]), Q[:, 0], P[:, 0])
        tips = self.frame.to_frame(p.res["tip"])
        return np.column_stack([np.minimum(P[:, 0], qa), tips[:, 1], np.maximum(P[:, 0], qa)])

    def scallop(self, before: list[PassPositions], prev: PassPositions, new: PassPositions,
                exclude: Sequence[tuple[float, float]] = ()) -> float:
        """The largest height above the face left between `prev`'s tips and `new`'s tips, the passes in
        `before` cut too (inf where a needle between them is not cut at all), on the rows outside the
        `exclude` intervals of the along coordinate. `self.rows` keeps each row's value, `self.peak` where
        the highest is."""
        self.rows = {}
        tp, tn = self._contact_band(prev), self._contact_band(new)
        gp, gn = prev.good(self.failed), new.good(self.failed)
        gp &= np.isfinite(tp[:, 0])
        gn &= np.isfinite(tn[:, 0])
        if not gp.any() or not gn.any():
            return math.inf
        t_lo = max(tp[gp, 1].min(), tn[gn, 1].min())
        t_hi = min(tp[gp, 1].max(), tn[gn, 1].max())
        if t_hi <= t_lo:
            return math.inf
        rows = self.row_positions(t_lo, t_hi)
        passes = before + [prev, new]
        gap = 2.0 * self.row_spacing + 1e-9  # a row farther than this from a good position is not measured
        coarse = []
        for t_row in rows:
            cancel.poll()
            if any(lo <= t_row <= hi for lo, hi in exclude):
                continue
            near_p = gp & (np.abs(tp[:, 1] - t_row) <= gap)
            near_n = gn & (np.abs(tn[:, 1] - t_row) <= gap)
            if not near_p.any() or not near_n.any():
                self.rows_skipped += 1
                continue
            # the strip: from the previous pass's first contact to the new pass's last, at this row
            a_lo = float(np.interp(t_row, *_sorted(tp[gp, 1], tp[gp, 0])))
            a_hi = float(np.interp(t_row, *_sorted(tn[gn, 1], tn[gn, 2])))
            if a_hi <= a_lo:
                continue
            n = max(2, int(math.ceil((a_hi - a_lo) / NEEDLE_SPACING)))
            cell = (a_hi - a_lo) / n
            paths = self._paths(passes, t_row)
            xs, dev = self._deviation(paths, t_row, a_lo, n, cell)
            ok = np.isfinite(dev)
            if not ok.any():
                continue
            i = int(np.flatnonzero(ok)[np.argmax(dev[ok])])
            coarse.append((float(dev[i]), float(t_row), float(xs[i]), paths))
            self.rows[float(t_row)] = float(dev[i])
        if not coarse:
            return 0.0
        coarse.sort(key=lambda r: -r[0])
        best = coarse[0][0]
        self.peak = (coarse[0][2], coarse[0][1])
        for dev0, t_row, x_peak, paths in coarse[:FINE_ROWS]:
            if not math.isfinite(dev0):
                return math.inf
            n = int(round(2 * NEEDLE_SPACING / FINE_SPACING))
            xs, dev = self._deviation(paths, t_row, x_peak - NEEDLE_SPACING, n, FINE_SPACING)
            ok = np.isfinite(dev)
            if ok.any():
                self.rows[t_row] = max(self.rows[t_row], float(dev[ok].max()))
            if ok.any() and float(dev[ok].max()) > best:
                best = float(dev[ok].max())
                self.peak = (float(xs[ok][np.argmax(dev[ok])]), t_row)
        return best

    peak: tuple = (math.nan, math.nan)  # (across, along) in the frame of the last scallop's highest needle
    rows: dict = {}


def _sorted(t: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(t)
    return t[order], a[order]


def place_passes(face: BezierFace, rect: Rect, params: Any, Ri: float, position: Callable[[np.ndarray], Any],
                 meter: ScallopMeter, failed: int, progress: Optional[Callable[[float], bool]] = None
                 ) -> tuple[list[PassPositions], ScallopPlacement]:
    """Passes across `rect`, each at the largest side step whose scallop with the passes before it is at most
    params.scallop. `position(xy)` positions footprint points (MultipointResults). Every pass runs the same
    way (+f); the caller alternates them for zigzag."""
    frame = meter.frame
    h = float(params.scallop)
    limit = estimate_passes(frame.a1 - frame.a0, Ri, h)
    least = ball_step(Ri, h)  # no pass is placed nearer than this to the one before (but the last one)
    report = ScallopPlacement()

    def make(a: float) -> Optional[PassPositions]:
        seg = clip_line_to_rect(a * frame.c, frame.f, rect)
        if seg is None:
            return None
        if (seg[1] - seg[0]) @ frame.f < 0:
            seg = seg[::-1]
        xy = sample_segment(seg[0], seg[1], params.forward_step)
        report.trials += 1
        return PassPositions(a, xy, position(xy))

    first = make(frame.a0)
    if first is None:
        raise TmmError("the footprint is empty")
    placed = [first]
    report.offsets.append(first.a)
    report.scallops.append(0.0)
    step = min(float(params.side_step), frame.a1 - frame.a0)
    while placed[-1].a < frame.a1 - 1e-9:
        if len(placed) >= limit:
            raise TmmError(f"scallop {h:g} mm needs more than {limit} passes over this boundary (the estimate "
                           "the work was checked against); use a larger scallop")
        prev, before = placed[-1], placed[-3:-1]
        room = frame.a1 - prev.a
        excluded: list[tuple[float, float]] = []
        left: list[tuple[list[float], dict]] = []  # rows left out, with the row values they had
        for _attempt in range(3):
            best, over, smallest = _search(make, meter, before, prev, frame, h, min(step, room), room, excluded)
            if best is not None:
                break
            # rows still above the tolerance at the smallest step tried: material one pass leaves by itself
            # (not a scallop between passes), left out of this strip's measure and reported
            rows = smallest or {}
            bad = [t for t, v in rows.items() if v > h]
            if not bad or len(bad) == len(rows):
                break  # nothing to leave out, or every row: no step holds this strip (placed as estimated)
            half = 0.5 * meter.row_spacing
            excluded += [(t - half, t + half) for t in bad]
            left.append((bad, rows))
        if best is not None and best[0] < least - 1e-12 and room > least:
            # a step below the estimate's (the ball's on a plane) holds only where a pass leaves no scallop of
            # its own beside a strip it cannot reach: stepping on by it would creep (thousands of passes a
            # micrometre apart); the strip is placed at the estimate's step and reported instead
            best = None
        if best is None:  # the estimate's step, the strip measured as it is
            s_fall = min(least, room)
            trial = make(frame.a1 if s_fall >= room - 1e-9 else prev.a + s_fall)
            if trial is None:
                raise TmmError(f"no pass fits the boundary after the pass at {prev.a - frame.a0:.4g} mm")
            value = meter.scallop(before, prev, trial, excluded)
            best = (step, value, trial)
            over_rows = [t for t, v in meter.rows.items() if v > h]
            if not over_rows and value > h:  # nothing measured (no good positions near): the whole strip
                along = frame.to_frame(trial.xy)[:, 1]
                over_rows = list(np.arange(along.min(), along.max() + 1e-9, meter.row_spacing))
            report.unreached += _areas(frame, prev.a, trial.a, meter, over_rows, meter.rows, OVER_SCALLOP)
        s_ok, value, trial = best
        for bad, rows in left:
            report.unreached += _areas(frame, prev.a, trial.a, meter, bad, rows, NOT_REACHED)
        placed.append(trial)
        report.offsets.append(trial.a)
        report.scallops.append(value)
        step = s_ok
        if progress is not None and progress((trial.a - frame.a0) / max(frame.a1 - frame.a0, 1e-12)) is False:
            raise Cancelled("multipoint tool path computation cancelled")
    report.rows_skipped = meter.rows_skipped
    return placed, report


def _areas(frame: Frame, a0: float, a1: float, meter: ScallopMeter, bad: list[float], values: dict,
           reason: str) -> list[LeftArea]:
    """LeftAreas of the strip a0..a1 over the rows `bad` (along coordinates), runs of neighbouring rows
    joined; `values` the rows' measured heights."""
    out: list[LeftArea] = []
    half = 0.5 * meter.row_spacing
    runs: list[list[float]] = []
    for t in sorted(bad):
        if runs and t - runs[-1][-1] <= meter.row_spacing * 1.001:
            runs[-1].append(t)
        else:
            runs.append([t])
    for run in runs:
        lo, hi = run[0] - half, run[-1] + half
        worst = max(run, key=lambda t: values.get(t, math.inf))
        corners = np.round(frame.to_world(np.array([[a0, lo], [a1, lo], [a1, hi], [a0, hi]])), 9)
        at = frame.to_world(np.array([[0.5 * (a0 + a1), worst]]))[0]
        out.append(LeftArea(a0 - frame.a0, a1 - frame.a0, (lo, hi), corners, float(values.get(worst, math.inf)),
                            (float(at[0]), float(at[1])), len(run), reason))
    return out


def _search(make, meter: ScallopMeter, before, prev: PassPositions, frame: Frame, h: float, s: float,
            room: float, excluded: list) -> tuple[Optional[tuple], Optional[tuple], Optional[dict]]:
    """The largest step (<= room) found whose scallop is within h: (step, scallop, pass) or None; the
    smallest step found above it (step, scallop) or None; the row values of the smallest step tried above."""
    best: Optional[tuple[float, float, PassPositions]] = None
    over: Optional[tuple[float, float]] = None
    smallest: Optional[dict] = None
    for _ in range(MAX_TRIALS):
        a = frame.a1 if s >= room - 1e-9 else prev.a + s
        trial = make(a)
        value = meter.scallop(before, prev, trial, excluded) if trial is not None else math.inf
        if value <= h:
            if best is None or s > best[0]:
                best = (s, value, trial)
            if s >= room - 1e-9 or h - value <= SCALLOP_REL * h:
                break
        elif over is None or s < over[0]:
            over = (s, value)
            smallest = dict(meter.rows)
        if over is not None and best is not None and over[0] - best[0] < STEP_TOL:
            break
        s = _next_step(s, value, h, best, over, room)
    return best, over, smallest


def _next_step(s: float, value: float, h: float, best, over, room: float) -> float:
    """The next trial step: scallop ~ step^2, so interpolate sqrt(scallop) linearly in the step inside the
    bracket, kept a tenth of the bracket away from its ends; outside a bracket, grow or shrink by the ratio."""
    if best is not None and over is not None:
        (s0, v0, _), (s1, v1) = best, over
        r0, r1 = math.sqrt(max(v0, 0.0)), math.sqrt(v1) if math.isfinite(v1) else math.inf
        t = (math.sqrt(h) - r0) / (r1 - r0) if math.isfinite(r1) and r1 > r0 else 0.5
        t = min(0.9, max(0.1, t))
        return s0 + t * (s1 - s0)
    if over is None:  # all within the tolerance: grow
        ratio = math.sqrt(h / value) if value > 0 else 2.0
        return min(room, s * min(2.0, max(1.05, ratio)))
    ratio = math.sqrt(h / value) if math.isfinite(value) and value > 0 else 0.5  # all above: shrink
    return s * min(0.95, max(0.3, ratio))
