"""Kinematics of the 5-axis Tarus mill (TPI-2000, seed 000 sections 3.5.5.2 and 4.2), and a plain 3-axis mill.

Kinematic chain (TMM's definition; the seed only says "the tilt head (C-axis) is on the top of the rotation
head (A-axis)" and gives the joint speeds, see docs/tarus.md):

    work frame W --X,Y,Z (prismatic, along the work axes)--> pivot point P
                --A (revolute about the vertical +Z through P)--> rotation head
                --C (revolute about the head's tilt axis through P)--> tilt head, spindle, tool

* Frames. W is the work frame (G54 zero, axes parallel to the machine's X, Y, Z, +Z up, away from the table).
  X, Y, Z are the coordinates of the pivot point P in W. P is the point where the A axis (vertical) and the
  C axis (horizontal) cross; the spindle axis passes through P as well (no head offsets).
* A turns the rotation head about +Z, right-handed (counter-clockwise seen from above). At A = 0 the tilt
  axis is parallel to +Y.
* C tilts the spindle about the tilt axis, right-handed about the head's +Y: a positive C swings the spindle
  end of the tool towards +X of the head (for A = 0 the tip moves to -X of the pivot).
* The tool axis u (unit vector from the tip towards the spindle, as in `core.toolpath`) is
  u = Rz(A) Ry(C) e_z = (sin C cos A, sin C sin A, cos C): A is the azimuth of the axis, C its angle from
  the vertical. A = C = 0 is the vertical 3-axis orientation.
* Pivot length Lp: distance from P to the spindle gauge line (spindle nose) along the axis. Tool length Lt:
  gauge line to the tool tip. The tip is T = P - (Lp + Lt) u.

Inverse kinematics: P = T + (Lp + Lt) u, C = atan2(hypot(ux, uy), uz), A = atan2(uy, ux) unwrapped to the
2 pi multiple nearest the previous A (no 360 degree jumps). When negative tilts are allowed (C limits below
zero), (A + pi, -C) is a second branch; along a path the branch with the shorter motion time (eq. 3.123)
from the previous joints wins, which keeps the motion continuous. For a vertical axis (|sin C| below
`singular_tol`) A is undefined and is held at its previous value (A0 = `a_home` at the start).

Units: lengths in mm, angles in radians, speeds in mm/s and rad/s. Joint arrays are (n, 5): x, y, z, a, c.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError

Limits = Optional[tuple[float, float]]
JOINT_NAMES = ("X", "Y", "Z", "A", "C")
_LIMIT_SLACK = 1e-12  # rad / mm: values this close outside a limit are taken as on it


class JointLimitError(TmmError):
    """A move needs a joint value outside its limits. Attributes: index (move, or None for a single
    pose), joint ('X'|'Y'|'Z'|'A'|'C'), value and limits (mm or rad)."""

    def __init__(self, message: str, joint: str, value: float, limits: tuple[float, float],
                 index: Optional[int] = None) -> None:
        super().__init__(message)
        self.joint, self.value, self.limits, self.index = joint, value, limits, index


@dataclass(frozen=True)
class Joints:
    """One machine position: pivot point x, y, z (mm, work frame), A and C (rad)."""
    x: float
    y: float
    z: float
    a: float
    c: float

    def as_array(self) -> np.ndarray:
        return np.array([self.x, self.y, self.z, self.a, self.c], dtype=float)

    @classmethod
    def from_array(cls, v: Sequence[float]) -> "Joints":
        return cls(float(v[0]), float(v[1]), float(v[2]), float(v[3]), float(v[4]))


@dataclass(frozen=True)
class JointSpeeds:
    """Constant joint speeds (seed 000: uniform motion, no acceleration): mm/s and rad/s."""
    x: float = 170.0
    y: float = 180.0
    z: float = 240.0
    a: float = 0.5
    c: float = 0.3

    def as_array(self) -> np.ndarray:
        return np.array([self.x, self.y, self.z, self.a, self.c], dtype=float)


def _fmt(joint: str, v: float) -> str:
    return f"{math.degrees(v):.6g} deg" if joint in ("A", "C") else f"{v:.6g} mm"


def unit_axis(axis: Sequence[float]) -> np.ndarray:
    """`axis` as a float unit vector; TmmError for a zero, short or non-finite vector."""
    u = np.asarray(axis, dtype=float).reshape(-1)
    if u.shape != (3,) or not np.all(np.isfinite(u)):
        raise TmmError(f"tool axis must be 3 finite numbers, got {axis!r}")
    n = math.sqrt(float(u @ u))
    if n < 1e-9:
        raise TmmError(f"tool axis {tuple(u)} has no direction (length {n:g})")
    return u if abs(n - 1.0) < 4e-16 else u / n


def _wrap_near(a: float, ref: float) -> float:
    """a + 2 pi k nearest to ref."""
    return a + 2 * math.pi * round((ref - a) / (2 * math.pi))


@dataclass(frozen=True)
class TarusMachine:
    """Settings and kinematics of the Tarus head-head 5-axis mill (chain in the module docstring).

    pivot_length, tool_length: mm (pivot to gauge line, gauge line to tip). c_limits: tilt range (rad), the
    seed's C-space range 0..45 degrees by default; a_limits: (min, max) rad, +-360 degrees by default (the seed
    gives none; a head's cables usually allow about two turns), None for a continuous A;
    x/y/z_limits: travel of the pivot point in the work frame (None: unlimited). speeds: joint speeds.
    singular_tol: |sin C| under which the axis counts as vertical and A is held. a_home: A before the
    first move.
    """
    pivot_length: float = 150.0
    tool_length: float = 100.0
    c_limits: tuple[float, float] = (0.0, math.radians(45.0))
    a_limits: Limits = (-2.0 * math.pi, 2.0 * math.pi)
    x_limits: Limits = None
    y_limits: Limits = None
    z_limits: Limits = None
    speeds: JointSpeeds = field(default_factory=JointSpeeds)
    singular_tol: float = 1e-10
    a_home: float = 0.0
    name: str = "Tarus TPI-2000"

    def __post_init__(self) -> None:
        for label, v in (("pivot length", self.pivot_length), ("tool length", self.tool_length)):
            if not math.isfinite(v) or v < 0:
                raise TmmError(f"Tarus {label} must be a length >= 0 mm, got {v!r}")
        for joint, lim in zip(JOINT_NAMES, (self.x_limits, self.y_limits, self.z_limits, self.a_limits,
                                            self.c_limits)):
            if lim is not None and not (len(lim) == 2 and lim[0] <= lim[1]):
                raise TmmError(f"Tarus {joint} limits must be (min, max) with min <= max, got {lim!r}")
        if not (-math.pi <= self.c_limits[0] and self.c_limits[1] <= math.pi):
            raise TmmError("Tarus C limits must lie within -180..180 degrees")
        if any(not (s > 0) for s in self.speeds.as_array()):
            raise TmmError(f"Tarus joint speeds must be positive, got {self.speeds}")

    @property
    def length(self) -> float:
        """Tip to pivot point along the tool axis: pivot length + tool length (mm)."""
        return self.pivot_length + self.tool_length

    def limits(self) -> dict[str, Limits]:
        return {"X": self.x_limits, "Y": self.y_limits, "Z": self.z_limits, "A": self.a_limits,
                "C": self.c_limits}

    def tilt_within(self, axes: np.ndarray, slack: float = 1e-9) -> np.ndarray:
        """(...,) for unit axes (..., 3): whether the tilt C of one of the two joint solutions (C or -C, as
        `candidates` gives them) lies within the C limits, `slack` rad wider: a necessary condition of
        `inverse` (the other joints' limits are not checked)."""
        u = np.asarray(axes, dtype=float)
        c = np.arctan2(np.hypot(u[..., 0], u[..., 1]), u[..., 2])
        lo, hi = self.c_limits[0] - slack, self.c_limits[1] + slack
        return ((lo <= c) & (c <= hi)) | ((lo <= -c) & (-c <= hi))

    # --- kinematics --------------------------------------------------------------------------
    def forward(self, joints: Joints | Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        """(tip, axis) in the work frame for machine joints (Joints or x, y, z, a, c)."""
        j = joints.as_array() if isinstance(joints, Joints) else np.asarray(joints, dtype=float)
        sc, cc = math.sin(j[4]), math.cos(j[4])
        axis = np.array([sc * math.cos(j[3]), sc * math.sin(j[3]), cc])
        return j[:3] - self.length * axis, axis

    def forward_path(self, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Vectorised forward: (n, 5) joints -> tips (n, 3), axes (n, 3)."""
        j = np.asarray(joints, dtype=float).reshape(-1, 5)
        sc = np.sin(j[:, 4])
        axes = np.column_stack([sc * np.cos(j[:, 3]), sc * np.sin(j[:, 3]), np.cos(j[:, 4])])
        return j[:, :3] - self.length * axes, axes

    def candidates(self, tip: Sequence[float], axis: Sequence[float],
                   previous: Optional[Joints] = None) -> list[Joints]:
        """Every joint solution for (tip, axis), A unwrapped next to the previous A, limits not checked:
        (A, C >= 0) first, then (A + pi, -C)."""
        u = unit_axis(axis)
        t = np.asarray(tip, dtype=float).reshape(3)
        p = t + self.length * u
        a_prev = previous.a if previous is not None else self.a_home
        h = math.hypot(u[0], u[1])
        c = math.atan2(h, u[2])
        if h <= self.singular_tol:  # vertical axis (or straight up): A undefined, hold it
            pairs = [(a_prev, c), (a_prev, -c)] if c > 0 else [(a_prev, c)]
        else:
            a = math.atan2(u[1], u[0])
            pairs = [(_wrap_near(a, a_prev), c), (_wrap_near(a + math.pi, a_prev), -c)]
        return [Joints(float(p[0]), float(p[1]), float(p[2]), a_, c_) for a_, c_ in pairs]

    def _fit_limits(self, j: Joints, previous: Optional[Joints]) -> tuple[Optional[Joints], Optional[str]]:
        """j moved into the A limits by whole turns if needed (nearest the previous A); (None, reason)
        when some joint cannot be within its limits."""
        if self.a_limits is not None:
            lo, hi = self.a_limits
            a = j.a
            if not (lo - _LIMIT_SLACK <= a <= hi + _LIMIT_SLACK):
                ref = previous.a if previous is not None else self.a_home
                turns = [a + 2 * math.pi * k for k in range(math.floor((lo - a) / (2 * math.pi)),
                                                            math.ceil((hi - a) / (2 * math.pi)) + 1)]
                inside = [v for v in turns if lo - _LIMIT_SLACK <= v <= hi + _LIMIT_SLACK]
                if not inside:
                    return None, self._limit_message("A", a, self.a_limits)
                a = min(inside, key=lambda v: abs(v - ref))
                j = Joints(j.x, j.y, j.z, a, j.c)
        for joint, value in zip(JOINT_NAMES, (j.x, j.y, j.z, j.a, j.c)):
            lim = self.limits()[joint]  # NaN: a coordinate not known yet (e.g. a first 'G0 Z..'), unchecked
            if lim is None or math.isnan(value):
                continue
            if not (lim[0] - _LIMIT_SLACK <= value <= lim[1] + _LIMIT_SLACK):
                return None, self._limit_message(joint, value, lim)
        return j, None

    @staticmethod
    def _limit_message(joint: str, value: float, lim: tuple[float, float]) -> str:
        return f"joint {joint} = {_fmt(joint, value)} is outside its limits [{_fmt(joint, lim[0])}, " \
               f"{_fmt(joint, lim[1])}]"

    def inverse(self, tip: Sequence[float], axis: Sequence[float],
                previous: Optional[Joints] = None, index: Optional[int] = None) -> Joints:
        """Joints that put the tool tip at `tip` with tool axis `axis` (work frame, unit vector tip ->
        spindle). With `previous`, the reachable branch nearest in motion time and A next to previous.a.
        JointLimitError (a TmmError) when no solution is within the limits; `index` names the move."""
        best: Optional[Joints] = None
        first_error: Optional[tuple[str, str, float, tuple[float, float]]] = None
        for cand in self.candidates(tip, axis, previous):
            fitted, reason = self._fit_limits(cand, previous)
            if fitted is None:
                if first_error is None:
                    joint = reason.split()[1]
                    value = {"X": cand.x, "Y": cand.y, "Z": cand.z, "A": cand.a, "C": cand.c}[joint]
                    first_error = (reason, joint, value, self.limits()[joint] or (0.0, 0.0))
                continue
            if best is None:
                best = fitted
                if previous is None:
                    break
            elif self.motion_time(previous, fitted) < self.motion_time(previous, best) - 1e-12:
                best = fitted
        if best is None:
            assert first_error is not None
            reason, joint, value, lim = first_error
            where = f"move {index}: " if index is not None else ""
            t = np.asarray(tip, dtype=float).reshape(3)
            u = unit_axis(axis)
            raise JointLimitError(
                f"{where}{reason} (tip {t[0]:.4f}, {t[1]:.4f}, {t[2]:.4f} mm, axis {u[0]:.6f}, {u[1]:.6f}, "
                f"{u[2]:.6f}; {self.name})", joint, value, lim, index)
        return best

    # --- time ----------------------------------------------------------------------------------
    def motion_time(self, j0: Joints | Sequence[float], j1: Joints | Sequence[float]) -> float:
        """Seconds from j0 to j1 with all joints moving at once at their constant speeds (seed 000 eq.
        3.121-3.123): max(|dx|/vx, |dy|/vy, |dz|/vz, |dC|/wC, |dA|/wA). The seed's cutter holder (CH)
        point is the pivot point here, whose coordinates are the X, Y, Z joints. Coordinates not known
        (NaN, e.g. before the first full position) are left out."""
        a = j0.as_array() if isinstance(j0, Joints) else np.asarray(j0, dtype=float)
        b = j1.as_array() if isinstance(j1, Joints) else np.asarray(j1, dtype=float)
        t = np.abs(b - a) / self.speeds.as_array()
        return float(np.max(t[~np.isnan(t)], initial=0.0))

    def segment_times(self, joints: np.ndarray, tips: Optional[np.ndarray] = None,
                      feeds: Optional[Sequence[Optional[float]]] = None) -> np.ndarray:
        """(n-1,) seconds per move: joint motion time, and for moves with a feed (mm/s, None or 0 for a
        rapid) at least the tip distance / feed."""
        j = np.asarray(joints, dtype=float).reshape(-1, 5)
        if len(j) < 2:
            return np.zeros(0)
        t = np.max(np.abs(np.diff(j, axis=0)) / self.speeds.as_array(), axis=1)
        if feeds is not None:
            if tips is None:
                tips = self.forward_path(j)[0]
            d = np.linalg.norm(np.diff(np.asarray(tips, dtype=float).reshape(-1, 3), axis=0), axis=1)
            f = np.array([(v if v else np.inf) for v in list(feeds)[1:]], dtype=float)
            t = np.maximum(t, d / f)
        return t

    def cycle_time(self, joints: np.ndarray, tips: Optional[np.ndarray] = None,
                   feeds: Optional[Sequence[Optional[float]]] = None) -> float:
        """Estimated seconds for a path of joints (n, 5): the sum of `segment_times`. feeds[i] is the feed
        of the move ending at point i (mm/s; None or 0: rapid, joint speeds only)."""
        return float(self.segment_times(joints, tips, feeds).sum())


@dataclass(frozen=True)
class ThreeAxisMachine:
    """A plain 3-axis mill: the joints are the tip (tool length compensated by the control); A = C = 0.
    Only the vertical tool axis is reachable."""
    speeds: JointSpeeds = field(default_factory=lambda: JointSpeeds(170.0, 180.0, 240.0, math.inf, math.inf))
    axis_tol: float = 1e-9
    x_limits: Limits = None
    y_limits: Limits = None
    z_limits: Limits = None
    name: str = "3-axis mill"
    length: float = 0.0

    def forward(self, joints: Joints | Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
        j = joints.as_array() if isinstance(joints, Joints) else np.asarray(joints, dtype=float)
        return j[:3].copy(), np.array([0.0, 0.0, 1.0])

    def inverse(self, tip: Sequence[float], axis: Sequence[float] = (0.0, 0.0, 1.0),
                previous: Optional[Joints] = None, index: Optional[int] = None) -> Joints:
        u = unit_axis(axis)
        where = f"move {index}: " if index is not None else ""
        if abs(u[0]) > self.axis_tol or abs(u[1]) > self.axis_tol or u[2] <= 0:
            raise TmmError(f"{where}a 3-axis machine cannot tilt the tool (axis {u[0]:.6f}, {u[1]:.6f}, "
                           f"{u[2]:.6f})")
        t = np.asarray(tip, dtype=float).reshape(3)
        for joint, value, lim in zip("XYZ", t, (self.x_limits, self.y_limits, self.z_limits)):
            if lim is not None and not (lim[0] - _LIMIT_SLACK <= value <= lim[1] + _LIMIT_SLACK):
                raise JointLimitError(f"{where}{TarusMachine._limit_message(joint, float(value), lim)}",
                                      joint, float(value), lim, index)
        return Joints(float(t[0]), float(t[1]), float(t[2]), 0.0, 0.0)

    def solve_path(self, tips: np.ndarray, axes: np.ndarray, start: Optional[Joints] = None) -> np.ndarray:
        tips = np.asarray(tips, dtype=float).reshape(-1, 3)
        axes = np.asarray(axes, dtype=float).reshape(-1, 3)
        return np.array([self.inverse(t, u, index=i).as_array() for i, (t, u) in enumerate(zip(tips, axes))]
                        ).reshape(-1, 5)

    def motion_time(self, j0: Joints | Sequence[float], j1: Joints | Sequence[float]) -> float:
        a = j0.as_array() if isinstance(j0, Joints) else np.asarray(j0, dtype=float)
        b = j1.as_array() if isinstance(j1, Joints) else np.asarray(j1, dtype=float)
        return float(np.max(np.abs(b - a)[:3] / self.speeds.as_array()[:3]))

    def cycle_time(self, joints: np.ndarray, tips: Optional[np.ndarray] = None,
                   feeds: Optional[Sequence[Optional[float]]] = None) -> float:
        j = np.asarray(joints, dtype=float).reshape(-1, 5)
        total = 0.0
        for i in range(1, len(j)):
            t = self.motion_time(j[i - 1], j[i])
            if feeds is not None and feeds[i]:
                t = max(t, float(np.linalg.norm(j[i, :3] - j[i - 1, :3])) / feeds[i])
            total += t
        return total
