"""The one linker: cut segments (core.segments) -> a tool path, by a policy.

Between segments the tool either stays down (a segment `joined` to the previous one: a zig-zag link the
strategy made of dropped, gouge-free points, then the next pass) or leaves and re-enters:
  retract VERTICAL (3-axis): straight up to the safe height, a rapid across, the entry down;
  retract ALONG_AXIS (5-axis): back along the tool axis by `axis_retract` (fed: the tilted tool moves
      sideways too, through what may still be stock), straight up to the transit height (the lowest point
      of the tilted tool at the safe height), a rapid across with the tool already turned, down (fed, as
      everything below the safe height) to `axis_retract` above the next first point on its axis, the
      entry along it.
The entry is a PLUNGE move at the vertical feed (the only entry so far); ramps and helices are entries
too: they get a row in ENTRIES and an `entry` name, nothing else changes.
The path starts at the clearance height over the first entry (5-axis: upright, then turned there) and
ends at the clearance height (5-axis: upright again, so any later op starts untilted).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, check
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.toolpath import MoveKind, Toolpath, Z_AXIS

VERTICAL, ALONG_AXIS = "vertical", "along_axis"
PLUNGE = "plunge"
Axis = tuple[float, float, float]


@dataclass
class LinkPolicy:
    safe_height: float                  # mm: rapid moves between segments happen at or above it
    clearance_height: float             # mm: start and end height
    retract: str = VERTICAL             # VERTICAL or ALONG_AXIS
    axis_retract: float = 5.0           # ALONG_AXIS: entry and exit distance along the tool axis, mm
    entry: str = PLUNGE                 # a key of ENTRIES
    # ALONG_AXIS: how far the lowest point of the tool lies below its tip for a tool axis (tool geometry:
    # core.tools.Cutter.lowest_below_tip); the transit height keeps that point at the safe height.
    lowest_below_tip: Optional[Callable[[Axis], float]] = None

    def validate(self) -> None:
        check(Spec("safe height", "mm"), self.safe_height)
        check(Spec("clearance height", "mm"), self.clearance_height)
        check(Spec("axis retract", "mm", low=0, kind="length"), self.axis_retract)
        if self.clearance_height < self.safe_height:
            raise TmmError(f"clearance height {self.clearance_height:g} mm is below the safe height "
                           f"{self.safe_height:g} mm")
        if self.retract not in (VERTICAL, ALONG_AXIS):
            raise TmmError(f"retract must be '{VERTICAL}' or '{ALONG_AXIS}', got {self.retract!r}")
        if self.entry not in ENTRIES:
            raise TmmError(f"entry must be one of {', '.join(ENTRIES)}, got {self.entry!r}")


def _plunge(tp: Toolpath, tip: np.ndarray, axis: Axis) -> None:
    tp.add(MoveKind.PLUNGE, *tip, axis)


ENTRIES: dict[str, Callable[[Toolpath, np.ndarray, Axis], None]] = {PLUNGE: _plunge}


def link(segments: Sequence[CutSegment], policy: LinkPolicy) -> Toolpath:
    """The tool path through `segments` in order (see the module doc). No segments: an empty path."""
    policy.validate()
    segments = [s for s in segments if len(s)]
    if not segments:
        return Toolpath()
    return (_link_vertical if policy.retract == VERTICAL else _link_along_axis)(segments, policy)


def _link_vertical(segments: list[CutSegment], policy: LinkPolicy) -> Toolpath:
    tp = Toolpath()
    enter = ENTRIES[policy.entry]
    for seg in segments:
        pts = seg.tips
        first = 0
        if not tp.moves or not seg.joined:
            x0, y0, _ = pts[0]
            if tp.moves:  # lift straight up, cross over at the safe height
                last = tp.moves[-1]
                tp.add(MoveKind.RAPID, last.x, last.y, policy.safe_height, last.axis)
            else:
                tp.add(MoveKind.RAPID, x0, y0, policy.clearance_height)
            tp.add(MoveKind.RAPID, x0, y0, policy.safe_height, seg.axis(0))
            enter(tp, pts[0], seg.axis(0))
            first = 1
        for i in range(first, len(pts)):
            tp.add(MoveKind.FEED, *pts[i], seg.axis(i))
    last = tp.moves[-1]
    tp.add(MoveKind.RAPID, last.x, last.y, policy.clearance_height, last.axis)
    return tp


def _link_along_axis(segments: list[CutSegment], policy: LinkPolicy) -> Toolpath:
    below = policy.lowest_below_tip
    if below is None:
        raise TmmError("linking along the tool axis needs the tool's geometry (lowest_below_tip)")
    r = policy.axis_retract

    def above(tip: np.ndarray, a: Axis) -> tuple[float, float, float]:
        """On the axis `r` above the tip, raised to the transit height if lower."""
        p = tip + r * np.asarray(a)
        return float(p[0]), float(p[1]), max(float(p[2]), policy.safe_height + below(a))

    enter = ENTRIES[policy.entry]
    tp = Toolpath()
    a0 = segments[0].axis(0)
    x, y, z = above(segments[0].tips[0], a0)
    tp.add(MoveKind.RAPID, x, y, max(policy.clearance_height, z), Z_AXIS)
    tp.add(MoveKind.RAPID, x, y, max(policy.clearance_height, z), a0)
    for k, seg in enumerate(segments):
        start = 0
        if k == 0 or not seg.joined:
            a = seg.axis(0)
            tp.add(MoveKind.RAPID, *above(seg.tips[0], a), a)              # transit, the tool turned above the entry
            # below the safe height at the vertical feed, as the 3-axis entry: rapids stay above the stock
            tp.add(MoveKind.PLUNGE, *(seg.tips[0] + r * np.asarray(a)), a)  # down to the entry point on the axis
            enter(tp, seg.tips[0], a)                                        # along the axis onto the face
            start = 1
        for i in range(start, len(seg)):
            tp.add(MoveKind.FEED, *seg.tips[i], seg.axis(i))
        if k + 1 < len(segments) and segments[k + 1].joined:
            continue
        a1 = seg.axis(len(seg) - 1)
        tp.add(MoveKind.PLUNGE, *(seg.tips[-1] + r * np.asarray(a1)), a1)   # back along the axis, fed: the
        tp.add(MoveKind.RAPID, *above(seg.tips[-1], a1), a1)                # tilted tool moves sideways; up
    last = tp.moves[-1]
    top = max(policy.clearance_height, last.z)
    tp.add(MoveKind.RAPID, last.x, last.y, top, last.axis)
    tp.add(MoveKind.RAPID, last.x, last.y, top, Z_AXIS)                       # upright at the clearance height
    return tp
