"""The one tool model: a convex solid of revolution, the generalized APT cutter of seed 000 (section 3.5.2.2): diameter 2R at the cutting-edge height L_C, corner radius r, bottom angle beta1 (from the
horizontal) and taper angle beta2 (from the axis, positive when the side widens upwards).

ball: r = R; flat (cylindrical): r = 0; bull-nose (toroidal): 0 < r < R; all with beta1 = beta2 = 0.
V-bits and chamfers: r = 0 with a bottom cone (beta1) or a taper (beta2); tapered ball and bull: beta2 > 0.

Views of the same tool for the strategies: `native` (the APT profile the drop-cutter and drop-along
queries use), `torus_radii` (Ro, Ri: the toroidal view multipoint positioning and the 5-axis simulation
use; a ball is Ro = 0), `lowest_below_tip(axis)` (how far the tilted tool reaches below its tip, for
transit heights). `kind` is what strategies list as their supported tools (data, not code).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.kernel import native


def _number(name: str, v: object) -> float:
    if not isinstance(v, (int, float)) or isinstance(v, bool) or math.isnan(v):
        raise TmmError(f"cutter {name} must be a number, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Cutter:
    diameter: float
    corner_radius: float = 0.0
    bottom_angle_deg: float = 0.0     # beta1
    taper_angle_deg: float = 0.0      # beta2
    cutting_length: float = math.inf  # L_C; needed when the cutter has a cone or a taper

    def __post_init__(self) -> None:
        d = _number("diameter", self.diameter)
        r = _number("corner radius", self.corner_radius)
        if not (math.isfinite(d) and d > 0):
            raise TmmError(f"cutter diameter must be a positive finite number, got {d!r}")
        if not (math.isfinite(r) and r >= 0):
            raise TmmError(f"cutter corner radius must be zero or positive, got {r!r}")
        if self.is_plain and r > d / 2 + 1e-12:
            raise TmmError(f"cutter corner radius {r:g} mm is larger than the cutter radius {d / 2:g} mm")
        try:
            object.__setattr__(self, "_native", self._make_native())
        except ValueError as exc:
            raise TmmError(f"impossible cutter {self.describe()}: {exc}") from exc

    def _make_native(self) -> "native.Cutter":
        if self.is_plain:
            return native.Cutter(self.radius, self.corner_radius)
        return native.Cutter.apt(self.radius, self.corner_radius, _number("cutting length", self.cutting_length),
                                 math.radians(_number("bottom angle", self.bottom_angle_deg)),
                                 math.radians(_number("taper angle", self.taper_angle_deg)))

    @classmethod
    def ball(cls, diameter: float) -> "Cutter":
        return cls(diameter, diameter / 2)

    @classmethod
    def flat(cls, diameter: float) -> "Cutter":
        return cls(diameter, 0.0)

    @classmethod
    def bull(cls, diameter: float, corner_radius: float) -> "Cutter":
        return cls(diameter, corner_radius)

    @classmethod
    def torus(cls, Ro: float, Ri: float) -> "Cutter":
        """The toroidal cutter of major radius Ro (axis to tube centre) and minor radius Ri (seed 001)."""
        Ro, Ri = _number("major radius Ro", Ro), _number("minor radius Ri", Ri)
        if not (math.isfinite(Ro) and Ro >= 0):
            raise TmmError(f"major radius Ro must be >= 0 mm (0 is a ball end mill), got {Ro:g}")
        if not (math.isfinite(Ri) and Ri > 0):
            raise TmmError("minor radius Ri must be > 0: a flat end mill (Ri = 0) has no pseudo-insert to tilt "
                           f"about; multipoint positioning needs a toroidal or ball cutter (got Ri = {Ri:g})")
        return cls(2.0 * (Ro + Ri), Ri)

    @classmethod
    def vbit(cls, diameter: float, included_angle_deg: float, tip_diameter: float = 0.0) -> "Cutter":
        """A cone of `included_angle_deg` from a flat tip of `tip_diameter` up to `diameter`."""
        half = _number("included angle", included_angle_deg) / 2
        if not 0 < half < 90:
            raise TmmError(f"V-bit included angle must be between 0 and 180 degrees, got {included_angle_deg!r}")
        if not 0 <= tip_diameter < diameter:
            raise TmmError(f"V-bit tip diameter {tip_diameter!r} must be at least 0 and below the diameter "
                           f"{diameter!r}")
        height = (diameter - tip_diameter) / 2 / math.tan(math.radians(half))
        return cls(diameter, 0.0, 0.0, half, height)

    @property
    def radius(self) -> float:
        return self.diameter / 2

    @property
    def is_plain(self) -> bool:
        """Ball, flat or bull-nose: no cone, no taper."""
        return self.bottom_angle_deg == 0 and self.taper_angle_deg == 0

    @property
    def kind(self) -> str:
        if not self.is_plain:
            return "general"
        if self.corner_radius == 0:
            return "flat"
        if abs(self.corner_radius - self.radius) <= 1e-12:
            return "ball"
        return "bull"

    @property
    def torus_radii(self) -> tuple[float, float]:
        """(Ro, Ri) of the toroidal view: bull-nose (R - r, r), ball (0, R). Other tools have none."""
        if self.kind == "ball":
            return 0.0, self.radius
        if self.kind == "bull":
            return self.radius - self.corner_radius, self.corner_radius
        raise TmmError(f"the {self.describe()} cutter is not toroidal: a flat end mill (Ri = 0) has no pseudo-insert "
                       "to tilt about; multipoint positioning needs a toroidal (bull-nose) or ball cutter")

    def lowest_below_tip(self, axis: tuple[float, float, float]) -> float:
        """How far the lowest point of the cutter lies below its tip when its axis is `axis` (unit, tip ->
        spindle): r (1 - cos t) + (R - r) sin t for a tilt t (ball, flat, bull-nose)."""
        c = max(-1.0, min(1.0, axis[2]))
        r = self.corner_radius
        return r * (1.0 - c) + (self.radius - r) * math.sqrt(max(0.0, 1.0 - c * c))

    @property
    def native(self) -> "native.Cutter":
        return self._native  # type: ignore[attr-defined]

    def offset(self, distance: float) -> "Cutter":
        """The cutter grown by `distance` all round. Its lower surface lies `distance` below this cutter's, so
        dropping it on a mesh and raising the tip by `distance` gives the exact drop of this cutter on the
        mesh offset by `distance` (stock to leave)."""
        if distance == 0:
            return self
        if not self.is_plain:
            # The offset of a cone or taper is no longer an APT cutter (a cone's point becomes a sphere).
            raise TmmError(f"stock to leave is not supported with the {self.describe()} cutter; "
                           "use a ball, flat or bull-nose cutter")
        if distance < 0 and -distance > self.corner_radius:
            raise TmmError(
                f"negative stock to leave {distance:g} mm exceeds the corner radius {self.corner_radius:g} mm")
        return Cutter(self.diameter + 2 * distance, self.corner_radius + distance)

    def describe(self) -> str:
        k = self.kind
        if k == "bull":
            return f"bull-nose D{self.diameter:g} r{self.corner_radius:g}"
        if k == "general":
            return (f"APT D{self.diameter:g} r{self.corner_radius:g} beta1 {self.bottom_angle_deg:g} deg "
                    f"beta2 {self.taper_angle_deg:g} deg L_C {self.cutting_length:g}")
        return f"{k} D{self.diameter:g}"
