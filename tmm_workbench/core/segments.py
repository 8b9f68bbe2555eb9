"""Neutral cut segments: what every strategy computes and the linker joins into a tool path.

A segment is a run of CL points cut in one go: tool tips (n, 3) and, for 5-axis work, unit tool axes
(n, 3) (tip -> spindle; None: vertical). Its kind says what it is:
  PASS  cutting along the footprint (a raster pass, a waterline loop, a pass piece between lifts);
  LINK  a gouge-free connector the strategy computed between two passes (dropped points), cut at feed.
`joined` says the segment continues the previous one with the tool down (no retract): a zig-zag pass
after its link, a link after its pass. Anything else is entered from above by the linker's policy.
Optional entry facts a strategy may give (core.linking's HELIX and RAMP use them; PLUNGE ignores them):
`entry` (this segment's entry instead of the policy's), `entry_z` (where the material starts above the first
tip: the helix or ramp begins there, the tool fed down to it through air; None: at the safe height),
`helix_centre` and `helix_ccw` (the helix circle through the first tip and its sense), `closed` (the tips
are a loop: a ramp follows it backwards from the first tip, around it as often as needed).
"""
from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np


class SegmentKind(enum.Enum):
    PASS = "pass"
    LINK = "link"


@dataclass
class CutSegment:
    tips: np.ndarray                      # (n, 3) tool tip positions, mm
    kind: SegmentKind = SegmentKind.PASS
    axes: Optional[np.ndarray] = None     # (n, 3) unit tool axes; None: (0, 0, 1)
    joined: bool = False                  # continues the previous segment with the tool down
    pass_index: int = 0
    entry: Optional[str] = None           # a key of core.linking.ENTRIES; None: the policy's
    entry_z: Optional[float] = None       # where the material starts above the first tip, mm
    helix_centre: Optional[tuple[float, float]] = None
    helix_ccw: bool = True
    closed: bool = False                  # the tips are a closed loop

    def __post_init__(self) -> None:
        self.tips = np.asarray(self.tips, dtype=float).reshape(-1, 3)
        if self.axes is not None:
            self.axes = np.asarray(self.axes, dtype=float).reshape(-1, 3)
            if len(self.axes) != len(self.tips):
                raise ValueError(f"{len(self.axes)} tool axes for {len(self.tips)} tips")

    def __len__(self) -> int:
        return len(self.tips)

    def axis(self, i: int) -> tuple[float, float, float]:
        if self.axes is None:
            return (0.0, 0.0, 1.0)
        a = self.axes[i]
        return (float(a[0]), float(a[1]), float(a[2]))


@dataclass
class StrategyResult:
    """What a strategy's compute returns: the segments in cutting order and its diagnostics (counts,
    per-point results, warnings) for the op to show."""
    segments: list[CutSegment]
    diagnostics: dict[str, Any] = field(default_factory=dict)

    def cutting_points(self) -> np.ndarray:
        if not self.segments:
            return np.zeros((0, 3))
        return np.vstack([s.tips for s in self.segments])
