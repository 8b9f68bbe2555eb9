"""Side step from a scallop height for multipoint 5-axis finishing.

Passes are placed one after the other across the boundary: the first on the start edge, each next one at the
largest side step for which the scallop left between it and the passes before it, measured on the real tool
positions by multipoint_meter's ScallopMeter, is at most `MultipointParams.scallop`; the last on the far edge.

The search per pass brackets the step (the scallop grows about with the square of the step, so the next trial
interpolates in sqrt(scallop)), keeps the largest step found within the tolerance and stops when the scallop is
within SCALLOP_REL of it or the bracket is narrower than STEP_TOL. The step found is then searched again
down to one that also holds the rows near the passes' ends (ScallopMeter.end_rows, where the cusp rises past
the last position) if a smaller step can (_Placer._hold_ends). Rows where one of the two passes has no
good position near them (failed positions, the ends of the passes) are not measured and are counted. All the
trial passes of the placement stay within the work estimate's: MAX_TRIALS per pass of its pass limit.

Where the tolerance cannot be held the placement degrades instead of failing: rows still above it at the
smallest step tried above it are left out of the strip's measure and the step is searched again, as often as
rows remain to leave out; the pass before is placed once more with its strip measured to its farther contact
on those rows (what it leaves between its two contacts there is then held by the passes before it). A strip
none of whose rows can be held, or held only below the estimate's step (`ball_step`: stepping on by less would
creep), gets the estimate's step. Once all passes are placed, those strips are measured again with every pass
that reaches them (later passes remove part of what two passes leave), passes are added where one lowers the
rows still above the tolerance (a tilted tool cuts millimetres off its footprint, so the pass that reaches
them may belong elsewhere), and what is still above it is reported as `LeftArea`s (where, how high):
NOT_REACHED where rows were left out (the tool does not reach the face there: a rim, an edge, a steep flank
past the tilt limit), OVER_SCALLOP otherwise. Nothing is silently accepted.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, sample_segment
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.strategies.multipoint_meter import Frame, PassPositions, ScallopMeter, row_key

SCALLOP_REL = 0.02      # a pass is accepted once its scallop is within 2 % below the tolerance
STEP_TOL = 0.005        # mm: or once the bracket on the step is this narrow
MAX_TRIALS = 14         # trial passes per pass of the pass limit, on average (one search: at most this many)
FILL_TRIES = 4          # offsets tried for each pass added where the scallop is not held
END_RISE = 1.25         # the end rows' scallop up to this x the tolerance is held by a smaller step (_hold_ends)
END_TRIALS = 4          # trial passes searching that step


NOT_REACHED = "not reached"    # rows no side step holds: left out of the strip's measure
OVER_SCALLOP = "over scallop"  # rows of a strip no side step of at least the estimate's holds


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
               f"scallop {params.scallop:g} mm (corner radius {Ri:g} mm: up to {passes} passes, {passes * MAX_TRIALS} "
               f"trial passes in all) and forward step {params.forward_step:g} mm over a {width:.6g} mm wide boundary",
               "max_positions")
    return count


def place_passes(face: BezierFace, rect: Rect, params: Any, Ri: float, position: Callable[[np.ndarray], Any],
                 meter: ScallopMeter, failed: int, progress: Optional[Callable[[float], bool]] = None
                 ) -> tuple[list[PassPositions], ScallopPlacement]:
    """Passes across `rect`, each at the largest side step whose scallop with the passes before it is at most
    params.scallop. `position(xy)` positions footprint points (MultipointResults). Every pass runs the same
    way (+f); the caller alternates them for zigzag."""
    placer = _Placer(rect, params, Ri, position, meter)
    frame = meter.frame
    while placer.placed[-1].a < frame.a1 - 1e-9:
        a = placer.next_pass()
        if progress is not None and progress((a - frame.a0) / max(frame.a1 - frame.a0, 1e-12)) is False:
            raise Cancelled("multipoint tool path computation cancelled")
    return placer.placed, placer.finish()


class _Placer:
    """The passes placed so far, the report, and what the strips not held left out."""

    def __init__(self, rect: Rect, params: Any, Ri: float, position: Callable[[np.ndarray], Any],
                 meter: ScallopMeter) -> None:
        self.rect, self.params, self.position, self.meter = rect, params, position, meter
        frame = meter.frame
        self.h = float(params.scallop)
        self.limit = estimate_passes(frame.a1 - frame.a0, Ri, self.h)
        self.least = ball_step(Ri, self.h)  # no pass nearer than this to the one before (but the last one)
        self.budget = self.limit * MAX_TRIALS  # the trial passes estimate_work counted
        self.report = ScallopPlacement()
        self.far: frozenset = frozenset()  # rows where the next pass's strip runs to its farther contact
        self.redone: set = set()  # passes placed a second time
        first = self.make(frame.a0)
        if first is None:
            raise TmmError("the footprint is empty")
        self.placed = [first]
        self.report.offsets.append(first.a)
        self.report.scallops.append(0.0)
        self.left_out: dict[int, set] = {}  # per strip not held (id of the pass ending it): rows left out
        self.step = min(float(params.side_step), frame.a1 - frame.a0)

    def make(self, a: float) -> Optional[PassPositions]:
        frame = self.meter.frame
        seg = clip_line_to_rect(a * frame.c, frame.f, self.rect)
        if seg is None:
            return None
        if (seg[1] - seg[0]) @ frame.f < 0:
            seg = seg[::-1]
        xy = sample_segment(seg[0], seg[1], self.params.forward_step)
        self.report.trials += 1
        return PassPositions(a, xy, self.position(xy), self.far)

    def next_pass(self) -> float:
        """Places the next pass (or the one before once more); returns the across offset reached."""
        placed, report, frame, h = self.placed, self.report, self.meter.frame, self.h
        if len(placed) >= self.limit:
            raise TmmError(f"scallop {h:g} mm needs more than {self.limit} passes over this boundary (the "
                           "estimate the work was checked against); use a larger scallop")
        prev, before = placed[-1], placed[-3:-1]
        room = frame.a1 - prev.a
        best, excluded = _hold(self.make, self.meter, before, prev, h, min(self.step, room), room,
                               min(self.least, room), self._spare())
        if excluded and len(placed) > 1 and len(placed) - 1 not in self.redone:
            return self._redo(excluded)
        self.far = frozenset()
        if best is None:  # the estimate's step, the strip measured as it is
            s_fall = min(self.least, room)
            trial = self.make(frame.a1 if s_fall >= room - 1e-9 else prev.a + s_fall)
            if trial is None:
                raise TmmError(f"no pass fits the boundary after the pass at {prev.a - frame.a0:.4g} mm")
            best = (self.step, self.meter.scallop(before, prev, trial, _intervals(excluded, self.meter)), trial)
        elif not excluded:
            best = self._hold_ends(best, before, prev)
        s_ok, value, trial = best
        if excluded or value > h:
            self.left_out[id(trial)] = {row_key(t) for t in excluded}
        placed.append(trial)
        report.offsets.append(trial.a)
        report.scallops.append(value)
        self.step = s_ok
        return trial.a

    def _spare(self) -> int:
        """The trials left for this pass: one is kept for each pass that may still follow (its fallback), so
        the trials stay within the estimate's."""
        return self.budget - self.report.trials - (self.limit - len(self.placed))

    def _hold_ends(self, best: tuple, before: list[PassPositions], prev: PassPositions) -> tuple:
        """The step found on the rows, searched again (at most END_TRIALS trial passes) for the largest one
        that also holds the end rows (ScallopMeter.end_rows) when they are above the tolerance by at most
        END_RISE: a smaller step holds the cusp that rises where the passes end. More than that is the tool
        not reaching the face near its edge, which no step holds (the ends are not the placement's rows:
        never reported). Unchanged if no step tried holds them."""
        s, _, trial = best
        ends = self._ends(before, prev, trial)
        if not self.h < ends <= END_RISE * self.h:
            return best
        held: Optional[tuple] = None
        over = (s, ends)
        s_try = max(self.least, s * math.sqrt(self.h / ends))
        for _ in range(END_TRIALS):
            again = self.make(prev.a + s_try) if self._spare() > 0 and s_try < over[0] - STEP_TOL else None
            if again is None:
                break
            value = self.meter.scallop(before, prev, again)
            worst = max(value, self._ends(before, prev, again))
            if worst <= self.h:
                held = (s_try, worst, again, value)
                if self.h - worst <= SCALLOP_REL * self.h:
                    break
            else:
                over = (s_try, worst)
                if s_try <= self.least + 1e-12:
                    break
            if held is not None and over[0] - held[0] < STEP_TOL:
                break
            s_try = max(self.least, _next_step(s_try, worst, self.h, held and held[:3], over, over[0]))
        return best if held is None else (held[0], held[3], held[2])

    def _ends(self, before: list[PassPositions], prev: PassPositions, new: PassPositions) -> float:
        rows = self.meter.end_rows(prev, new)
        return self.meter.scallop(before, prev, new, at=rows) if len(rows) else 0.0

    def _redo(self, excluded: list[float]) -> float:
        """Rows no step holds lie where the previous pass cuts the row between its two contacts (its strip
        ended at the nearer one): that pass is placed once more with its strip measured to its farther
        contact on those rows."""
        placed = self.placed
        self.redone.add(len(placed) - 1)
        self.far = frozenset(row_key(t) for t in excluded)
        gone = placed.pop()
        self.report.offsets.pop()
        self.report.scallops.pop()
        self.left_out.pop(id(gone), None)
        self.step = gone.a - placed[-1].a
        return placed[-1].a

    def finish(self) -> ScallopPlacement:
        """Passes added where they lower what the strips not held leave; those strips then measured again
        with every pass that reaches them, and reported."""
        self.far = frozenset()
        while self._fill():
            pass
        for k, p in enumerate(self.placed):
            if id(p) in self.left_out:
                self.report.scallops[k], areas = _left_areas(self.placed, k, self.left_out[id(p)], self.meter,
                                                             self.h)
                self.report.unreached += areas
        self.report.rows_skipped = self.meter.rows_skipped
        return self.report

    def _over(self) -> dict:
        """The rows of the strips not held still above the tolerance, every pass cut: {(pass id, row): the
        across coordinate of the row's highest needle}."""
        out = {}
        for k, p in enumerate(self.placed):
            if id(p) in self.left_out:
                for t, x in _over_rows(self.placed, k, self.meter, self.h).items():
                    out[(id(p), t)] = x
        return out

    def _fill(self) -> bool:
        """Adds the pass, among FILL_TRIES candidates (_candidates), that leaves the fewest rows of the strips
        not held above the tolerance, if fewer than now: the strips' rows were read with their two passes,
        and on a small face a pass elsewhere (a tilted tool cuts millimetres off its footprint) may reach what
        they do not. Returns whether a pass was added."""
        placed = self.placed
        over = self._over()
        if not over or len(placed) >= self.limit:
            return False
        best: Optional[tuple[int, PassPositions]] = None
        for a in self._candidates(over)[:FILL_TRIES]:
            trial = self.make(a) if self.report.trials < self.budget else None
            if trial is None:
                continue
            j = int(np.searchsorted([p.a for p in placed], a))
            self._insert(j, trial)
            left = len(self._over())
            self._remove(j)
            if left < len(over) and (best is None or left < best[0]):
                best = (left, trial)
        if best is not None:
            self._insert(int(np.searchsorted([p.a for p in placed], best[1].a)), best[1])
        return best is not None

    def _candidates(self, over: dict) -> list[float]:
        """Offsets for a pass added: for each row left above the tolerance, the offset at which the contacts
        of the passes on either side of its highest needle on that row would reach it (interpolated between
        theirs); then the middles of the widest strips within the tool's reach of such a needle."""
        placed, meter = self.placed, self.meter
        out = []
        for (_, t), x in over.items():
            if not math.isfinite(t):
                continue
            touch = [meter.row_contact(p, t) for p in placed]
            for j in range(1, len(placed)):
                x0, x1 = touch[j - 1], touch[j]
                if min(x0, x1) <= x <= max(x0, x1) and x1 != x0:
                    out.append(placed[j - 1].a + (x - x0) / (x1 - x0) * (placed[j].a - placed[j - 1].a))
        reach = meter.Ro + meter.Ri
        near = [j for j in range(1, len(placed))
                if any(placed[j - 1].a - reach <= x <= placed[j].a + reach for x in over.values())]
        near.sort(key=lambda j: placed[j - 1].a - placed[j].a)
        out += [0.5 * (placed[j - 1].a + placed[j].a) for j in near]
        return [a for a in out if min(abs(a - p.a) for p in placed) >= STEP_TOL]

    def _insert(self, j: int, p: PassPositions) -> None:
        """Pass p placed before pass j: the strip it splits, if not held, is two strips not held."""
        if id(self.placed[j]) in self.left_out:
            self.left_out[id(p)] = set(self.left_out[id(self.placed[j])])
        self.placed.insert(j, p)
        self.report.offsets.insert(j, p.a)
        self.report.scallops.insert(j, 0.0)  # measured in finish

    def _remove(self, j: int) -> None:
        p = self.placed.pop(j)
        self.left_out.pop(id(p), None)
        self.report.offsets.pop(j)
        self.report.scallops.pop(j)


