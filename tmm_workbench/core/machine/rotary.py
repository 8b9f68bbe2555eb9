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

The vertical (C = 0, the singularity of a head-head machine with C >= 0). A tool axis passing through the
vertical is a normal event on a free-form face (over a bump, a dip or a saddle point the tilt goes to zero):
its azimuth, which A follows, swings by about 180 degrees there, the faster the closer the axis passes. Axes
within `pole_tol` of the vertical are taken as vertical (C = 0; the axis moves by at most `pole_tol`), and a
cutting move whose axis passes within `pole_tol` of it is routed through it: down to C = 0 at the A it
had, A turned there (where it moves neither tip nor axis), then on at its new A. A is free at such a pole
pass, so the whole turns are chosen per stretch between pole passes, not per block: the planner picks the
way round that keeps the cut inside the A limits (an axis circling the vertical needs no unwinding). Axes
passing farther than `pole_tol` from the vertical are followed by subdivision (A swings fast but
continuously beside the pole). Machines with negative tilts stay on one branch through the vertical
instead (A still, C changes sign): nothing is snapped there.

Subdivision. Between two joint positions a control without tool-centre-point mode moves X Y Z A C linearly;
the tip then leaves the straight line between the two programmed tips and the axis its interpolation (slerp).
`subdivide` halves a move (tip linear, axis slerp, joints by continuous unwrapping), and each half again
where it is still out, until at every piece the tip stays within `tip_tol` of where the straight line has it
at the same fraction and the axis within `axis_tol` of its slerp, checked at 8 points per piece; only the
pieces beside the pole need the finest halving.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.machine.tarus import _LIMIT_SLACK, JointLimitError, Joints, TarusMachine, unit_axis

TWO_PI = 2.0 * math.pi
_SAME_AXIS = 1e-12   # 1 - cos(angle) under which two axes are the same orientation
_CHECKS = 8          # interior points per piece checked by `subdivide`
_MAX_DEPTH = 16      # halvings of one move (65536 pieces where all of it needs the finest)
# axes this close to the vertical are vertical: half the post's default axis tolerance (0.05 deg), the other
# half left for the pieces on the way to and from the pole
POLE_TOL = math.radians(0.025)
_CENTRE_WEIGHT = 1e-3  # rad of A travel per rad of A off the middle of its limits: breaks ties only


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


def snaps_to_pole(machine: TarusMachine, pole_tol: float) -> bool:
    """Whether near-vertical axes are taken as vertical: only for a machine without negative tilts (with
    them a sweep through the vertical keeps its branch and A)."""
    return pole_tol > 0 and machine.c_limits[0] >= 0


def pole_pass(u0: np.ndarray, u1: np.ndarray) -> tuple[float, float]:
    """(angle, fraction): how close the slerp from unit u0 to unit u1 comes to the vertical +Z, and at
    which fraction of the move (the great circle's nearest point to +Z when it lies on the arc, else the
    nearer end)."""
    u0, u1 = np.asarray(u0, dtype=float), np.asarray(u1, dtype=float)
    ends = [(math.atan2(math.hypot(u[0], u[1]), u[2]), s) for u, s in ((u0, 0.0), (u1, 1.0))]
    best = min(ends)
    n = np.cross(u0, u1)
    sin_th = float(np.linalg.norm(n))
    if sin_th < 1e-12:
        return best
    n /= sin_th
    p = np.array([0.0, 0.0, 1.0]) - n[2] * n  # +Z projected on the arc's plane
    norm = float(np.linalg.norm(p))
    if norm < 1e-15:
        return best
    p /= norm
    th = math.atan2(sin_th, float(u0 @ u1))
    a0 = math.atan2(float(np.cross(u0, p) @ n), float(u0 @ p))  # signed angle u0 -> p about n
    if 0.0 < a0 < th:
        d = math.atan2(abs(n[2]), norm)  # the angle between +Z and its projection
        if d < best[0]:
            return d, a0 / th
    return best


def _snap(machine: TarusMachine, tip: tuple[float, float, float], prev: Joints) -> Joints:
    """The tool at `tip` with its axis vertical: C = 0, A held from `prev`, the pivot right above the tip."""
    return Joints(tip[0], tip[1], tip[2] + machine.length, prev.a, 0.0)


