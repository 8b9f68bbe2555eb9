"""Touch-ups: the tool put where it reaches what a rest's passes and waterline loops leave above the tolerance.

The rest's reach is the tool's envelope, its drop at every cell centre of the rest grid; but the passes and loops
run elsewhere, and what they leave within reach lies almost all where only a narrow band of positions reaches:
in concave corners and at the feet of walls, where the drop at the cell itself touches a wall beside it (mount_rush,
raster: 180 of the 192 cells left; docs/rest_pencil.md). A pass 0.15 mm off that band stands on the wall and
leaves 0.02 mm on the floor. So for each cell still above the tolerance, the grid position whose drop comes lowest
over it (among the cell centres within the tool's radius, as the envelope found it) is a touch-up point when it
brings the cell within the tolerance; the points are chained where they are grid neighbours, each chain a piece
(consecutive points joined by the straight move lifted onto the surface, as rest_joins does), the others single
points (a piece of two equal tips: the tool goes down there and up); the shank and holder kept clear of the model
as the passes' are (core.strategies.holder_guard). With the whole tool (the params' assembly) a position's height
is the lowest at which neither its cutter nor its shank or holder comes too close: beside a wall taller than the
flutes the cutter's own lowest position over a floor cell often puts the shank in the wall (pycam_textbox's floor
between the letters: the guard then lifted or left out the touch-up), while another position within the radius
cuts the cell with the shank clear.
"""
from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.footprint.reach import NEAREST_BATCH, nearest_positions, reach_excess
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.stock_bodies import bodies_drop
from tmm_workbench.core.strategies import holder_guard, rest_joins
from tmm_workbench.core.tools.cutter import Cutter

CHAIN_CELLS = 1.5   # touch-up points at most this many cells apart are cut in one piece
CHUNK = 500_000     # (cell, position) pairs looked at together
DOUBT = 4.0         # tolerances: a cell no grid position brings within one is searched between them when its
#                     envelope comes within this many along the normal (reach_excess)


def pieces(mesh: TriMesh, cutter: Cutter, params: Any, left: Optional[RestStock], surface: DropSurface
           ) -> list[CutSegment]:
    """Touch-up pieces for `left` (the cells the rest's passes and loops leave above its tolerance, at the
    heights they leave; None: nothing), not joined, through the holder guard with the Surface params' assembly;
    none for a cell no grid position brings within it."""
    if left is None:
        return []
    s = max(float(getattr(params, "stock_to_leave", 0.0)), 0.0)
    bodies = None if getattr(params, "assembly", None) is None else bodies_drop(mesh, params.assembly, surface,
                                                                                 getattr(params, "stock", None))
    points = _best_positions(left, cutter, surface, s, bodies)
    if not len(points):
        return []
    grown = cutter.offset(s)
    out = []
    for chain in _chains(points, CHAIN_CELLS * left.grid.cell):
        if len(chain) == 1:
            out.append(CutSegment(np.vstack([chain, chain])))
            continue
        path = [chain[0]]
        for a, b in zip(chain[:-1], chain[1:]):
            path += list(rest_joins.lifted(a, b, surface, grown, s)[1:])
        out.append(CutSegment(np.array(path)))
    return holder_guard.apply(mesh, params, out, params.sample_step, surface, {})