def _hold(make, meter: ScallopMeter, before, prev: PassPositions, h: float, s: float, room: float, least: float,
          spare: int) -> tuple[Optional[tuple], list[float]]:
    """The largest step, at least `least`, holding h on the strip's rows: (step, scallop, pass) or None, and the
    rows left out of the strip's measure: those still above h at the smallest step tried above it, material
    the next pass does not remove at any step. They are left out and the step searched again, until no row
    is left to leave out, or every row is, or the `spare` trials are spent."""
    excluded: list[float] = []
    while spare > 0:
        best, smallest, tried = _search(make, meter, before, prev, h, s, room, _intervals(excluded, meter),
                                        min(MAX_TRIALS, spare))
        spare -= tried
        if best is not None and best[0] >= least - 1e-12:
            return best, excluded
        # below the estimate's step (the ball's on a plane) a step holds only where a pass leaves no scallop
        # of its own beside rows it cannot reach: stepping on by it would creep (thousands of passes a
        # micrometre apart)
        rows = smallest or {}
        bad = [t for t, v in rows.items() if v > h]
        if not bad or len(bad) == len(rows):
            break  # nothing to leave out, or every row: no step holds this strip (placed as estimated)
        excluded += bad
    return None, excluded


def _intervals(rows: Sequence[float], meter: ScallopMeter) -> list[tuple[float, float]]:
    half = 0.5 * meter.row_spacing
    return [(t - half, t + half) for t in rows]


