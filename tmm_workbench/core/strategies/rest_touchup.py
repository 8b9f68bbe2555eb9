"""Touch-ups: the tool put where it reaches what a rest's passes and waterline loops leave above the tolerance.

The rest's reach is the tool's envelope, its drop at every cell centre of the rest grid; but the passes and loops
run elsewhere, and what they leave within reach lies almost all where only a narrow band of positions reaches:
in concave corners and at the feet of walls, where the drop at the cell itself touches a wall beside it (mount_rush,
raster: 180 of the 192 cells left; docs/rest_pencil.md). A pass 0.15 mm off that band stands on the wall and
leaves 0.02 mm on the floor. So for each cell still above the tolerance, the grid position whose drop comes lowest
over it (among the cell centres within the tool's radius, as the envelope found it) is a touch-up point when it
brings the cell within the tolerance; the points are chained where they are grid neighbours, each chain a piece
(consecutive points joined by the straight move lifted onto the surface, as rest_joins does), the others single
points (a piece of two equal tips: the tool goes down there and up).
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies import rest_joins
from tmm_workbench.core.tools.cutter import Cutter

CHAIN_CELLS = 1.5   # touch-up points at most this many cells apart are cut in one piece


def pieces(left: Optional[RestStock], cutter: Cutter, surface: DropSurface, stock_to_leave: float = 0.0
           ) -> list[CutSegment]:
    """Touch-up pieces for `left` (the cells the rest's passes and loops leave above its tolerance, at the
    heights they leave; None: nothing), not joined; none for a cell no grid position brings within it."""
    if left is None:
        return []
    points = _best_positions(left, cutter, surface, max(stock_to_leave, 0.0))
    if not len(points):
        return []
    grown = cutter.offset(max(stock_to_leave, 0.0))
    out = []
    for chain in _chains(points, CHAIN_CELLS * left.grid.cell):
        if len(chain) == 1:
            out.append(CutSegment(np.vstack([chain, chain])))
            continue
        path = [chain[0]]
        for a, b in zip(chain[:-1], chain[1:]):
            path += list(rest_joins.lifted(a, b, surface, grown, stock_to_leave)[1:])
        out.append(CutSegment(np.array(path)))
    return out


def _best_positions(left: RestStock, cutter: Cutter, surface: DropSurface, s: float) -> np.ndarray:
    """(k, 3) distinct tips: for each cell of `left`, the cell centre within the tool's radius whose drop comes
    lowest over it, where that is within the tolerance of the design (plus the stock to leave)."""
    g = left.grid
    iy, ix = np.nonzero(np.isfinite(left.heights))
    rmax = float(cutter.native.max_radius)
    n = int(math.ceil(rmax / g.cell))
    oy, ox = np.mgrid[-n:n + 1, -n:n + 1]
    near = np.hypot(ox, oy) * g.cell <= rmax
    oy, ox = oy[near], ox[near]
    cy = np.clip(iy[:, None] + oy[None, :], 0, g.ny - 1)
    cx = np.clip(ix[:, None] + ox[None, :], 0, g.nx - 1)
    flat = cy * g.nx + cx
    unique, inverse = np.unique(flat.ravel(), return_inverse=True)
    xs, ys = g.xs()[unique % g.nx], g.ys()[unique // g.nx]
    grown = cutter.offset(s)
    floor = float(np.nanmin(left.design)) - 1.0
    z = surface.drop(grown, np.column_stack([xs, ys]), floor) + s
    tips = z[inverse].reshape(flat.shape)
    d = np.hypot(g.xs()[cx] - g.xs()[ix][:, None], g.ys()[cy] - g.ys()[iy][:, None])
    over = tips + np.asarray(grown.native.height(np.ascontiguousarray(d.ravel())), dtype=float).reshape(d.shape)
    k = np.argmin(over, axis=1)
    rows = np.arange(len(iy))
    ok = over[rows, k] - left.design[iy, ix] <= left.within + s
    chosen = np.unique(inverse.reshape(flat.shape)[rows[ok], k[ok]])
    return np.column_stack([xs[chosen], ys[chosen], z[chosen]])


def _chains(points: np.ndarray, gap: float) -> list[np.ndarray]:
    """`points` in chains, each walked to its nearest point not yet taken while that is within `gap` in XY."""
    left = np.ones(len(points), dtype=bool)
    chains = []
    while left.any():
        k = int(np.flatnonzero(left)[0])
        chain = [k]
        left[k] = False
        while left.any():
            d = np.hypot(*(points[:, :2] - points[chain[-1], :2]).T)
            d[~left] = np.inf
            j = int(np.argmin(d))
            if d[j] > gap:
                break
            chain.append(j)
            left[j] = False
        chains.append(points[chain])
    return chains