def _best_positions(left: RestStock, cutter: Cutter, surface: DropSurface, s: float,
                    bodies: Optional[AssemblyDrop] = None) -> np.ndarray:
    """(k, 3) distinct tips: for each cell of `left`, the cell centre within the tool's radius whose drop comes
    lowest over it, where that is within the tolerance of the design (plus the stock to leave); with `bodies`
    (the whole tool) no lower than its shank and holder keep their clearance there."""
    g = left.grid
    iy, ix = np.nonzero(np.isfinite(left.heights))
    rmax = float(cutter.native.max_radius)
    n = int(math.ceil(rmax / g.cell))
    oy, ox = np.mgrid[-n:n + 1, -n:n + 1]
    near = np.hypot(ox, oy) * g.cell <= rmax
    oy, ox = oy[near], ox[near]
    grown = cutter.offset(s)
    floor = float(np.nanmin(left.design)) - 1.0
    chosen: list[np.ndarray] = []
    near_reach = _near_reach(left, cutter)
    step = max(1, CHUNK // len(oy))
    for k0 in range(0, len(iy), step):   # a block of cells at a time: cells x positions within the radius
        by, bx = iy[k0:k0 + step], ix[k0:k0 + step]
        cy = np.clip(by[:, None] + oy[None, :], 0, g.ny - 1)
        cx = np.clip(bx[:, None] + ox[None, :], 0, g.nx - 1)
        unique, inverse = np.unique((cy * g.nx + cx).ravel(), return_inverse=True)
        xy = np.column_stack([g.xs()[unique % g.nx], g.ys()[unique // g.nx]])
        z = surface.drop(grown, xy, floor) + s
        if bodies is not None:
            z = np.maximum(z, bodies.heights_of(holder_guard.BODIES, xy, floor)[0])
        d = np.hypot(g.xs()[cx] - g.xs()[bx][:, None], g.ys()[cy] - g.ys()[by][:, None])
        profile = np.asarray(grown.native.height(np.ascontiguousarray(d.ravel())), dtype=float).reshape(d.shape)
        over = z[inverse].reshape(d.shape) + profile
        best = np.argmin(over, axis=1)
        rows = np.arange(len(by))
        ok = over[rows, best] - left.design[by, bx] <= left.within + s
        at = inverse.reshape(d.shape)[rows[ok], best[ok]]
        chosen.append(np.column_stack([xy[at], z[at]]))
        if s == 0.0 and not ok.all():
            doubt = ~ok & near_reach[by, bx]
            chosen.append(_between(left, cutter, surface, bodies, np.column_stack([by[doubt], bx[doubt]]), floor))
    return np.unique(np.vstack(chosen), axis=0) if chosen else np.empty((0, 3))


def _near_reach(left: RestStock, cutter: Cutter) -> np.ndarray:
    """(ny, nx) the cells whose envelope comes within DOUBT tolerances of the design along its normal beyond the
    grid's cusp (core.footprint.reach.reach_excess; all without an envelope): the others (sharp inner corners,
    under a wall's overhang) no position between the grid's brings within one, and searching them costs ~200
    drops each."""
    if left.envelope is None:
        return np.ones(left.heights.shape, dtype=bool)
    with np.errstate(invalid="ignore"):
        return reach_excess(left.envelope, left.design, left.grid.cell, cutter.radius) <= DOUBT * left.within


def _between(left: RestStock, cutter: Cutter, surface: DropSurface, bodies: Optional[AssemblyDrop],
             cells: np.ndarray, floor: float) -> np.ndarray:
    """(k, 3) tips between the grid's positions for `cells` ((n, 2) rows, columns) no grid position brings within
    the tolerance: where the tool dropped anywhere within its radius (core.footprint.reach's pattern search, the
    whole tool with `bodies`) comes within it of the design point along the normal, as the planner's left check
    judges. On a wall the grid's positions lie cell / cos a apart along it and their drops miss the cell, and at
    a wall's foot the vertical gap of the best position stays above the tolerance where the normal one does not
    (demo: the D1's touch-ups left 0.012 mm beside its walls where a position 0.009 mm off exists)."""
    if not len(cells):
        return np.empty((0, 3))
    design = np.where(np.isfinite(left.design), left.design, floor)
    out = [np.empty((0, 3))]
    for k in range(0, len(cells), NEAREST_BATCH):
        gap, tips = nearest_positions(None, cutter, left.grid, design, cells[k:k + NEAREST_BATCH], surface, bodies,
                                      floor)
        out.append(tips[gap <= left.within])
    return np.vstack(out)


def _chains(points: np.ndarray, gap: float) -> list[np.ndarray]:
    """`points` in chains, each walked to its nearest point not yet taken while that is within `gap` in XY."""
    from scipy.spatial import cKDTree

    tree = cKDTree(points[:, :2])
    free = np.ones(len(points), dtype=bool)
    chains = []
    for start in range(len(points)):
        if not free[start]:
            continue
        chain = [start]
        free[start] = False
        while True:
            near = [j for j in tree.query_ball_point(points[chain[-1], :2], gap) if free[j]]
            if not near:
                break
            j = min(near, key=lambda j: float(np.hypot(*(points[j, :2] - points[chain[-1], :2]))))
            chain.append(j)
            free[j] = False
        chains.append(points[chain])
    return chains