def _left_areas(placed: list[PassPositions], k: int, left_out: set, meter: ScallopMeter, h: float
                ) -> tuple[float, list[LeftArea]]:
    """The strip before pass k measured again with every pass that reaches it cut, later ones too: its
    scallop over the rows not left out, and LeftAreas for its rows still above h (NOT_REACHED those left out
    of its measure, OVER_SCALLOP the others)."""
    prev, new = placed[k - 1], placed[k]
    value = _measure_all(placed, k, meter)
    rows, spans = dict(meter.rows), dict(meter.spans)
    out = [t for t in rows if row_key(t) in left_out and rows[t] > h]
    over = [t for t, v in rows.items() if v > h and row_key(t) not in left_out]
    scallop = max((v for t, v in rows.items() if row_key(t) not in left_out), default=0.0)
    if not rows and value > h:  # nothing measured (no good positions near): the whole strip
        along = meter.frame.to_frame(new.xy)[:, 1]
        over, scallop = list(np.arange(along.min(), along.max() + 1e-9, meter.row_spacing)), value
        spans = {t: (prev.a, new.a, 0.5 * (prev.a + new.a)) for t in over}
    return scallop, (_areas(meter, out, rows, spans, NOT_REACHED) + _areas(meter, over, rows, spans, OVER_SCALLOP))


