"""How long a tool path takes: every move the longer of its length at its feed and its slowest joint at the
machine's speed (seed 000's uniform-motion model, no acceleration); rapids at the joint speeds alone. For
3-axis paths the joints are the tip (a plain mill, as core.machine.tarus.ThreeAxisMachine; rapid rates
per axis); 5-axis paths take the Tarus post's estimate, which plans A and C (core.post.tarus_writer)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import MoveKind, Toolpath

DEFAULT_RAPID_MM_S = 5000.0 / 60.0  # a small mill's rapid when the tool controller gives none


@dataclass(frozen=True)
class CycleTime:
    seconds: float
    cutting_seconds: float     # feed moves (FEED and PLUNGE)
    rapid_seconds: float
    cutting_length: float      # mm
    rapid_length: float

    def hms(self) -> str:
        return hms(self.seconds)


def hms(seconds: float) -> str:
    """HH:MM:SS, as FreeCAD's CycleTime shows it."""
    s = int(round(max(seconds, 0.0)))
    return f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"


def three_axis_time(tips: np.ndarray, feeds: Sequence[Optional[float]], horiz_rapid: Optional[float] = None,
                    vert_rapid: Optional[float] = None) -> CycleTime:
    """tips (n, 3); feeds[i] the feed of the move ending at point i, mm/s (None: a rapid; feeds[0] unused; or an
    array with inf or nan for a rapid);
    rapid rates in mm/s per axis (X and Y at horiz_rapid, Z at vert_rapid), DEFAULT_RAPID_MM_S when not
    given or 0. Each move takes the longer of its slowest axis at the rapid rate and its length at its feed."""
    p = np.asarray(tips, dtype=float).reshape(-1, 3)
    if len(feeds) != len(p):
        raise TmmError(f"{len(feeds)} feeds for {len(p)} points")
    if len(p) < 2:
        return CycleTime(0.0, 0.0, 0.0, 0.0, 0.0)
    if isinstance(feeds, np.ndarray):   # a million moves: no Python per move (inf or nan for a rapid)
        f = np.where(np.isnan(feeds[1:]), math.inf, feeds[1:].astype(float))
    else:
        f = np.array([math.inf if v is None else float(v) for v in list(feeds)[1:]])
    bad = np.flatnonzero(~(f > 0))
    if len(bad):
        raise TmmError(f"move {int(bad[0]) + 1} has the feed {float(f[bad[0]])!r} mm/s: a feed must be > 0 for a cycle time")
    hr = horiz_rapid if horiz_rapid and horiz_rapid > 0 else DEFAULT_RAPID_MM_S
    vr = vert_rapid if vert_rapid and vert_rapid > 0 else DEFAULT_RAPID_MM_S
    d = np.abs(np.diff(p, axis=0))
    length = np.linalg.norm(d, axis=1)
    rapid = np.isinf(f)
    times = np.maximum(np.maximum(d[:, 0], d[:, 1]) / hr, np.maximum(d[:, 2] / vr, length / f))
    return CycleTime(float(times.sum()), float(times[~rapid].sum()), float(times[rapid].sum()),
                     float(length[~rapid].sum()), float(length[rapid].sum()))


def toolpath_feeds(toolpath: Toolpath, horiz_feed: float, vert_feed: float) -> list[Optional[float]]:
    """Per point the feed of the move ending there: FEED at horiz_feed, PLUNGE at vert_feed, RAPID None."""
    return [None] + [None if m.kind is MoveKind.RAPID else (vert_feed if m.kind is MoveKind.PLUNGE else horiz_feed)
                     for m in toolpath.moves[1:]]
