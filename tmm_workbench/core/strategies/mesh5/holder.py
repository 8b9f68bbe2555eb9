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
  counted in the report, never cut silently.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import List, Optional

import numpy as np

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
            (x0, y0, _), (x1, y1, _) = self.left_out.min(0), self.left_out.max(0)
            pieces = ", ".join(f"{p} {n}" for p, n in self.pieces.items())
            text += (f"; {len(self.left_out)} moves left out where they would come closer than the clearance "
                     f"({pieces} samples), within x {x0:.4g}..{x1:.4g}, y {y0:.4g}..{y1:.4g} mm: not cut there")
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
