"""The posture at each CC point of a pass, chosen in its C-space for the Tarus motion time (seed 000 section
3.5.5.2, eq. 3.119-3.124).

The seed's ideal posture holds the cutter-holder point straight above the CC point (H = L (0, 0, 1), eq.
3.119-3.120: a vertical tool axis), and its local optimisation takes, point by point, the available posture
closest to that ideal in motion time (eq. 3.121-3.123, by a penalty method). Point by point, the choice can
jump between far-apart postures from one CC point to the next, and the machine pays for every jump. Here the
whole pass is chosen at once: a shortest path (dynamic programming) over the C-space grid along the pass,
whose cost is the sum of the Tarus motion times between neighbouring CC points plus `ideal_weight` times the
motion time from each posture to its ideal. The seed's point-by-point choice is one of the sequences the
shortest path considers, and it minimises the second term; so the shortest path's total motion time is never
above it (the exact optimum over the grid, where the seed's penalty method gives a local one).

States: the available (lambda, omega) of each CC point (S2 <= S1), lifted by S2 (the least gouge-free lift:
the least material left), whose joints the Tarus inverse kinematics can reach within the machine's limits
(`TarusMachine.inverse`; postures it refuses are dropped). Motion time between two states: eq. 3.123 on the
joints (`TarusMachine.speeds`), A taken the short way round; where a state's axis is vertical A is free
(the machine holds it) and counts as not moving.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import List, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine.rotary import solve_path
from tmm_workbench.core.machine.tarus import JointLimitError, TarusMachine
from tmm_workbench.core.strategies.mesh5.cspace import CSpace
from tmm_workbench.core.strategies.mesh5.posture import tool_rotation, world_placement
from tmm_workbench.core.tools.cutter import Cutter

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class PassPostures:
    """The chosen posture of each of n CC points: grid indices (n, 2) (lambda, omega), the C-space set
    (lam, omg rad, delta mm, each (n,)), the CL tips and axes in world coordinates (n, 3) and the joints
    (n, 5) from the Tarus inverse kinematics (A in -pi..pi, not unwrapped: rotary.solve_path plans it)."""
    index: np.ndarray
    lam: np.ndarray
    omg: np.ndarray
    delta: np.ndarray
    tips: np.ndarray
    axes: np.ndarray
    joints: np.ndarray


@dataclass(frozen=True)
class _States:
    flat: np.ndarray      # (k,) flat grid index
    delta: np.ndarray     # (k,)
    tips: np.ndarray      # (k, 3)
    axes: np.ndarray      # (k, 3)
    joints: np.ndarray    # (k, 5)


def _states(cs: CSpace, k: int, cutter: Cutter, point: np.ndarray, frame: np.ndarray,
            machine: TarusMachine) -> _States:
    """The reachable available postures of CC point k, each at its lift S2."""
    flat = np.flatnonzero(cs.available[k].ravel())
    lam, omg = (g.ravel()[flat] for g in cs.grid.mesh())
    delta = cs.lift[k].ravel()[flat]
    n = len(flat)
    tips, axes = world_placement(cutter, np.repeat(point[None], n, 0), np.repeat(frame[None], n, 0), lam, omg,
                                 delta)
    keep, joints = [], []
    for i in range(n):
        try:
            joints.append(machine.inverse(tips[i], axes[i]).as_array())
        except JointLimitError:
            continue
        keep.append(i)
    keep = np.asarray(keep, dtype=np.int64)
    return _States(flat[keep], delta[keep], tips[keep], axes[keep], np.asarray(joints).reshape(-1, 5))


def pair_times(machine: TarusMachine, j0: np.ndarray, j1: np.ndarray) -> np.ndarray:
    """(p, q) motion times (s) between every joint row of j0 (p, 5) and of j1 (q, 5): eq. 3.123 as
    TarusMachine.motion_time, A the short way round and free where either axis is vertical."""
    d = np.abs(j1[None, :, :] - j0[:, None, :])
    da = np.mod(d[:, :, 3], TWO_PI)
    da = np.minimum(da, TWO_PI - da)
    vertical = (np.abs(np.sin(j0[:, 4]))[:, None] <= machine.singular_tol) | \
               (np.abs(np.sin(j1[:, 4]))[None, :] <= machine.singular_tol)
    d[:, :, 3] = np.where(vertical, 0.0, da)
    return (d / machine.speeds.as_array()).max(axis=2)


def ideal_joints(machine: TarusMachine, points: np.ndarray) -> np.ndarray:
    """(n, 5) joints of the seed's ideal postures: the holder point L above the CC point, the axis vertical
    (eq. 3.119-3.120)."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    return np.array([machine.inverse(p, (0.0, 0.0, 1.0)).as_array() for p in pts]).reshape(-1, 5)


