"""The toolpath model: ordered moves of the tool tip, before any FreeCAD or G-code concern."""
from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np


class MoveKind(enum.Enum):
    RAPID = "rapid"    # G0, above everything
    PLUNGE = "plunge"  # G1 at the vertical feed, down into the material
    FEED = "feed"      # G1 at the horizontal feed, cutting


@dataclass(frozen=True)
class Move:
    kind: MoveKind
    x: float
    y: float
    z: float


@dataclass
class Toolpath:
    moves: list[Move] = field(default_factory=list)

    def __iter__(self) -> Iterator[Move]:
        return iter(self.moves)

    def __len__(self) -> int:
        return len(self.moves)

    def add(self, kind: MoveKind, x: float, y: float, z: float) -> None:
        self.moves.append(Move(kind, float(x), float(y), float(z)))

    def points(self) -> np.ndarray:
        """Tip positions as an (n, 3) array."""
        return np.array([(m.x, m.y, m.z) for m in self.moves], dtype=float).reshape(-1, 3)

    def cutting_points(self) -> np.ndarray:
        """Tip positions of FEED and PLUNGE moves, (n, 3)."""
        return np.array([(m.x, m.y, m.z) for m in self.moves if m.kind is not MoveKind.RAPID],
                        dtype=float).reshape(-1, 3)
