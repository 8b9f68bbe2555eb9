"""The holder guard: a 3-axis strategy's cut segments made safe for the whole tool (core.tools.assembly). The
shank, neck and holder are dropped over every CL point and along every move (core.query.drop_assembly, the cutter
left out: its own drop made the points); where one of them would come closer to the model than its clearance:
  lift       the tool rises there to where they keep it (the surface below keeps material); a move that had to
             rise becomes lines through its samples, each at least the bodies' height (arcs dropped there);
  leave_out  the moves there are not cut: the segment is split and the linker retracts over the gap.
Raising a 3-axis tool never gouges (the cutter's drop is below), and the bodies' drop is monotone in height, so
a vertical entry to a kept point is clear. Between two samples the bodies' height can rise steeply (a shank's
edge rolling over a sharp rim: 0.19 mm under it halfway along a 0.5 mm step was measured): lifted moves get
points inserted (a staircase where they climb or fall) until they pass at most BETWEEN_MM under it, inside the
clearance; so do moves clear at both ends that pass under it in between (a raster's lean move climbing past a
wall's top). What it changed is reported with the shortest stick-out that cuts everything
(core.verify.holder_clearance.minimum_stick_out). With the params' `stock` (what the Job's earlier ops left:
core.sim.stock_bodies) the bodies keep their clearance from the material standing off the design as well."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.params import param
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.report_text import within
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.stock_bodies import bodies_drop
from tmm_workbench.core.strategies.segment_split import keep_runs, keeps_end, move_samples
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.verify.holder_clearance import StickOut, minimum_stick_out

LIFT, LEAVE_OUT = "lift", "leave_out"
BODIES = ("neck", "shank", "holder")
TOLERANCE_MM = 1e-4    # a body this little above a point is not a collision (the drops' own accuracy is ~1e-9)
BETWEEN_MM = 0.005     # a lifted move may pass this far under the bodies' height between its points (of ~1 mm)
MIN_GAP_MM = 0.005     # and points are not inserted closer than this
BETWEEN_FRACTIONS = (0.25, 0.5, 0.75)   # where a move clear at both ends is checked in between
MAX_ROUNDS = 12        # halvings: a 0.5 mm sample step down to about 0.1 um
MARK_CELL_MM = 0.5     # the report's spots: one affected point per cell this wide (the view draws them)
MAX_SPOTS = 20000      # and at most this many (a larger region keeps every k-th)


@dataclass
class WholeToolParams:
    """The fields a 3-axis strategy's params carry for the holder guard: the assembly (None: the cutter alone),
    what to do where a body would come too close, and the list its HolderReport is appended to."""
    assembly: Any = None
    holder_collision: str = param(LIFT, "holder collision", choices=(LIFT, LEAVE_OUT))
    holder_notes: Optional[list] = None
    # what the Job's earlier ops left (core.sim.stock_bodies.InProcessStock): the bodies keep their clearance
    # from it too (None: from the model only)
    stock: Any = None


def apply(mesh: TriMesh, params: WholeToolParams, segments: list[CutSegment], step: float,
          surface: Optional[DropSurface], diagnostics: dict) -> list[CutSegment]:
    """A strategy's segments through the guard when its params carry an assembly: diagnostics "holder" (the
    report, also appended to params.holder_notes) and "top" raised to the highest lifted tip."""
    if params.assembly is None:
        return segments
    segments, report = guard(mesh, params.assembly, segments, params.holder_collision, step, surface,
                             stock=getattr(params, "stock", None))
    diagnostics["holder"] = report
    if "top" in diagnostics:
        diagnostics["top"] = max([diagnostics["top"]] + [float(seg.tips[:, 2].max()) for seg in segments if len(seg)])
    if params.holder_notes is not None:
        params.holder_notes.append(report)
    return segments


@dataclass
class HolderReport:
    mode: str
    points: int                                   # CL points and move samples checked
    affected: int = 0                             # of them raised (lift) or left out (leave_out)
    max_lift: float = 0.0                         # mm, the most a point was raised (or would have been)
    region: Optional[tuple[float, float, float, float]] = None   # xmin, ymin, xmax, ymax of the affected points
    pieces: dict = field(default_factory=dict)    # piece -> affected points it set
    stick_out: Optional[StickOut] = None          # the shortest stick-out that cuts everything
    note: str = ""
    spots: Optional[np.ndarray] = None            # (n, 3) where material is left: affected CL points at their
    #                                               own height, thinned to one per MARK_CELL_MM cell for the view

    def summary(self) -> str:
        if not self.affected:
            return f"the shank and holder keep their clearance everywhere ({self.points} points checked)"
        what = "raised" if self.mode == LIFT else "left out"
        by = ", ".join(f"{p} {n}" for p, n in sorted(self.pieces.items()))
        text = (f"{self.affected} of {self.points} points {what} where the shank or holder would come closer than "
                f"its clearance ({by}; up to {self.max_lift:.3f} mm), "
                f"{within(np.reshape(self.region, (2, 2)))}: material is left there")
        if self.stick_out is not None:
            text += f"; {self.stick_out.summary()}"
        return text + (f" ({self.note})" if self.note else "")


def guard(mesh: TriMesh, assembly: ToolAssembly, segments: list[CutSegment], mode: str, step: float,
          surface: Optional[DropSurface] = None, progress: Optional[Progress] = None, stock: Any = None
          ) -> tuple[list[CutSegment], HolderReport]:
    """The segments made safe for the shank and holder (see the module) and what was changed; `stock`: the
    in-process stock they keep clear of as well (core.sim.stock_bodies.InProcessStock; None: the model only)."""
    if mode not in (LIFT, LEAVE_OUT):
        raise TmmError(f"holder collision must be '{LIFT}' or '{LEAVE_OUT}', got {mode!r}")
    if not step > 0:
        raise TmmError(f"holder guard sample step must be > 0 mm, got {step!r}")
    if any(seg.axes is not None for seg in segments):
        raise TmmError("the holder guard takes 3-axis segments (a vertical tool); 5-axis moves are checked by "
                       "core.verify.holder_clearance")
    drop = bodies_drop(mesh, assembly, surface, stock)
    sampled = [move_samples(seg, step) for seg in segments]
    allpts = np.vstack([p for p, _ in sampled]) if sampled else np.zeros((0, 3))
    zb, owner = drop.heights_of(BODIES, allpts[:, :2], progress=progress)
    over = zb - allpts[:, 2]
    hit = (over > TOLERANCE_MM) & (owner >= 0)   # where the needle standing in for the cutter set it, no body did
    between, between_owner = _low_between(drop, sampled, allpts)
    owner = np.where(between & ~hit, between_owner, owner)   # the piece that set the height between
    hit |= between
    report = HolderReport(mode, len(allpts))
    if not hit.any():
        return segments, report
    report.affected = int(hit.sum())
    report.max_lift = max(0.0, float(over[hit].max()))
    p = allpts[hit]
    report.region = (float(p[:, 0].min()), float(p[:, 1].min()), float(p[:, 0].max()), float(p[:, 1].max()))
    report.spots = spots(p)
    names, counts = np.unique(drop.piece_names(owner[hit]), return_counts=True)
    report.pieces = {str(n): int(c) for n, c in zip(names, counts)}
    out: list[CutSegment] = []
    start = 0
    end_kept = True   # the previous segment's last tip: a segment joined to it stays joined only then
    for seg, (pts, move) in zip(segments, sampled):
        end = start + len(pts)
        seg_hit, seg_z = hit[start:end], zb[start:end]
        start = end
        if not seg_hit.any():
            pieces = [seg if end_kept else replace(seg, joined=False)]
        elif mode == LIFT:
            tips = pts.copy()
            tips[:, 2] = np.maximum(tips[:, 2], seg_z)
            pieces = [replace(seg, tips=_refined(drop, tips), arcs=None, joined=seg.joined and end_kept)]
        else:
            pieces = _leave_out(seg, seg_hit, move, end_kept)
        out += pieces
        end_kept = mode == LIFT or keeps_end(seg, pieces)
    try:
        report.stick_out = minimum_stick_out(mesh, assembly, allpts[:, :2], surface=drop.surface)  # along the moves
    except TmmError as exc:  # a holder narrower than the shank somewhere: no stick-out is monotone
        report.note = f"no shortest stick-out told: {exc}"
    return out, report


def spots(points: np.ndarray, cell: float = MARK_CELL_MM, most: int = MAX_SPOTS) -> np.ndarray:
    """One of `points` per `cell`-wide XY cell (the lowest there: where the most is left), at most `most`."""
    if not len(points):
        return np.zeros((0, 3))
    keys = np.floor(points[:, :2] / cell).astype(np.int64)
    order = np.lexsort((points[:, 2], keys[:, 1], keys[:, 0]))
    k = keys[order]
    first = np.ones(len(k), dtype=bool)
    first[1:] = np.any(k[1:] != k[:-1], axis=1)
    kept = points[order[first]]
    return kept[:: max(1, -(-len(kept) // most))]


def _low_between(drop: AssemblyDrop, sampled: list, allpts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per sample: whether the straight move from it to the segment's next sample passes more than BETWEEN_MM
    under the bodies' height at a quarter, half or three quarters of the way, both ends clear (a raster's lean
    move climbing past a wall's top: the shank's edge crosses the wall's clearance between two samples 0.4 mm
    apart). Both ends of such a move count as hit: the segment is lifted and refined (lift), the move left out
    (leave_out). With the piece that set the height there (-1 elsewhere)."""
    ends = np.cumsum([len(p) for p, _ in sampled])
    inner = np.ones(len(allpts), dtype=bool)
    inner[ends - 1] = False                        # a segment's last sample has no next one in it
    first = np.flatnonzero(inner)
    out = np.zeros(len(allpts), dtype=bool)
    owners = np.full(len(allpts), -1, dtype=np.int64)
    if not len(first):
        return out, owners
    a, b = allpts[first], allpts[first + 1]
    low = np.zeros(len(first), dtype=bool)
    by = np.full(len(first), -1, dtype=np.int64)
    for t in BETWEEN_FRACTIONS:
        at = a + t * (b - a)
        zb, owner = drop.heights_of(BODIES, at[:, :2])
        now = (zb - at[:, 2] > BETWEEN_MM) & (owner >= 0) & ~low
        by[now] = owner[now]
        low |= now
    for k in (first[low], first[low] + 1):
        out[k] = True
        owners[k] = by[low]
    return out, owners


