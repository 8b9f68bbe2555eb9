"""Arcs (G2/G3; FreeCAD's I/J/K: the centre relative to the start) as chords no further than `tolerance`
from the arc: what the simulator and the checks read of paths made by FreeCAD's own ops (XY, G17: Z
helical, linear in the angle) and of TMM's lean passes (XZ, G18, and YZ, G19: arcs in a pass's vertical
plane). As RS274/NGC: G2 is clockwise viewed from the positive end of the plane's normal axis (Z, Y, X).

`Arc` is the circle of one arc move of the toolpath model (core.toolpath.Move.arc, core.segments.CutSegment.arcs):
the move's end is its point, its start the previous move's. Its G-code (plane word, G2/G3, the centre words) is
written here only (`PLANE_CODES`, `Arc.command`); its chords, for readers that take moves as lines, too
(`Arc.chords`)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError


# the plane's two axes in the order that makes a counter-clockwise turn positive about its normal, then the normal
_AXES = {"XY": (0, 1, 2), "XZ": (2, 0, 1), "YZ": (1, 2, 0)}
PLANE_CODES = {"XY": "G17", "XZ": "G18", "YZ": "G19"}  # the plane select word of each arc plane
_CENTRE_WORDS = "IJK"  # the centre's X, Y, Z offsets from the start
Point = Sequence[float]


@dataclass(frozen=True)
class Arc:
    """The circle of an arc move (sweep under 360 deg) to the move's end point, as RS274/NGC reads it."""
    centre: tuple[float, float, float]  # mm, absolute
    clockwise: bool                     # G2: clockwise viewed from the plane's positive normal axis
    plane: str                          # "XY" (G17), "XZ" (G18, normal +Y) or "YZ" (G19, normal +X)

    def __post_init__(self) -> None:
        if self.plane not in _AXES:
            raise TmmError(f"arc plane must be one of {', '.join(_AXES)}, got {self.plane!r}")

    @classmethod
    def through(cls, start: Point, end: Point, centre: Point, plane: str) -> "Arc":
        """The arc from `start` to `end` about `centre` in `plane` that sweeps less than 180 deg."""
        c = np.asarray(centre, dtype=float)
        normal = np.cross(np.asarray(start, dtype=float) - c, np.asarray(end, dtype=float) - c)
        return cls((float(c[0]), float(c[1]), float(c[2])), bool(normal[_AXES[plane][2]] < 0), plane)

    def reversed(self) -> "Arc":
        """The same circle run the other way (the move from its end back to its start)."""
        return replace(self, clockwise=not self.clockwise)

    def offsets(self, start: Point) -> dict[str, float]:
        """The centre words from `start`: the plane's two of I, J, K (I and K in XZ, J and K in YZ)."""
        used = sorted(_AXES[self.plane][:2])
        return {_CENTRE_WORDS[k]: self.centre[k] - start[k] for k in used}

    def command(self, start: Point, end: Point) -> tuple[str, dict[str, float]]:
        """The G-code of the arc move from `start` to `end`: (G2 or G3, X Y Z and the centre words); the plane
        word (PLANE_CODES) must be in force before it."""
        words = {"X": float(end[0]), "Y": float(end[1]), "Z": float(end[2])}
        words.update(self.offsets(start))
        return ("G2" if self.clockwise else "G3"), words

    def chords(self, start: Point, end: Point, tolerance: float) -> np.ndarray:
        """The points after `start` along the arc to `end` (the last row) as chords within `tolerance`."""
        off = self.offsets(start)
        return arc_points(start, end, off.get("I", 0.0), off.get("J", 0.0), self.clockwise, tolerance,
                          plane=self.plane, k=off.get("K", 0.0))


def arc_points(start, end, i: float, j: float, clockwise: bool, tolerance: float = 1e-3, plane: str = "XY",
               k: float = 0.0) -> np.ndarray:
    """(k, 3) points after `start` along the arc to `end` (the last row is `end`) in `plane` ("XY", "XZ",
    "YZ"; i, j, k: the centre's X, Y, Z offsets from the start, the plane's two used). A full circle when start
    and end coincide in the plane. TmmError when the centre is not equidistant (by more than 1e-4 relative)."""
    if plane not in _AXES:
        raise TmmError(f"arc plane must be one of {', '.join(_AXES)}, got {plane!r}")
    order = list(_AXES[plane])
    back = np.argsort(order)
    offsets = np.array([i, j, k], dtype=float)[order]
    pts = _arc_xy(np.asarray(start, float)[order], np.asarray(end, float)[order], offsets[0], offsets[1],
                  clockwise, tolerance)
    return pts[:, back]


def _arc_xy(p0: np.ndarray, p1: np.ndarray, i: float, j: float, clockwise: bool, tolerance: float) -> np.ndarray:
    c = p0[:2] + (i, j)
    r0, r1 = float(np.hypot(*(p0[:2] - c))), float(np.hypot(*(p1[:2] - c)))
    if not (r0 > 0 and math.isfinite(r0)):
        raise TmmError(f"arc from {p0.tolist()} with centre offset ({i:g}, {j:g}): zero radius")
    if abs(r0 - r1) > 1e-4 * max(r0, 1.0) + 1e-6:
        raise TmmError(f"arc from {p0.tolist()} to {p1.tolist()}: the centre is {r0:.6g} mm from the start and "
                       f"{r1:.6g} mm from the end")
    a0 = math.atan2(p0[1] - c[1], p0[0] - c[0])
    a1 = math.atan2(p1[1] - c[1], p1[0] - c[0])
    sweep = (a0 - a1) if clockwise else (a1 - a0)
    sweep %= 2 * math.pi
    if sweep < 1e-12:
        sweep = 2 * math.pi  # the same point: a full circle
    step = 2 * math.acos(max(-1.0, 1 - tolerance / r0)) if tolerance < r0 else math.pi / 2
    n = max(1, math.ceil(sweep / step))
    t = np.arange(1, n + 1) / n
    ang = a0 + (-sweep if clockwise else sweep) * t
    r = r0 + (r1 - r0) * t
    pts = np.column_stack([c[0] + r * np.cos(ang), c[1] + r * np.sin(ang), p0[2] + (p1[2] - p0[2]) * t])
    pts[-1] = p1
    return pts
