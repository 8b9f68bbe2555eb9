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
`arcs` (3-axis): per tip, the arc (core.arcs.Arc) of the move that ends at it, None for a line; the move to the
first tip comes from the previous segment's last one (used when `joined`). The linker makes them arc moves.
"""
from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.arcs import Arc

ArcsAt = tuple[Optional[Arc], ...]  # per tip: the arc of the move ending there, None: a line


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
    arcs: Optional[ArcsAt] = None         # per tip, the arc ending there; None: lines only
    axis_retract: Optional[float] = None  # linking along the axis: this segment's entry and exit (None: the policy's)

    def __post_init__(self) -> None:
        self.tips = np.asarray(self.tips, dtype=float).reshape(-1, 3)
        if self.axes is not None:
            self.axes = np.asarray(self.axes, dtype=float).reshape(-1, 3)
            if len(self.axes) != len(self.tips):
                raise ValueError(f"{len(self.axes)} tool axes for {len(self.tips)} tips")
        if self.arcs is not None:
            self.arcs = tuple(self.arcs)
            if len(self.arcs) != len(self.tips):
                raise ValueError(f"{len(self.arcs)} arcs for {len(self.tips)} tips")
            if self.axes is not None and any(self.arcs):
                raise ValueError("arcs are 3-axis moves: a segment with tool axes has none")

    def __len__(self) -> int:
        return len(self.tips)

    def axis(self, i: int) -> tuple[float, float, float]:
        if self.axes is None:
            return (0.0, 0.0, 1.0)
        a = self.axes[i]
        return (float(a[0]), float(a[1]), float(a[2]))

    def arc(self, i: int) -> Optional[Arc]:
        """The arc of the move that ends at tip i (None: a line)."""
        return None if self.arcs is None else self.arcs[i]

    def reversed_arcs(self, into_first: Optional[Arc] = None) -> Optional[ArcsAt]:
        """The arcs of this segment run backwards (its tips reversed): the arc ending at tip i then ends at
        tip i - 1 and turns the other way; `into_first` is the arc of the move that now ends at the first tip."""
        if (self.arcs is None and into_first is None) or not len(self):
            return None
        old = self.arcs or (None,) * len(self)
        back = tuple(None if a is None else a.reversed() for a in old[:0:-1])
        return (into_first,) + back


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
