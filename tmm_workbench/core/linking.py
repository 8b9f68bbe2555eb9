"""The one linker: cut segments (core.segments) -> a tool path, by a policy.

Between segments the tool either stays down (a segment `joined` to the previous one: a zig-zag link the
strategy made of dropped, gouge-free points, then the next pass) or leaves and re-enters:
  retract VERTICAL (3-axis): straight up to the safe height, a rapid across, the entry down;
  retract ALONG_AXIS (5-axis): back along the tool axis by `axis_retract` (fed: the tilted tool moves
      sideways too, through what may still be stock), straight up to the transit height (the lowest point
      of the tilted tool at the safe height), a rapid across with the tool already turned, down (fed, as
      everything below the safe height) to `axis_retract` above the next first point on its axis, the
      entry along it.
Entries (3-axis), rows of ENTRIES; a segment may name its own (CutSegment.entry), else the policy's:
  PLUNGE  straight down at the vertical feed from the safe height onto the first tip;
  HELIX   fed straight down through air to where the material starts (CutSegment.entry_z; None: the safe
          height), then down a helix at `ramp_angle_deg` on the circle about `helix_centre` through the first
          tip, ending with one full circle at its depth (a flat bottom), at the first tip;
  RAMP    the same descent through air, then down along the segment's own path at `ramp_angle_deg`:
          backwards around a closed loop (`closed`) from its first tip, back and forth along an open one,
          ending at the first tip.
Helix and ramp are only as gouge-free as the XY they pass over: the strategy gives a centre whose circle
lies where the tool centre may go at the first tip's height and above (the linker does not see the model).
The path starts at the clearance height over the first entry (5-axis: upright, then turned there) and
ends at the clearance height (5-axis: upright again, so any later op starts untilted).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import math

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, check
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.toolpath import MoveKind, Toolpath, Z_AXIS

VERTICAL, ALONG_AXIS = "vertical", "along_axis"
PLUNGE, HELIX, RAMP = "plunge", "helix", "ramp"
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
    ramp_angle_deg: float = 3.0         # HELIX and RAMP: descent angle from the horizontal
    arc_tol: float = 0.01               # HELIX: chord deviation of the helix from its circle, mm

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
        check(Spec("ramp angle", "deg", low=0, high=90, low_open=True), self.ramp_angle_deg)
        check(Spec("arc tolerance", "mm", low=0, low_open=True, kind="length"), self.arc_tol)
        if self.retract == ALONG_AXIS and self.entry != PLUNGE:
            raise TmmError(f"entry {self.entry!r} is 3-axis only; linking along the tool axis enters by "
                           f"'{PLUNGE}'")


# An entry: the fed descent (k, 3) from where it begins (its first point: the XY the tool comes down at,
# at the height where the material starts) to the segment's first tip (its last point, exactly).
def _plunge(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    return seg.tips[:1].copy()


def _top(seg: CutSegment, policy: LinkPolicy) -> float:
    """Where the entry starts cutting: the material's top (entry_z) if below the safe height."""
    top = policy.safe_height if seg.entry_z is None else min(float(seg.entry_z), policy.safe_height)
    return top


def _helix(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    end = seg.tips[0]
    if seg.helix_centre is None:
        raise TmmError("a helix entry needs the helix centre of its segment (CutSegment.helix_centre)")
    c = np.asarray(seg.helix_centre, dtype=float)
    r = float(np.hypot(*(end[:2] - c)))
    if not r > 1e-9:
        raise TmmError(f"helix entry at ({end[0]:g}, {end[1]:g}): the first tip lies on the helix centre")
    drop = _top(seg, policy) - float(end[2])
    sense = 1.0 if seg.helix_ccw else -1.0
    dt = 2.0 * math.acos(1.0 - policy.arc_tol / r) if policy.arc_tol < r else math.pi / 4
    t_end = math.atan2(end[1] - c[1], end[0] - c[0])
    pieces = []
    if drop > 0:
        sweep = drop / math.tan(math.radians(policy.ramp_angle_deg)) / r
        f = np.linspace(0.0, 1.0, max(2, math.ceil(sweep / dt) + 1))
        t = t_end - sense * sweep * (1.0 - f)
        pieces.append(np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t), end[2] + drop * (1.0 - f)]))
    f = np.linspace(0.0, 1.0, max(4, math.ceil(2 * math.pi / dt) + 1))[1 if pieces else 0:]
    t = t_end + sense * 2 * math.pi * f                    # the full circle at depth: a flat bottom
    pieces.append(np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t), np.full(len(t), end[2])]))
    out = np.vstack(pieces)
    out[-1] = end
    return out