def _block_joints(machine: TarusMachine, moves: list[Move], first: int, last: int, previous: Joints,
                  pole_tol: float) -> tuple[np.ndarray, list[int]]:
    """Joints of one block before its whole turns are chosen: each move's branch the one reached from the
    move before in the least joint time (so a sweep through the vertical may change branch where C = 0),
    A continuous; the first move next to `previous`. Axes within `pole_tol` of the vertical snapped to it.
    Also the moves (global indices) after which A is free: a cutting move whose axis passes within
    `pole_tol` of the vertical. JointLimitError for a move whose C is out of limits."""
    out = np.empty((last - first + 1, 5))
    free: list[int] = []
    snap = snaps_to_pole(machine, pole_tol)
    prev = previous
    for k, i in enumerate(range(first, last + 1)):
        cands = [j for j in machine.candidates(moves[i].tip, moves[i].axis, prev) if _c_ok(machine, j.c)]
        if not cands:
            c = machine.candidates(moves[i].tip, moves[i].axis, prev)[0].c
            raise JointLimitError(f"move {i}: {TarusMachine._limit_message('C', c, machine.c_limits)} "
                                  f"({machine.name})", "C", c, machine.c_limits, i)
        best = min(cands, key=lambda j: machine.motion_time(prev, j))
        if snap and 0.0 < abs(best.c) <= pole_tol:
            best = _snap(machine, moves[i].tip, prev)
        out[k] = best.as_array()
        if snap and k > 0 and not moves[i].rapid and crosses_pole(machine, out[k - 1], out[k], pole_tol):
            free.append(i)
        prev = best
    return out, free


def crosses_pole(machine: TarusMachine, j0: np.ndarray, j1: np.ndarray, pole_tol: float) -> bool:
    """The move j0 -> j1 (its ideal: the axis by slerp) passes within `pole_tol` of the vertical."""
    return pole_pass(machine.forward(j0)[1], machine.forward(j1)[1])[0] <= pole_tol


def plan(machine: TarusMachine, moves: list[Move], a_start: Optional[float] = None,
         pole_tol: float = POLE_TOL) -> np.ndarray:
    """(n, 5) joints x, y, z (pivot point), a, c for `moves`, A planned per block (module doc): the whole
    turns of every stretch (a block, or its part between pole passes) chosen together (dynamic programming
    over the few that fit each) for the least A travel in all. JointLimitError for a move out of the X/Y/Z
    or C limits, RotaryPlanError for a stretch A cannot follow."""
    n = len(moves)
    joints = np.full((n, 5), np.nan)
    a_prev = machine.a_home if a_start is None else a_start
    spans = blocks(moves)
    if not spans:
        return joints
    parts: list[np.ndarray] = []
    stretches: list[tuple[int, int, int, int]] = []  # first, last move of a stretch, and of its block
    previous = Joints(math.nan, math.nan, math.nan, a_prev, 0.0)
    for first, last in spans:  # each block continued from the one before, before any whole turns
        block, free = _block_joints(machine, moves, first, last, previous, pole_tol)
        for lo, hi in zip([first] + free, [f - 1 for f in free] + [last]):
            parts.append(block[lo - first:hi - first + 1])
            stretches.append((lo, hi, first, last))
        previous = Joints.from_array(block[-1])
    spans = [(lo, hi) for lo, hi, _, _ in stretches]
    options: list[list[int]] = []
    for (lo, hi, first, last), part in zip(stretches, parts):
        turns = _turns(machine, part[:, 3])
        if machine.a_limits is None and lo != first:  # a continuous A may turn either way at the pole too
            turns = [-1, 0, 1]
        if not turns:
            a_lo, a_hi = machine.a_limits  # type: ignore[misc]
            a = part[:, 3]
            where = "" if (lo, hi) == (first, last) else f", moves {lo}..{hi} between passes through the vertical"
            raise RotaryPlanError(
                f"moves {first}..{last} (a cut with its approach and retract{where}): A turns through "
                f"{math.degrees(float(a.max() - a.min())):.6g} deg, more than its limits "
                f"[{math.degrees(a_lo):.6g}, {math.degrees(a_hi):.6g}] deg hold without unwinding inside the "
                f"cut; split the pass or widen the limits ({machine.name})", first, last)
        options.append(turns)
    # cost[k] of the best turns so far ending with turn k of the current block; back pointers per block
    # ties (a half turn at the pole either way round) go to the stretch nearer the middle of the A limits,
    # so turns through the vertical alternate instead of winding A up
    centre = a_prev if machine.a_limits is None else 0.5 * sum(machine.a_limits)

    def off_centre(b: int, k: int) -> float:
        return _CENTRE_WEIGHT * abs(float(parts[b][:, 3].mean()) + TWO_PI * k - centre)

    cost = {k: abs(parts[0][0, 3] + TWO_PI * k - a_prev) + off_centre(0, k) for k in options[0]}
    back: list[dict[int, int]] = [{}]
    for b in range(1, len(parts)):
        end, start = parts[b - 1][-1, 3], parts[b][0, 3]
        step: dict[int, float] = {}
        ptr: dict[int, int] = {}
        for k in options[b]:
            best_k = min(cost, key=lambda kp: cost[kp] + abs(start + TWO_PI * k - end - TWO_PI * kp))
            step[k] = cost[best_k] + abs(start + TWO_PI * k - end - TWO_PI * best_k) + off_centre(b, k)
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


