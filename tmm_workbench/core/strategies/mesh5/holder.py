"""The whole tool (core.tools.assembly) on a 5-axis mesh finish: what the shank and holder changed, and the
cut moves checked against the model.

The C-space bounds them already: with an assembly, S2 is the assembly drop (lift.lifts), so a posture whose
shank or holder would come closer than its clearance is unavailable, and the optimiser tilts the tool away or
the place is left unfinished (the plan's strips). Two things are added here:

* what the holder changed, for the report: the CC points where the upright posture (the axis along the
  normal) would need a larger lift with the assembly than the cutter alone: there the tool tilts away;
* the moves between positions: the C-space clears the tool at its positions and the step-over checks the
  middle of each move by a lift, which cannot help where only another posture clears the holder (a move
  sweeping the holder past a wall's corner). Every cut move is checked by core.verify.holder_clearance (its
  shank and holder against the model's surface points along the move, axis by slerp); a move that comes closer
  than the clearance is left out (the segment split there, the linker leaves and enters along the axis), and
  counted in the report, never cut silently;
* the links (link_clear): each pass's entry and exit, the linker's axis retract then straight up to the transit
  height, checked the same way; where straight up brings the shank or holder into the model (under an
  overhang) the pass is left and entered along its axis all the way to the transit height, checked again.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import List, Optional

import numpy as np

from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.report_text import within
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.stepover import AdaptivePlan
from tmm_workbench.core.strategies.segment_split import keep_runs
from tmm_workbench.core.toolpath import Move, MoveKind, Toolpath
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

SAMPLE_STEP = 0.5      # mm between checked samples along a move
SURFACE_STEP = 0.25    # mm between the model's surface points the tilted bodies are measured to
CHECK_TOL = 0.01       # mm closer than the clearance that counts (the surface sample's own error is below it)


@dataclass
class HolderNote:
    """What the shank and holder did to a 5-axis mesh finish (app.tool_assembly.report shows `summary()` and
    draws `spots`)."""
    assembly: str
    cc_points: int                     # CC points planned
    tilted: np.ndarray                 # (k, 3) CC points whose upright posture the shank or holder blocks
    most_tilt_deg: float               # the largest tilt from the normal chosen at them
    left_out: np.ndarray               # (m, 3) tips of moves left out (closer to the model than the clearance)
    samples: int                       # positions checked along the cut moves
    pieces: dict = field(default_factory=dict)   # piece -> samples that came too close

    @property
    def affected(self) -> int:
        """Moves left out: material the plan counted on is not cut there."""
        return len(self.left_out)

    @property
    def spots(self) -> np.ndarray:
        return np.vstack([self.tilted, self.left_out])

    def summary(self) -> str:
        text = f"{self.assembly}: the shank and holder bound every C-space"
        if len(self.tilted):
            text += (f"; at {len(self.tilted)} of {self.cc_points} CC points they block the upright posture and the "
                     f"tool tilts away (up to {self.most_tilt_deg:.0f} deg from the normal)")
        if len(self.left_out):
            pieces = ", ".join(f"{p} {n}" for p, n in self.pieces.items())
            text += (f"; {len(self.left_out)} moves left out where they would come closer than the clearance "
                     f"({pieces} samples), {within(self.left_out)}: not cut there")
        return text + f"; checked along the cut moves: {self.samples} positions"


def blocked_upright(reach: MeshReach, cutter: Cutter, assembly: ToolAssembly, points: np.ndarray,
                    frames: np.ndarray) -> np.ndarray:
    """(n,) True where the upright posture (lambda 0) needs a larger lift with the assembly than with the
    cutter alone (or none within a radius clears it)."""
    lam = omg = np.zeros(1)
    alone = lifts(reach, cutter, points, frames, lam, omg, cutter.radius)[:, 0]
    whole = lifts(reach, cutter, points, frames, lam, omg, cutter.radius, assembly=assembly)[:, 0]
    return ~(whole <= alone + 1e-6)


def _moves(segments: List[CutSegment]) -> tuple[Toolpath, np.ndarray]:
    """All segments' positions as one path of feed moves, and the index of the move into each point (-1 at a
    segment's first point: the jump from the previous segment is the linker's, not checked here)."""
    moves, owner = [], []
    for s in segments:
        axes = s.axes if s.axes is not None else np.tile([0.0, 0.0, 1.0], (len(s.tips), 1))
        for i, (t, a) in enumerate(zip(s.tips, axes)):
            moves.append(Move(MoveKind.FEED, *map(float, t), axis=tuple(map(float, a))))
            owner.append(-1 if i == 0 else len(owner))
    return Toolpath(moves), np.asarray(owner)


def guard(mesh, reach: MeshReach, cutter: Cutter, assembly: ToolAssembly, plan: AdaptivePlan,
          segments: List[CutSegment]) -> tuple[List[CutSegment], HolderNote]:
    """The segments with every move whose shank or holder comes closer to the model than its clearance left
    out (the segment split there; pieces of one position dropped), and the note of what the holder did."""
    pts = np.concatenate([p.points for q in plan.passes for p in q.paths]) if plan.passes else np.zeros((0, 3))
    frm = np.concatenate([p.frames for q in plan.passes for p in q.paths]) if plan.passes else np.zeros((0, 3, 3))
    lam = np.concatenate([q.lam for p in plan.passes for q in p.postures]) if plan.passes else np.zeros(0)
    up = blocked_upright(reach, cutter, assembly, pts, frm) if len(pts) else np.zeros(0, dtype=bool)
    most = float(np.degrees(lam[up].max())) if up.any() else 0.0
    path, owner = _moves(segments)
    check = check_holder_clearance(mesh, assembly, path, sample_step=SAMPLE_STEP, surface_step=SURFACE_STEP,
                                   tolerance=CHECK_TOL)
    bad = np.unique(check.move)
    bad = bad[np.isin(bad, owner[owner >= 0])]          # the jumps between segments are the linker's
    cut = np.zeros(len(owner), dtype=bool)
    cut[bad] = True
    out, start = [], 0
    for s in segments:
        n = len(s.tips)
        out += keep_runs(s, np.ones(n, dtype=bool), ~cut[start:start + n])
        start += n
    tips = path.points()
    keep = np.isin(check.move, bad)
    pieces = {str(p): int(np.sum(check.piece[keep] == p)) for p in np.unique(check.piece[keep])}
    note = HolderNote(assembly.describe(), len(pts), pts[up], most, tips[bad], check.samples, pieces)
    return out, note


def optional_guard(mesh, cutter: Cutter, assembly: Optional[ToolAssembly], plan: AdaptivePlan,
                   segments: List[CutSegment]) -> tuple[List[CutSegment], Optional[HolderNote]]:
    """guard() with an assembly; the segments unchanged and no note without one."""
    if assembly is None:
        return segments, None
    return guard(mesh, MeshReach(mesh), cutter, assembly, plan, segments)


# --- the links: leaving and entering a pass with the whole tool clear -------------------------------------------

@dataclass
class LinkNote:
    """What the whole tool did to the links between passes (module doc of link_clear)."""
    checked: int                       # entries and exits checked
    raised: np.ndarray                 # (k, 3) tips whose entry or exit now goes along the axis to the transit height
    blocked: np.ndarray                # (m, 3) tips whose entry or exit stays closer than the clearance
    samples: int

    def summary(self) -> str:
        text = f"links: {self.checked} entries and exits checked ({self.samples} positions)"
        if len(self.raised):
            text += (f", {len(self.raised)} passes left and entered along the tool axis up to the transit height "
                     f"(straight up the shank or holder came closer than the clearance)")
        if len(self.blocked):
            text += (f"; {len(self.blocked)} still closer than the clearance along the axis too, "
                     f"{within(self.blocked)}: check them")
        return text


def _trips(segments: List[CutSegment], policy: LinkPolicy) -> tuple[Toolpath, np.ndarray, np.ndarray]:
    """Every segment's entry and exit as the linker makes them (each linked alone), as trips down from the
    clearance height and back, in one path; the segment owning each move (-1: between trips) and each trip's
    tip (the segment's first or last)."""
    moves, owner, tips = [], [], []
    for k, seg in enumerate(segments):
        m = link([seg], policy).moves
        entry, exit_ = m[:5], m[-5:][::-1]          # (clearance ... tip), each as the linker moves
        for part, ends in ((entry, not seg.joined), (exit_, k + 1 == len(segments) or not segments[k + 1].joined)):
            if ends:
                trip = part + part[::-1][1:]
                moves += trip
                owner += [-1] + [k] * (len(trip) - 1)
                tips.append((part[-1].x, part[-1].y, part[-1].z))
    return Toolpath(moves), np.asarray(owner, dtype=np.int64), np.asarray(tips, dtype=float).reshape(-1, 3)


def _to_transit(seg: CutSegment, policy: LinkPolicy) -> float:
    """The axis retract that takes the segment's first and last tips along their axes to the transit height
    (the tilted tool's lowest point at the safe height): no vertical move is left below it."""
    out = policy.axis_retract
    for i in (0, len(seg) - 1):
        a = np.asarray(seg.axis(i))
        out = max(out, (policy.safe_height + policy.lowest_below_tip(tuple(a)) - seg.tips[i, 2]) / max(a[2], 1e-3))
    return float(out) + 1e-6


def link_clear(mesh, segments: List[CutSegment], policy: LinkPolicy, assembly: Optional[ToolAssembly]
               ) -> tuple[Toolpath, Optional[LinkNote]]:
    """The segments linked (core.linking, along the axis) with every entry and exit checked for the shank and
    holder (core.verify.holder_clearance): the straight rise to the transit height after the axis retract
    ignores the holder, which under an overhang can come up into it. A segment whose entry or exit comes closer
    than the clearance leaves and enters along its tool axis all the way to the transit height, and that is
    checked again; what still comes closer is reported in the note, never linked silently. No assembly: the
    linker's path and no note."""
    if assembly is None or not segments:
        return link(segments, policy), None
    segs = list(segments)
    path, owner, tips = _trips(segs, policy)
    check = check_holder_clearance(mesh, assembly, path, sample_step=SAMPLE_STEP, surface_step=SURFACE_STEP,
                                   tolerance=CHECK_TOL)
    bad = sorted({int(k) for k in owner[check.move] if k >= 0})
    samples, checked = check.samples, len(tips)
    for k in bad:
        segs[k] = replace(segs[k], axis_retract=_to_transit(segs[k], policy))
    blocked = np.zeros((0, 3))
    if bad:
        again, owner2, tips2 = _trips([segs[k] for k in bad], policy)
        check2 = check_holder_clearance(mesh, assembly, again, sample_step=SAMPLE_STEP, surface_step=SURFACE_STEP,
                                        tolerance=CHECK_TOL)
        samples += check2.samples
        still = sorted({int(k) for k in owner2[check2.move] if k >= 0})
        blocked = np.array([segs[bad[k]].tips[0] for k in still]).reshape(-1, 3)
    raised = np.array([segs[k].tips[0] for k in bad]).reshape(-1, 3)
    return link(segs, policy), LinkNote(checked, raised, blocked, samples)