def _walk(xy: np.ndarray, length: float) -> np.ndarray:
    """The polyline through `xy` (in that order, repeated as given by the caller) cut at `length` mm."""
    d = np.hypot(*np.diff(xy, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(d)])
    k = int(np.searchsorted(s, length))
    if k >= len(xy):
        return xy
    w = (length - s[k - 1]) / d[k - 1] if d[k - 1] > 0 else 0.0
    return np.vstack([xy[:k], xy[k - 1] + w * (xy[k] - xy[k - 1])])


def _ramp(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    tips = seg.tips
    end = tips[0]
    drop = _top(seg, policy) - float(end[2])
    if drop <= 0:
        return tips[:1].copy()
    length = drop / math.tan(math.radians(policy.ramp_angle_deg))
    xy = tips[:, :2]
    if seg.closed:
        loop = np.vstack([xy[:1], xy[::-1]])               # backwards from the first tip round to it
        per = float(np.hypot(*np.diff(loop, axis=0).T).sum())
        if not per > 0:
            raise TmmError(f"ramp entry at ({end[0]:g}, {end[1]:g}): the loop has no length to ramp along")
        turns = math.ceil(length / per) + 1
        back = _walk(np.vstack([loop[:1]] + [loop[1:]] * turns), length)
        path = back[::-1]
    else:
        there = np.vstack([xy, xy[-2::-1]])                 # out and back along the pass
        per = float(np.hypot(*np.diff(there, axis=0).T).sum())
        if not per > 0:
            raise TmmError(f"ramp entry at ({end[0]:g}, {end[1]:g}): the pass has no length to ramp along")
        turns = math.ceil(length / per) + 1
        out = _walk(np.vstack([there[:1]] + [there[1:]] * turns), length / 2)
        path = np.vstack([out, out[-2::-1]])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    z = float(end[2]) + drop * (1.0 - s / s[-1])
    ramp = np.column_stack([path, z])
    ramp[-1] = end
    return ramp


ENTRIES: dict[str, Callable[[CutSegment, LinkPolicy], np.ndarray]] = {PLUNGE: _plunge, HELIX: _helix,
                                                                      RAMP: _ramp}


def link(segments: Sequence[CutSegment], policy: LinkPolicy) -> Toolpath:
    """The tool path through `segments` in order (see the module doc). No segments: an empty path."""
    policy.validate()
    segments = [s for s in segments if len(s)]
    if not segments:
        return Toolpath()
    return (_link_vertical if policy.retract == VERTICAL else _link_along_axis)(segments, policy)


def _link_vertical(segments: list[CutSegment], policy: LinkPolicy) -> Toolpath:
    tp = Toolpath()
    for seg in segments:
        pts = seg.tips
        first = 0
        if not tp.moves or not seg.joined:
            name = seg.entry or policy.entry
            if name not in ENTRIES:
                raise TmmError(f"entry must be one of {', '.join(ENTRIES)}, got {name!r}")
            descent = ENTRIES[name](seg, policy)
            x0, y0, top = descent[0]
            if tp.moves:  # lift straight up, cross over at the safe height
                last = tp.moves[-1]
                tp.add(MoveKind.RAPID, last.x, last.y, policy.safe_height, last.axis)
            else:
                tp.add(MoveKind.RAPID, x0, y0, policy.clearance_height)
            tp.add(MoveKind.RAPID, x0, y0, policy.safe_height, seg.axis(0))
            if len(descent) == 1:                 # straight down onto the tip
                tp.add(MoveKind.PLUNGE, *pts[0], seg.axis(0))
            else:
                if top < policy.safe_height:      # through air to where the material starts
                    tp.add(MoveKind.PLUNGE, x0, y0, top, seg.axis(0))
                for p in descent[1:]:
                    tp.add(MoveKind.FEED, *p, seg.axis(0))
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
    if any(seg.entry not in (None, PLUNGE) for seg in segments):
        raise TmmError(f"helix and ramp entries are 3-axis only; linking along the tool axis enters by '{PLUNGE}'")

    def above(tip: np.ndarray, a: Axis) -> tuple[float, float, float]:
        """On the axis `r` above the tip, raised to the transit height if lower."""
        p = tip + r * np.asarray(a)
        return float(p[0]), float(p[1]), max(float(p[2]), policy.safe_height + below(a))

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
            tp.add(MoveKind.PLUNGE, *seg.tips[0], a)                         # along the axis onto the face
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
