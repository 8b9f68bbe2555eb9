"""The 5-axis mesh op's cycle time estimated without planning it, for the planner's decision (core.plan.five_axis):
about a tenth of the op's own plan (which builds a C-space of every posture at every CC point of every pass).

Strip width. Drive planes a few mm apart across the model are cut into CC points as the op cuts them
(mesh5.cc_paths); at each, the few least tilts of the op's posture grid along the feed are lifted clear of the
mesh by the C-space's own exact drop (mesh5.lift.lifts) and their half-widths at the op's tolerance measured as
the op measures them (stepover.half_widths: the tilted tool's effective cutting profile over the surface's
cross-section, at the op's MARGIN of the tolerance). A CC point's half step is the best posture's narrower side,
seen along the plane normal (the section's slope across the feed shortens it there); a probe plane's, per bin of the
feed, its narrowest CC point's there (the op keeps a finished level per bin, advanced by its worst CC point).

Passes. The op's step control (mesh5.step_replay, the step-over's own rule: each next plane half the
GAP_QUANTILE of the widths the last pass finished beyond the least level it finished, per bin of the feed)
replayed on those half steps, binned by probe plane across and the op's forward step along the feed.

Time. Those planes are cut into CC paths, the tool placed at the probes' most common tilt (lift 0), each path
with a radius of overrun at both ends, zig-zag, linked as the op links (multipoint.link_policy), and the result
timed by the Tarus post (core.post.tarus_writer: the joint speeds, A and C planned, the feeds of the materials
table), as the real op is. A probe CC point where no probed tilt clears the mesh and finishes it within the tolerance
is counted (`blocked`): the op may find a yawed posture there, or leave it for clean-up.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.post import ToolInfo
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies.mesh5 import finish
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths, plane_normal
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.posture import world_placement
from tmm_workbench.core.strategies.mesh5.step_replay import WidthField, replay_planes
from tmm_workbench.core.strategies.mesh5.stepover import MARGIN, half_widths
from tmm_workbench.core.tools.cutter import Cutter

PROBE_SPACING = 3.0   # mm between the probe planes (at least MIN_PROBES across the model)
MIN_PROBES = 8
TILTS = 4             # the least tilts of the posture grid probed at each CC point
OVERRUN_STEPS = 3


@dataclass(frozen=True)
class Mesh5Estimate:
    """The estimate: cycle time s (the Tarus post's), passes, cut length mm, the tilt placed (deg), the probe
    CC points and those no probed tilt finishes (blocked)."""
    seconds: float
    passes: int
    length: float
    tilt_deg: float
    probed: int
    blocked: int


def half_steps(reach: MeshReach, cutter: Cutter, params: finish.Mesh5Params, points: np.ndarray,
               frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(half step mm (n,), best tilt rad (n,)) of n CC points: the best of the grid's TILTS least tilts (module
    doc), each next tilt measured only where the last one widened the step or had none (the step grows with the
    tilt where a flatter tool gouges and must be lifted, then narrows: the profile curves more); 0 and NaN where
    none clears the mesh within a radius or finishes within the tolerance."""
    lam = params.grid().lambdas[:TILTS]
    lift = lifts(reach, cutter, points, frames, lam, np.zeros_like(lam), cutter.radius)   # (n, TILTS), inf: blocked
    best, tilt = np.zeros(len(points)), np.full(len(points), np.nan)
    growing = np.ones(len(points), dtype=bool)
    for k, lam_k in enumerate(lam):
        ask = np.flatnonzero(growing & np.isfinite(lift[:, k]))
        growing[:] = ~np.isfinite(lift[:, k]) & growing    # a blocked tilt: the next may clear
        if ask.size == 0:
            continue
        n = len(ask)
        w, _ = half_widths(reach, cutter, points[ask], frames[ask], np.full(n, lam_k), np.zeros(n), lift[ask, k],
                           MARGIN * params.tolerance)
        w = np.where(np.isinf(w), 2.0 * cutter.radius, w).min(axis=1)      # inf: the mesh ends first
        wider = w > best[ask]
        best[ask[wider]], tilt[ask[wider]] = w[wider], lam_k
        growing[ask[wider | (w <= 0.0)]] = True            # none yet at this tilt: the next may have one
    return best, tilt


def _planes(at: list, across: list, halves: list, probes: np.ndarray, forward_step: float, radius: float
            ) -> np.ndarray:
    """The op's drive planes from the probes' CC points (their plane offsets, feed coordinates and half steps,
    NaN where blocked): its step control replayed on them (step_replay), a quarter diameter apart where
    nothing clears anywhere."""
    half = np.concatenate(halves) if halves else np.zeros(0)
    if not np.isfinite(half).any():
        lo = probes[0] - 0.5 * (probes[1] - probes[0])
        return np.arange(lo + 0.25 * radius, probes[-1] + 0.5 * (probes[1] - probes[0]), 0.5 * radius)
    field = WidthField.binned(np.concatenate(at), np.concatenate(across), half, float(probes[1] - probes[0]),
                              forward_step)
    lo, hi = field.extent()
    return replay_planes(field, lo, hi, radius, forward_step, forward_step)


def segments(mesh: TriMesh, cutter: Cutter, params: finish.Mesh5Params, offsets: np.ndarray, tilt: float) -> list:
    """The estimated passes as cut segments (tips and axes at `tilt` rad along the feed, a radius of overrun at
    both ends, every other pass reversed)."""
    out = []
    for k, off in enumerate(offsets):
        for p in cc_paths(mesh, params.direction(), np.array([off]), params.forward_step, params.chord_tol):
            s = cutter.radius * np.arange(1, OVERRUN_STEPS + 1) / OVERRUN_STEPS
            pts = np.concatenate([p.points[0] - s[::-1, None] * p.frames[0, 0], p.points,
                                  p.points[-1] + s[:, None] * p.frames[-1, 0]])
            frm = np.concatenate([np.repeat(p.frames[:1], OVERRUN_STEPS, 0), p.frames,
                                  np.repeat(p.frames[-1:], OVERRUN_STEPS, 0)])
            n = len(pts)
            tips, axes = world_placement(cutter, pts, frm, np.full(n, tilt), np.zeros(n), np.zeros(n))
            if params.zigzag and k % 2 == 1:
                tips, axes = tips[::-1], axes[::-1]
            out.append(CutSegment(tips, axes=axes, pass_index=k))
    if params.zigzag:   # a reversed pass's paths run the other way too
        out.sort(key=lambda s: (s.pass_index, (1 if s.pass_index % 2 == 0 else -1) * float(s.tips[0] @ (
            np.r_[params.direction(), 0.0]))))
    return out


def estimate(mesh: TriMesh, cutter: Cutter, params: finish.Mesh5Params, tool_info: ToolInfo, feed: float,
             plunge: float, machine: Optional[TarusMachine] = None) -> Mesh5Estimate:
    """The op's cycle time and passes, estimated (module doc); `tool_info` (core.post.ToolInfo) and the feeds
    (mm/s) as the post gets them. TmmError where the op refuses the tool, the tilts or the work."""
    from tmm_workbench.core import path5
    from tmm_workbench.core.linking import link
    from tmm_workbench.core.post import Operation
    from tmm_workbench.core.post.tarus_writer import write_tarus
    from tmm_workbench.core.strategies.multipoint import link_policy

    lo_box, hi_box = mesh.bounds
    finish.estimate_work(params, cutter, tuple(map(float, lo_box)) + tuple(map(float, hi_box)))
    reach = MeshReach(mesh)
    m = plane_normal(params.direction())
    s = mesh.vertices @ m
    lo, hi = float(s.min()), float(s.max())
    count = max(MIN_PROBES, math.ceil((hi - lo) / PROBE_SPACING))
    probes = lo + (hi - lo) * (np.arange(count) + 0.5) / count
    feed_dir = np.array([m[1], -m[0], 0.0])                                  # the op's (mesh5.coverage)
    at, across, halves, tilts, blocked, probed = [], [], [], [], 0, 0
    for p in cc_paths(mesh, params.direction(), probes, params.forward_step, params.chord_tol):
        half, tilt = half_steps(reach, cutter, params, p.points, p.frames)
        ok = half > 0
        blocked += int((~ok).sum())
        probed += len(half)
        tilts.extend(tilt[ok])
        at.append(np.full(len(half), probes[p.plane]))
        across.append(p.points @ feed_dir)
        # LY seen along the plane normal (the section's slope across the feed shortens it)
        halves.append(np.where(ok, np.maximum(half * np.abs(p.frames[:, 1] @ m), 0.05 * cutter.radius), np.nan))
    offsets = _planes(at, across, halves, probes, params.forward_step, cutter.radius)
    values, counts = np.unique(np.round(tilts, 9), return_counts=True)
    tilt = float(values[np.argmax(counts)]) if len(values) else 0.0
    segs = segments(mesh, cutter, params, offsets, tilt)
    top = float(hi_box[2])
    tp = link(segs, link_policy(cutter, top + 5.0, top + 10.0, 5.0))
    program = [tool_info, Operation("estimate", path5.encode_toolpath(tp, feed, plunge), "Flood")]
    seconds = float(write_tarus(program, machine or TarusMachine()).cycle_time)
    length = float(sum(np.linalg.norm(np.diff(g.tips, axis=0), axis=1).sum() for g in segs))
    return Mesh5Estimate(seconds, len(offsets), length, math.degrees(tilt), probed, blocked)
