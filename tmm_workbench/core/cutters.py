"""Cutters as the kernel sees them: convex solids of revolution given by diameter and corner radius.

ball: corner_radius == diameter / 2; flat (cylindrical): corner_radius == 0; bull-nose (toroidal): in between.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import TmmError


@dataclass(frozen=True)
class Cutter:
    diameter: float
    corner_radius: float = 0.0

    def __post_init__(self) -> None:
        d, r = self.diameter, self.corner_radius
        if not (isinstance(d, (int, float)) and math.isfinite(d) and d > 0):
            raise TmmError(f"cutter diameter must be a positive finite number, got {d!r}")
        if not (isinstance(r, (int, float)) and math.isfinite(r) and r >= 0):
            raise TmmError(f"cutter corner radius must be zero or positive, got {r!r}")
        if r > d / 2 + 1e-12:
            raise TmmError(
                f"cutter corner radius {r:g} mm is larger than the cutter radius {d / 2:g} mm")

    @classmethod
    def ball(cls, diameter: float) -> "Cutter":
        return cls(diameter, diameter / 2)

    @classmethod
    def flat(cls, diameter: float) -> "Cutter":
        return cls(diameter, 0.0)

    @classmethod
    def bull(cls, diameter: float, corner_radius: float) -> "Cutter":
        return cls(diameter, corner_radius)

    @property
    def radius(self) -> float:
        return self.diameter / 2

    @property
    def kind(self) -> str:
        if self.corner_radius == 0:
            return "flat"
        if abs(self.corner_radius - self.radius) <= 1e-12:
            return "ball"
        return "bull"

    def offset(self, distance: float) -> "Cutter":
        """The cutter grown by `distance` all round. Its lower surface lies `distance` below this cutter's, so
        dropping it on a mesh and raising the tip by `distance` gives the exact drop of this cutter on the
        mesh offset by `distance` (stock to leave)."""
        if distance == 0:
            return self
        if distance < 0 and -distance > self.corner_radius:
            raise TmmError(
                f"negative stock to leave {distance:g} mm exceeds the corner radius {self.corner_radius:g} mm")
        return Cutter(self.diameter + 2 * distance, self.corner_radius + distance)

    def describe(self) -> str:
        if self.kind == "bull":
            return f"bull-nose D{self.diameter:g} r{self.corner_radius:g}"
        return f"{self.kind} D{self.diameter:g}"
