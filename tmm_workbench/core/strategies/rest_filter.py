"""The rest filter: a 3-axis strategy's cut segments kept only where the tool takes off rest material
(core.footprint.rest's RestStock: what the Job's earlier ops or a reference tool left, on the rest cells). A
point cuts when, over some rest cell within the tool radius, what is left stands more than the stock's tolerance
above the tool's surface there; a tip next to a cutting one is kept too (the move into a cut sweeps its way in). Elsewhere the segment is
split (core.strategies.segment_split) and the linker lifts over the gap: on a wall the rest raster does not climb
to the rim and back for material that is only at the wall's foot."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.strategies.segment_split import keep_runs, keeps_end, move_samples
from tmm_workbench.core.tools.cutter import Cutter

CHUNK = 20_000   # tips per vectorised block (x the cells under the tool: ~200 for a D3 on 0.25 mm cells)
BRIDGE_DIAMETERS = 3.0   # a gap in a pass shorter than this many tool diameters is cut through, not lifted over:
#                          feeding a few mm through air is quicker than a retract, a rapid and an entry


@dataclass
class RestParams:
    """The fields a 3-axis strategy's params carry for the rest filter (None: cut everywhere; a gap in a pass up
    to `rest_bridge` tool diameters is cut through)."""
    rest: Optional[RestStock] = None
    rest_bridge: float = BRIDGE_DIAMETERS


def _offsets(grid: Grid, reach: float) -> np.ndarray:
    """(k, 2) cell offsets (di, dj) whose centres may lie within `reach` of a point in the middle cell."""
    n = int(math.ceil(reach / grid.cell)) + 1
    d = np.arange(-n, n + 1)
    square = np.array(np.meshgrid(d, d)).reshape(2, -1).T
    nearest = np.maximum(np.abs(square) - 0.5, 0.0) * grid.cell   # the point anywhere in the middle cell
    return square[np.hypot(*nearest.T) <= reach]


def cutting(tips: np.ndarray, cutter: Cutter, rest: RestStock) -> np.ndarray:
    """(n,) whether the tool at each tip (a vertical axis) comes more than the tolerance below what is left over
    some cell centre within its radius."""
    g, R = rest.grid, cutter.native.max_radius
    offsets = _offsets(g, R)
    out = np.zeros(len(tips), dtype=bool)
    for a in range(0, len(tips), CHUNK):
        t = tips[a:a + CHUNK]
        i0 = np.floor((t[:, 0] - g.x0) / g.cell).astype(np.int64)
        j0 = np.floor((t[:, 1] - g.y0) / g.cell).astype(np.int64)
        i, j = i0[:, None] + offsets[None, :, 0], j0[:, None] + offsets[None, :, 1]
        dx = g.x0 + (i + 0.5) * g.cell - t[:, :1]
        dy = g.y0 + (j + 0.5) * g.cell - t[:, 1:2]
        d = np.hypot(dx, dy)
        near = (d <= R) & (i >= 0) & (i < g.nx) & (j >= 0) & (j < g.ny)
        surface = np.full(d.shape, np.inf)
        surface[near] = np.repeat(t[:, 2:3], offsets.shape[0], axis=1)[near] + cutter.native.height(d[near])
        left = np.full(d.shape, -np.inf)
        left[near] = rest.heights[j[near], i[near]]
        out[a:a + CHUNK] = np.any(left - surface > rest.tolerance, axis=1)
    return out


def apply(params: Any, cutter: Cutter, segments: list[CutSegment], diagnostics: dict) -> list[CutSegment]:
    """The segments cut only along the moves that take off rest material (params.rest; None: all of them),
    sampled a cell apart (a long move on a floor may cut only in its middle); what it kept in diagnostics
    "rest" (moves, kept)."""
    rest = getattr(params, "rest", None)
    if rest is None:
        return segments
    out: list[CutSegment] = []
    moves = kept = 0
    end_kept = False   # the previous segment's last tip was kept: one joined to it stays joined only then
    for seg in segments:
        pts, move = move_samples(seg, rest.grid.cell)
        ok_move = np.zeros(len(seg), dtype=bool)
        ok_move[np.unique(move[cutting(pts, cutter, rest)])] = True   # move 0: the first tip itself
        _bridge(seg, ok_move, getattr(params, "rest_bridge", BRIDGE_DIAMETERS) * cutter.diameter)
        ok_tip = ok_move.copy()
        ok_tip[:-1] |= ok_move[1:]    # a kept move's start
        moves += len(seg)
        kept += int(ok_move.sum())
        whole = ok_tip.all() and ok_move[1:].all() and (end_kept or not seg.joined)
        pieces = [seg] if whole else keep_runs(seg, ok_tip, ok_move | ~ok_tip, end_kept)
        out += pieces
        end_kept = keeps_end(seg, pieces)
    diagnostics["rest"] = {"moves": moves, "kept": kept}
    return out


def _bridge(seg: CutSegment, ok_move: np.ndarray, longest: float) -> None:
    """Marks the moves of every gap between two kept stretches of the segment as kept when the gap is at most
    `longest` mm long (in place)."""
    kept = np.flatnonzero(ok_move)
    if len(kept) < 2:
        return
    length = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(seg.tips, axis=0), axis=1))])
    for a, b in zip(kept[:-1], kept[1:]):
        if b > a + 1 and length[b - 1] - length[a] <= longest:
            ok_move[a + 1:b] = True
