"""A cut segment split where some of its tips or moves are not to be cut (the holder guard's leave-out, the rest
filter, the 5-axis mesh finish's holder check): the runs of kept tips joined by kept moves, each run of two tips
or more a segment entered anew by the linker (its tool axes with it)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from tmm_workbench.core.linking import RAMP
from tmm_workbench.core.segments import CutSegment


def keep_runs(seg: CutSegment, ok_tip: np.ndarray, ok_move: np.ndarray, joined: bool = True) -> list[CutSegment]:
    """The segment's runs of `ok_tip` tips joined by `ok_move` moves (move i ends at tip i), the first kept as
    it was entered when it starts at the first tip (still joined to the previous segment with the tool down only
    when `joined`: the caller knows whether that segment's end was kept); a later one ramps down along itself
    where the segment had an entry (a piece has no helix circle of its own)."""
    n = len(seg)
    pieces: list[CutSegment] = []
    i = 0
    while i < n:
        if not ok_tip[i]:
            i += 1
            continue
        j = i + 1
        while j < n and ok_move[j] and ok_tip[j]:
            j += 1
        if j - i >= 2:
            arcs = None if seg.arcs is None else (None,) + tuple(seg.arcs[i + 1:j])
            first = i == 0
            entry = seg.entry if first or (seg.entry is None and seg.helix_centre is None) else RAMP
            axes = None if seg.axes is None else seg.axes[i:j]
            pieces.append(replace(seg, tips=seg.tips[i:j], axes=axes, arcs=arcs, closed=False,
                                  joined=seg.joined and joined and first, entry_z=seg.entry_z if first else None,
                                  entry=entry, helix_centre=seg.helix_centre if first else None))
        i = j
    return pieces


def keeps_end(seg: CutSegment, pieces: list[CutSegment]) -> bool:
    """Whether `pieces` (what is kept of `seg`, in order) end at its last tip: a segment joined to `seg` stays
    joined only then. A kept last tip is not enough: keep_runs drops a run of one tip (a zig-zag link of one point,
    a last move left out), and the next segment joined to an earlier piece's end would be reached by a straight
    move across what was left out."""
    return bool(pieces) and len(pieces[-1]) > 0 and bool(np.array_equal(pieces[-1].tips[-1], seg.tips[-1]))


def move_samples(seg: CutSegment, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(points, move): the segment's tips with samples at most `step` apart along each move (arcs by their
    chords), each point's move (the tip it ends at; a tip is its own move's end)."""
    if seg.arcs is None or all(a is None for a in seg.arcs[1:]):
        return _line_samples(seg.tips, step)
    pts, move = [seg.tips[:1]], [np.zeros(1, dtype=np.int64)]
    for i in range(1, len(seg)):
        a, b = seg.tips[i - 1], seg.tips[i]
        arc = seg.arc(i)
        if arc is not None:
            chord = np.asarray(arc.chords(tuple(a), tuple(b), 1e-3), dtype=float).reshape(-1, 3)
        else:
            n = max(1, int(np.ceil(np.hypot(*(b[:2] - a[:2])) / step)))
            chord = a + np.outer(np.arange(1, n + 1) / n, b - a)
        pts.append(chord)
        move.append(np.full(len(chord), i, dtype=np.int64))
    return np.vstack(pts), np.concatenate(move)


def _line_samples(tips: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """move_samples of a segment of lines, all moves at once."""
    a, b = tips[:-1], tips[1:]
    n = np.maximum(1, np.ceil(np.hypot(*(b[:, :2] - a[:, :2]).T) / step).astype(np.int64))
    move = np.repeat(np.arange(1, len(tips), dtype=np.int64), n)
    k = np.arange(len(move)) - np.repeat(np.cumsum(n) - n, n) + 1          # 1 .. n within each move
    f = (k / n[move - 1])[:, None]
    return (np.vstack([tips[:1], a[move - 1] + f * (b - a)[move - 1]]),
            np.concatenate([np.zeros(1, dtype=np.int64), move]))
