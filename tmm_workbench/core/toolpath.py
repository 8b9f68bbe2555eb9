"""The toolpath model: ordered moves of the tool tip and tool axis, before any FreeCAD or G-code concern.

A move's position is the tool tip (the CL point of seed 000) in work coordinates, mm; its axis is the unit
vector from the tip towards the spindle, (0, 0, 1) for 3-axis work. A FEED move may be an arc (`Move.arc`,
core.arcs.Arc: G2/G3 from the previous move's point about its centre; 3-axis lean passes): readers that take
moves as lines read its chord, or `Toolpath.chorded` for the arc within a tolerance.
"""
from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Iterator, Optional

import numpy as np

from tmm_workbench.core.arcs import Arc


class MoveKind(enum.Enum):
    RAPID = "rapid"    # G0, above everything
    PLUNGE = "plunge"  # G1 at the vertical feed, down into the material
    FEED = "feed"      # G1 at the horizontal feed, cutting


Z_AXIS = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class Move:
    kind: MoveKind
    x: float
    y: float
    z: float
    axis: tuple[float, float, float] = Z_AXIS
    arc: Optional[Arc] = None  # a FEED move along this circle from the previous move's point; None: a line


@dataclass
class Toolpath:
    moves: list[Move] = field(default_factory=list)

    def __iter__(self) -> Iterator[Move]:
        return iter(self.moves)

    def __len__(self) -> int:
        return len(self.moves)

    def add(self, kind: MoveKind, x: float, y: float, z: float,
            axis: tuple[float, float, float] = Z_AXIS, arc: Optional[Arc] = None) -> None:
        self.moves.append(Move(kind, float(x), float(y), float(z),
                               (float(axis[0]), float(axis[1]), float(axis[2])), arc))

    @property
    def arcs(self) -> dict[int, Arc]:
        """The arc moves: move index -> its Arc."""
        return {i: m.arc for i, m in enumerate(self.moves) if m.arc is not None}

    def chorded(self, tolerance: float = 1e-4) -> "Toolpath":
        """The tool path with its arc moves as chords within `tolerance` (the same kind and axis): what a
        simulation of the moves as lines reads. Without arcs: this path."""
        if not any(m.arc is not None for m in self.moves[1:]):
            return self
        out = Toolpath(self.moves[:1])
        for p, m in zip(self.moves, self.moves[1:]):
            if m.arc is None:
                out.moves.append(m)
                continue
            for q in m.arc.chords((p.x, p.y, p.z), (m.x, m.y, m.z), tolerance):
                out.add(m.kind, *q, m.axis)
        return out

    def points(self) -> np.ndarray:
        """Tip positions as an (n, 3) array."""
        return np.array([(m.x, m.y, m.z) for m in self.moves], dtype=float).reshape(-1, 3)

    def axes(self) -> np.ndarray:
        """Tool axes as an (n, 3) array."""
        return np.array([m.axis for m in self.moves], dtype=float).reshape(-1, 3)

    def is_five_axis(self) -> bool:
        return any(m.axis != Z_AXIS for m in self.moves)

    def cutting_points(self) -> np.ndarray:
        """Tip positions of FEED and PLUNGE moves, (n, 3)."""
        return np.array([(m.x, m.y, m.z) for m in self.moves if m.kind is not MoveKind.RAPID],
                        dtype=float).reshape(-1, 3)

    def steep_descents(self, angle_deg: float) -> np.ndarray:
        """(n,) bool: FEED moves going down more steeply than `angle_deg` below the horizontal (a machinist
        runs these at the plunge feed); the first move and non-FEED moves are False."""
        return steep_mask(self.points(), np.array([m.kind is MoveKind.FEED for m in self.moves]), angle_deg)


def steep_mask(points: np.ndarray, feed: np.ndarray, angle_deg: float) -> np.ndarray:
    """(n,) bool: the moves ending at `points[i]` with `feed[i]` (a FEED move) going down more steeply than
    `angle_deg` below the horizontal; the first move is False."""
    if not (0.0 <= angle_deg <= 90.0):
        raise ValueError(f"plunge angle must be in [0, 90] degrees, got {angle_deg!r}")
    out = np.zeros(len(points), dtype=bool)
    if len(points) < 2:
        return out
    d = np.diff(points, axis=0)
    horizontal = np.hypot(d[:, 0], d[:, 1])
    out[1:] = (d[:, 2] < 0) & (-d[:, 2] > horizontal * np.tan(np.radians(angle_deg))) & feed[1:]
    return out