def _pick(cs: CSpace, cutter: Cutter, points: np.ndarray, frames: np.ndarray, states: List[_States],
          chosen: List[int]) -> PassPostures:
    flat = np.array([s.flat[c] for s, c in zip(states, chosen)], dtype=np.int64)
    il, io = np.unravel_index(flat, cs.grid.shape)
    return PassPostures(np.stack([il, io], 1), cs.grid.lambdas[il], cs.grid.omegas[io],
                        np.array([s.delta[c] for s, c in zip(states, chosen)]),
                        np.array([s.tips[c] for s, c in zip(states, chosen)]).reshape(-1, 3),
                        np.array([s.axes[c] for s, c in zip(states, chosen)]).reshape(-1, 3),
                        np.array([s.joints[c] for s, c in zip(states, chosen)]).reshape(-1, 5))


def _all_states(cs: CSpace, cutter: Cutter, points: np.ndarray, frames: np.ndarray,
                machine: TarusMachine) -> List[_States]:
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    if len(pts) != len(cs.lift) or len(frm) != len(pts):
        raise TmmError(f"{len(pts)} CC points and {len(frm)} frames for a C-space of {len(cs.lift)} points")
    states = [_states(cs, k, cutter, pts[k], frm[k], machine) for k in range(len(pts))]
    bad = [k for k, s in enumerate(states) if len(s.flat) == 0]
    if bad:
        where = ", ".join(f"#{k} ({pts[k][0]:.3f}, {pts[k][1]:.3f}, {pts[k][2]:.3f})" for k in bad[:5])
        raise TmmError(f"{len(bad)} of {len(pts)} CC points have no available posture within the limits of the "
                       f"{machine.name} (C {math.degrees(machine.c_limits[0]):g}..{math.degrees(machine.c_limits[1]):g}"
                       f" deg): {where}{' ...' if len(bad) > 5 else ''}; leave them to clean-up")
    return states


def nearest_ideal(cs: CSpace, cutter: Cutter, points: np.ndarray, frames: np.ndarray,
                  machine: TarusMachine) -> PassPostures:
    """The seed's local optimum: at each CC point, the available posture closest in motion time to the ideal
    (eq. 3.123-3.124), exactly over the grid."""
    states = _all_states(cs, cutter, points, frames, machine)
    ideal = ideal_joints(machine, points)
    chosen = [int(np.argmin(pair_times(machine, ideal[k:k + 1], s.joints)[0])) for k, s in enumerate(states)]
    return _pick(cs, cutter, points, frames, states, chosen)


def _turns(cs: CSpace, s0: _States, s1: _States) -> np.ndarray:
    """(p, q) rad between the tool axes of two CC points' states, each in its own LCS (how far the posture
    turns against the surface from one CC point to the next)."""
    lam, omg = (g.ravel() for g in cs.grid.mesh())
    a0, a1 = (tool_rotation(lam[s.flat], omg[s.flat])[:, 2, :] for s in (s0, s1))
    return np.arccos(np.clip(a0 @ a1.T, -1.0, 1.0))


def smooth_postures(cs: CSpace, cutter: Cutter, points: np.ndarray, frames: np.ndarray,
                    machine: Optional[TarusMachine] = None, ideal_weight: float = 0.1,
                    hold: Optional[np.ndarray] = None) -> PassPostures:
    """The postures of a pass (CC points in feed order) with the least sum of Tarus motion times between
    neighbours plus `ideal_weight` x the motion times to the ideal postures (module doc). `hold` (n,) s/rad:
    plus, into each CC point, that weight x the angle its posture turns against the surface from the one
    before (in their LCSs): where the strip's edge is formed by the tool a radius along the pass, a posture
    that turns there leaves what the CC point's own swept profile covered (stepover: a side run to the
    mesh's edge). TmmError naming the CC points that have no reachable available posture."""
    if not (isinstance(ideal_weight, (int, float)) and math.isfinite(ideal_weight) and ideal_weight >= 0):
        raise TmmError(f"ideal weight must be a finite number >= 0, got {ideal_weight!r}")
    machine = TarusMachine() if machine is None else machine
    states = _all_states(cs, cutter, points, frames, machine)
    ideal = ideal_joints(machine, points)
    cost = ideal_weight * pair_times(machine, ideal[:1], states[0].joints)[0]
    back: List[np.ndarray] = []
    for k in range(1, len(states)):
        step = pair_times(machine, states[k - 1].joints, states[k].joints) + cost[:, None]
        if hold is not None and hold[k] > 0:
            step = step + hold[k] * _turns(cs, states[k - 1], states[k])
        arg = np.argmin(step, axis=0)
        back.append(arg)
        cost = step[arg, np.arange(step.shape[1])] + \
            ideal_weight * pair_times(machine, ideal[k:k + 1], states[k].joints)[0]
    chosen = [int(np.argmin(cost))]
    for arg in reversed(back):
        chosen.append(int(arg[chosen[-1]]))
    return _pick(cs, cutter, points, frames, states, chosen[::-1])


def pass_motion_time(machine: TarusMachine, postures: PassPostures) -> float:
    """Seconds the Tarus needs for the pass's joint moves (eq. 3.123 summed), with the joints planned as the
    post plans them (rotary.solve_path: A unwrapped and held through vertical axes)."""
    joints = solve_path(machine, postures.tips, postures.axes)
    return machine.cycle_time(joints)