def solve_path(machine: TarusMachine, tips: np.ndarray, axes: np.ndarray, start: Optional[Joints] = None,
               rapid: Optional[list[bool]] = None) -> np.ndarray:
    """(n, 5) joints for a path of tips (n, 3) and axes (n, 3), planned as a post plans it (`plan`): A
    continuous through each cut (branch, unwrapping, held through vertical axes), the whole turns that keep each
    cut inside the A limits, unwinding only at rapids that turn the tool (`rapid`: per move; default none, the
    whole path one cut). JointLimitError names the first move (0-based index) out of the X/Y/Z/C limits;
    RotaryPlanError a cut A cannot follow."""
    tips = np.asarray(tips, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    if len(tips) != len(axes):
        raise TmmError(f"solve_path: {len(tips)} tips but {len(axes)} axes")
    flags = [False] * len(tips) if rapid is None else [bool(r) for r in rapid]
    moves = [Move(tuple(t), tuple(unit_axis(u)), r) for t, u, r in zip(tips, axes, flags)]
    return plan(machine, moves, start.a if start is not None else None)


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
    """(m, 5) joints of the pieces' ends (the last one j1) for the linear joint move j0 -> j1: halved where a
    piece is out of the tolerances (module doc), the pieces' ends on the ideal move (tip on its line, axis
    by slerp). TmmError when a piece is still out after _MAX_DEPTH halvings."""
    t0, u0 = machine.forward(j0)
    t1, u1 = machine.forward(j1)
    ends: list[np.ndarray] = []
    todo = [(0.0, 1.0, j0, j1, 0)]  # pieces still to check, the first one last (a stack)
    while todo:
        s0, s1, a, b, depth = todo.pop()
        tip_dev, axis_dev = deviation(machine, a, b)
        if tip_dev <= tip_tol and axis_dev <= axis_tol:
            ends.append(b)
            continue
        if depth == _MAX_DEPTH:
            raise TmmError(f"a joint move cannot follow its straight line within {tip_tol:g} mm and "
                           f"{math.degrees(axis_tol):g} deg even in pieces of 1/{2 ** _MAX_DEPTH} of it "
                           f"(tip off by {tip_dev:.3g} mm, axis by {math.degrees(axis_dev):.3g} deg)")
        s = 0.5 * (s0 + s1)
        mid = _follow(machine, t0 * (1 - s) + t1 * s, slerp(u0, u1, np.array([s]))[0], a, b)
        todo.append((s, s1, mid, b, depth + 1))
        todo.append((s0, s, a, mid, depth + 1))
    return np.array(ends).reshape(-1, 5)


def _follow(machine: TarusMachine, tip: np.ndarray, axis: np.ndarray, prev: np.ndarray,
            after: Optional[np.ndarray] = None) -> np.ndarray:
    """Joints for (tip, axis) between `prev` and `after` (default: continuing from `prev`): the same C
    branch, A next to the middle of their A (a piece's A lies between its ends', however fast it swings)."""
    az, tilt = _angles(axis, machine.singular_tol)
    c = math.copysign(tilt, prev[4]) if prev[4] != 0 else tilt
    ref = float(prev[3]) if after is None else 0.5 * float(prev[3] + after[3])
    if az is None:
        a = float(prev[3])
    else:
        if c < 0:
            az += math.pi
        a = az + TWO_PI * round((ref - az) / TWO_PI)
    pivot = tip + machine.length * axis
    return np.array([pivot[0], pivot[1], pivot[2], a, c])
