"""Rotary planning for a head-head 5-axis machine (the Tarus: A about Z carrying the tilt C), shared by every
5-axis post: which A branch each cut gets, and how a joint move is subdivided so that a control that
interpolates the joints linearly keeps the tip on its straight line.

Cuts and unwinding. A tool path is split into blocks at the rapid moves that change the tool orientation
(the transit above the part, the tool retracted along its axis before it): everything between two such
rapids - the approach down the axis, the cut, the retract - is one block, and A moves continuously through
it (unwrapped move by move, held through vertical axes). Each block gets the whole turns k (A + 2 pi k) and,
where the C limits allow negative tilts, the branch (A + pi, -C) that keep all of its A inside the A limits
with the least A travel from the block before; unwinding therefore happens only at a transit, never inside
a cut. A block whose A span is wider than the limits cannot be cut without unwinding: RotaryPlanError names
it (its first and last move) and nothing is emitted.

Subdivision. Between two joint positions a control without tool-centre-point mode moves X Y Z A C linearly;
the tip then leaves the straight line between the two programmed tips and the axis its interpolation (slerp).
`subdivide` splits a move into 2, 4, 8, ... equal pieces (tip linear, axis slerp, joints by continuous
unwrapping) until, at every piece, the tip stays within `tip_tol` of where the straight line has it at the
same fraction and the axis within `axis_tol` of its slerp, checked at 8 points per piece.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.machine.tarus import _LIMIT_SLACK, JointLimitError, Joints, TarusMachine

TWO_PI = 2.0 * math.pi
_SAME_AXIS = 1e-12   # 1 - cos(angle) under which two axes are the same orientation
_CHECKS = 8          # interior points per piece checked by `subdivide`
_MAX_PIECES = 4096


class RotaryPlanError(TmmError):
    """A block (a cut with its approach and retract) cannot keep A within the limits without unwinding."""

    def __init__(self, message: str, first: int, last: int) -> None:
        super().__init__(message)
        self.first, self.last = first, last


@dataclass(frozen=True)
class Move:
    """One motion for the planner: tip (mm; NaN where not known yet), unit axis, rapid or not."""
    tip: tuple[float, float, float]
    axis: tuple[float, float, float]
    rapid: bool


def blocks(moves: list[Move]) -> list[tuple[int, int]]:
    """[first, last] move index pairs of the blocks (see the module doc)."""
    out: list[tuple[int, int]] = []
    start = 0
    for i in range(1, len(moves)):
        a, b = np.asarray(moves[i - 1].axis), np.asarray(moves[i].axis)
        if moves[i].rapid and 1.0 - float(a @ b) > _SAME_AXIS:
            out.append((start, i - 1))
            start = i
    if moves:
        out.append((start, len(moves) - 1))
    return out


def _angles(axis: np.ndarray, singular_tol: float) -> tuple[Optional[float], float]:
    """(azimuth or None for a vertical axis, tilt) of a unit axis."""
    h = math.hypot(axis[0], axis[1])
    tilt = math.atan2(h, axis[2])
    return (None if h <= singular_tol else math.atan2(axis[1], axis[0])), tilt


def _c_ok(machine: TarusMachine, c: float) -> bool:
    lo, hi = machine.c_limits
    return lo - _LIMIT_SLACK <= c <= hi + _LIMIT_SLACK


def _block_joints(machine: TarusMachine, moves: list[Move], first: int, last: int,
                  previous: Joints) -> np.ndarray:
    """Joints of one block before its whole turns are chosen: each move's branch the one reached from the
    move before in the least joint time (so a sweep through the vertical may change branch where C = 0),
    A continuous; the first move next to `previous`. JointLimitError for a move whose C is out of limits."""
    out = np.empty((last - first + 1, 5))
    prev = previous
    for k, i in enumerate(range(first, last + 1)):
        cands = [j for j in machine.candidates(moves[i].tip, moves[i].axis, prev) if _c_ok(machine, j.c)]
        if not cands:
            c = machine.candidates(moves[i].tip, moves[i].axis, prev)[0].c
            raise JointLimitError(f"move {i}: {TarusMachine._limit_message('C', c, machine.c_limits)} "
                                  f"({machine.name})", "C", c, machine.c_limits, i)
        best = min(cands, key=lambda j: machine.motion_time(prev, j))
        out[k] = best.as_array()
        prev = best
    return out


def plan(machine: TarusMachine, moves: list[Move], a_start: Optional[float] = None) -> np.ndarray:
    """(n, 5) joints x, y, z (pivot point), a, c for `moves`, A planned per block (module doc): the whole
    turns of all blocks chosen together (dynamic programming over the few that fit each block) for the least
    A travel in all. JointLimitError for a move out of the X/Y/Z or C limits, RotaryPlanError for a block
    A cannot follow."""
    n = len(moves)
    joints = np.full((n, 5), np.nan)
    a_prev = machine.a_home if a_start is None else a_start
    spans = blocks(moves)
    if not spans:
        return joints
    parts: list[np.ndarray] = []
    previous = Joints(math.nan, math.nan, math.nan, a_prev, 0.0)
    for first, last in spans:  # each block continued from the one before, before any whole turns
        block = _block_joints(machine, moves, first, last, previous)
        parts.append(block)
        previous = Joints.from_array(block[-1])
    options: list[list[int]] = []
    for (first, last), block in zip(spans, parts):
        turns = _turns(machine, block[:, 3])
        if not turns:
            lo, hi = machine.a_limits  # type: ignore[misc]
            a = block[:, 3]
            raise RotaryPlanError(
                f"moves {first}..{last} (a cut with its approach and retract): A turns through "
                f"{math.degrees(float(a.max() - a.min())):.6g} deg, more than its limits "
                f"[{math.degrees(lo):.6g}, {math.degrees(hi):.6g}] deg hold without unwinding inside the cut; "
                f"split the pass or widen the limits ({machine.name})", first, last)
        options.append(turns)
    # cost[k] of the best turns so far ending with turn k of the current block; back pointers per block
    cost = {k: abs(parts[0][0, 3] + TWO_PI * k - a_prev) for k in options[0]}
    back: list[dict[int, int]] = [{}]
    for b in range(1, len(parts)):
        end, start = parts[b - 1][-1, 3], parts[b][0, 3]
        step: dict[int, float] = {}
        ptr: dict[int, int] = {}
        for k in options[b]:
            best_k = min(cost, key=lambda kp: cost[kp] + abs(start + TWO_PI * k - end - TWO_PI * kp))
            step[k] = cost[best_k] + abs(start + TWO_PI * k - end - TWO_PI * best_k)
            ptr[k] = best_k
        cost, back = step, back + [ptr]
    k = min(cost, key=cost.get)
    chosen = [0] * len(parts)
    for b in range(len(parts) - 1, -1, -1):
        chosen[b] = k
        if b:
            k = back[b][k]
    for (first, last), block, k in zip(spans, parts, chosen):
        block[:, 3] += TWO_PI * k
        for row, i in zip(block, range(first, last + 1)):
            _check_linear(machine, row, i)
        joints[first:last + 1] = block
    return joints


def _turns(machine: TarusMachine, a: np.ndarray) -> list[int]:
    """The whole turns k that keep a + 2 pi k inside the A limits (all of them; [0] for a continuous A: the
    block already continues from the one before)."""
    if machine.a_limits is None:
        return [0]
    lo, hi = machine.a_limits
    k_lo = math.ceil((lo - _LIMIT_SLACK - float(a.min())) / TWO_PI)
    k_hi = math.floor((hi + _LIMIT_SLACK - float(a.max())) / TWO_PI)
    return list(range(k_lo, k_hi + 1))


def _check_linear(machine: TarusMachine, j: np.ndarray, index: int) -> None:
    for joint, value, lim in zip("XYZ", j[:3], (machine.x_limits, machine.y_limits, machine.z_limits)):
        if lim is None or math.isnan(value):
            continue
        if not (lim[0] - _LIMIT_SLACK <= value <= lim[1] + _LIMIT_SLACK):
            raise JointLimitError(f"move {index}: {TarusMachine._limit_message(joint, float(value), lim)} "
                                  f"({machine.name})", joint, float(value), lim, index)


def deviation(machine: TarusMachine, j0: np.ndarray, j1: np.ndarray, checks: int = _CHECKS
              ) -> tuple[float, float]:
    """(tip distance in mm, axis angle in rad) between the linear joint move j0 -> j1 and the ideal move
    (tip on the straight line, axis by slerp) at the same fraction, the largest at `checks` interior
    points. The same fraction, not the nearest point of the line: a tip that runs ahead along its line
    while the axis lags is a pose the positions never checked (it can cut in)."""
    s = np.arange(1, checks + 1) / (checks + 1)
    js = j0[None, :] * (1 - s[:, None]) + j1[None, :] * s[:, None]
    tips, axes = machine.forward_path(js)
    t0, u0 = machine.forward(j0)
    t1, u1 = machine.forward(j1)
    ideal = t0[None, :] * (1 - s[:, None]) + t1[None, :] * s[:, None]
    tip_dev = float(np.linalg.norm(tips - ideal, axis=1).max())
    ref = slerp(u0, u1, s)
    axis_dev = float(np.arccos(np.clip((axes * ref).sum(1), -1.0, 1.0)).max())
    return tip_dev, axis_dev


def subdivide(machine: TarusMachine, j0: np.ndarray, j1: np.ndarray, tip_tol: float, axis_tol: float
              ) -> np.ndarray:
    """(m, 5) joints of the pieces' ends (the last one j1) for the linear joint move j0 -> j1, m a power of
    two (module doc). TmmError when even 4096 pieces do not stay within the tolerances."""
    t0, u0 = machine.forward(j0)
    t1, u1 = machine.forward(j1)
    pieces = 1
    while pieces <= _MAX_PIECES:
        s = np.arange(1, pieces + 1) / pieces
        tips = t0[None, :] * (1 - s[:, None]) + t1[None, :] * s[:, None]
        axes = slerp(u0, u1, s)
        ends = np.empty((pieces, 5))
        prev = j0
        ok = True
        for k in range(pieces):
            if k == pieces - 1:
                end = j1
            else:
                end = _follow(machine, tips[k], axes[k], prev)
            ends[k] = end
            if ok:
                tip_dev, axis_dev = deviation(machine, prev, end)
                ok = tip_dev <= tip_tol and axis_dev <= axis_tol
            prev = end
        if ok:
            return ends
        pieces *= 2
    raise TmmError(f"a joint move cannot follow its straight line within {tip_tol:g} mm and "
                   f"{math.degrees(axis_tol):g} deg even in {_MAX_PIECES} pieces (a move through the vertical?)")


def _follow(machine: TarusMachine, tip: np.ndarray, axis: np.ndarray, prev: np.ndarray) -> np.ndarray:
    """Joints for (tip, axis) continuing from `prev`: the same C branch, A next to prev's A."""
    az, tilt = _angles(axis, machine.singular_tol)
    c = math.copysign(tilt, prev[4]) if prev[4] != 0 else tilt
    if az is None:
        a = float(prev[3])
    else:
        if c < 0:
            az += math.pi
        a = az + TWO_PI * round((prev[3] - az) / TWO_PI)
    pivot = tip + machine.length * axis
    return np.array([pivot[0], pivot[1], pivot[2], a, c])
