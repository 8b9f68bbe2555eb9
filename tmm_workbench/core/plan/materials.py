"""Feeds and speeds for the automatic planner: a small table of common materials for carbide end mills.

Per material: the cutting speed (m/min at the tool's circumference), the chip load per tooth by tool diameter
(mm, interpolated between the rows, clamped at the ends) and the roughing engagement (axial depth and radial
step-over as fractions of the diameter). The spindle speed is the cutting speed's, capped by the machine's
spindle; the feed is chip load x flutes x rpm, capped by the machine's feed; the plunge feed a third of it.
Moderate starting values from tool makers' charts for 2-3 flute carbide in a hobby or light industrial mill;
a shop with better numbers writes its own in the job file's `material` (the same keys).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tmm_workbench.core.errors import TmmError

# name -> cutting speed m/min, ((diameter mm, chip load mm/tooth), ...), roughing depth / D, roughing width / D
TABLE: dict[str, tuple[float, tuple[tuple[float, float], ...], float, float]] = {
    "aluminium": (250.0, ((2.0, 0.010), (3.0, 0.015), (6.0, 0.035), (10.0, 0.060), (12.0, 0.070)), 0.5, 0.40),
    "hardwood": (350.0, ((2.0, 0.020), (3.0, 0.030), (6.0, 0.080), (10.0, 0.120), (12.0, 0.140)), 1.0, 0.45),
    "mdf": (400.0, ((2.0, 0.025), (3.0, 0.040), (6.0, 0.100), (10.0, 0.150), (12.0, 0.180)), 1.0, 0.50),
    "modelling_foam": (500.0, ((2.0, 0.040), (3.0, 0.060), (6.0, 0.150), (10.0, 0.250), (12.0, 0.300)), 2.0, 0.60),
}
PLUNGE_SHARE = 1.0 / 3.0     # of the feed: entering the material axially
MIN_RPM = 1000.0             # below it a spindle runs rough; a tool that would need less gets this


@dataclass(frozen=True)
class Cutting:
    """One tool's numbers in one material on one machine."""
    rpm: float
    feed: float          # mm/min
    plunge: float        # mm/min
    chip_load: float     # mm/tooth used
    step_down: float     # mm, roughing depth per layer (before the flute length's limit)
    stepover_percent: float

    def as_dict(self) -> dict:
        return {"rpm": round(self.rpm), "feed_mm_min": round(self.feed, 1), "plunge_mm_min": round(self.plunge, 1),
                "chip_load_mm": round(self.chip_load, 4), "roughing_step_down_mm": round(self.step_down, 3),
                "roughing_stepover_percent": round(self.stepover_percent, 1)}


def names() -> list[str]:
    return sorted(TABLE)


def cutting(material: str, diameter: float, flutes: int, spindle_max: float, feed_max: float) -> Cutting:
    """The spindle speed, feeds and roughing engagement of a `diameter` mm tool with `flutes` teeth."""
    if material not in TABLE:
        raise TmmError(f"material must be one of {', '.join(names())}, got {material!r}")
    vc, rows, depth, width = TABLE[material]
    rpm = min(spindle_max, max(MIN_RPM, vc * 1000.0 / (math.pi * diameter)))
    d, fz = zip(*rows)
    chip = float(np.interp(diameter, d, fz))
    feed = min(feed_max, chip * flutes * rpm)
    return Cutting(rpm, feed, feed * PLUNGE_SHARE, chip, depth * diameter, width * 100.0)