def _measure_all(placed: list[PassPositions], k: int, meter: ScallopMeter) -> float:
    """The scallop of the strip before pass k with every pass that reaches it cut (meter.rows: per row)."""
    prev, new = placed[k - 1], placed[k]
    reach = 2.0 * (meter.Ro + meter.Ri)
    others = [p for j, p in enumerate(placed) if j not in (k - 1, k) and prev.a - reach <= p.a <= new.a + reach]
    return meter.scallop(others, prev, new)


def _over_rows(placed: list[PassPositions], k: int, meter: ScallopMeter, h: float) -> dict:
    """The rows (row_key) of the strip before pass k above h, every pass that reaches it cut, with the across
    coordinate of their highest needle."""
    value = _measure_all(placed, k, meter)
    over = {row_key(t): meter.spans[t][2] for t, v in meter.rows.items() if v > h}
    return over or ({math.inf: 0.5 * (placed[k - 1].a + placed[k].a)} if value > h else {})


def _areas(meter: ScallopMeter, bad: list[float], values: dict, spans: dict, reason: str) -> list[LeftArea]:
    """LeftAreas over the rows `bad` (along coordinates), runs of neighbouring rows joined; `values` the rows'
    measured heights, `spans` their (across from, across to, across of the highest needle), kept within the
    boundary."""
    frame = meter.frame
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
        a0 = max(frame.a0, min(spans[t][0] for t in run))
        a1 = min(frame.a1, max(spans[t][1] for t in run))
        corners = np.round(frame.to_world(np.array([[a0, lo], [a1, lo], [a1, hi], [a0, hi]])), 9)
        at = np.round(frame.to_world(np.array([[min(max(spans[worst][2], a0), a1), worst]]))[0], 9)
        out.append(LeftArea(a0 - frame.a0, a1 - frame.a0, (lo, hi), corners, float(values.get(worst, math.inf)),
                            (float(at[0]), float(at[1])), len(run), reason))
    return out


def _search(make, meter: ScallopMeter, before, prev: PassPositions, h: float, s: float, room: float,
            excluded: list, trials: int) -> tuple[Optional[tuple], Optional[dict], int]:
    """The largest step (<= room) found whose scallop is within h, in at most `trials` trial passes:
    (step, scallop, pass) or None; the row values of the smallest step tried above h (or None); the trial
    passes made."""
    frame = meter.frame
    best: Optional[tuple[float, float, PassPositions]] = None
    over: Optional[tuple[float, float]] = None
    smallest: Optional[dict] = None
    for n in range(1, trials + 1):
        trial = make(frame.a1 if s >= room - 1e-9 else prev.a + s)
        value = meter.scallop(before, prev, trial, excluded) if trial is not None else math.inf
        if value <= h:
            if best is None or s > best[0]:
                best = (s, value, trial)
            if s >= room - 1e-9 or h - value <= SCALLOP_REL * h:
                return best, smallest, n
        elif over is None or s < over[0]:
            over = (s, value)
            smallest = dict(meter.rows)
        if over is not None and best is not None and over[0] - best[0] < STEP_TOL:
            return best, smallest, n
        s = _next_step(s, value, h, best, over, room)
    return best, smallest, trials


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