def _refined(drop: AssemblyDrop, tips: np.ndarray) -> np.ndarray:
    """Lifted tips with points inserted wherever the straight move between two would pass more than BETWEEN_MM
    under the bodies' height at a quarter, half or three quarters of it (a holder's rounded edge over a sharp rim,
    a shank's edge crossing a wall's clearance: the bodies' height can jump there), down to MIN_GAP_MM apart: a
    climbing or falling move becomes a staircase (up first, or down last: the tool higher, never lower), a level
    one gets the lifted points where it passed under."""
    for _ in range(MAX_ROUNDS):
        a, b = tips[:-1], tips[1:]
        gap = np.hypot(*np.diff(tips[:, :2], axis=0).T)
        low = np.zeros(len(a), dtype=bool)
        lifted = []
        for t in BETWEEN_FRACTIONS:
            mid = a + t * (b - a)
            zb, _ = drop.heights_of(BODIES, mid[:, :2])
            under = (zb - mid[:, 2] > BETWEEN_MM) & (gap > MIN_GAP_MM)
            mid[:, 2] = np.maximum(mid[:, 2], zb)
            low |= under
            lifted.append((under, mid, t))
        if not low.any():
            break
        sloped = low & (np.abs(b[:, 2] - a[:, 2]) > BETWEEN_MM)
        corner = np.where((b[:, 2] > a[:, 2])[:, None], np.column_stack([a[:, :2], b[:, 2]]),
                          np.column_stack([b[:, :2], a[:, 2]]))
        new, keys = [corner[sloped]], [np.flatnonzero(sloped) + 0.5]
        for under, mid, t in lifted:
            level = under & ~sloped
            new.append(mid[level])
            keys.append(np.flatnonzero(level) + t)   # between the move's start (its index) and end, in order
        order = np.argsort(np.concatenate([np.arange(len(tips), dtype=float)] + keys), kind="stable")
        tips = np.vstack([tips] + new)[order]
    return tips


def _leave_out(seg: CutSegment, hit: np.ndarray, move: np.ndarray, joined: bool) -> list[CutSegment]:
    """The segment's runs of clear tips joined by clear moves (`hit` per sample, `move` its move); `joined`:
    whether the previous segment's end was kept (keep_runs)."""
    n = len(seg)
    tip_sample = np.searchsorted(move, np.arange(n), side="right") - 1   # a move's last sample is its tip
    ok_move = np.ones(n, dtype=bool)
    ok_move[np.unique(move[hit])] = False
    return keep_runs(seg, ~hit[tip_sample], ok_move, joined)
