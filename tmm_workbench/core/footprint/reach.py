"""What a tool reaches of a design judged along the normal, between the grid's positions too: the planner's reach
tests and left check (core.plan.analysis, core.plan.left_check) and a rest's touch-ups (core.strategies.rest_touchup)
judge by the same rules. On a steep wall the vertical gap is many times the depth along the normal, and the grid's
positions lie cell / cos a apart along it (1.15 mm on an 80 deg wall at 0.2 mm: more than a D1): what a tool reaches
there is told by dropping it between them."""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

STEEPEST_DEG = 80.0      # the grid's own cusp is judged at most at this slope (on a wall it grows without bound)
FIRST_SAMPLES = 7        # nearest_reach: the first round's drops per side over the tool's width,
REFINE = 6               # then 5 x 5 rounds: a D1's positions 0.003 mm apart at the end (0.016 mm on an 80 deg wall)
NEAREST_BATCH = 4096     # cells searched at once (49 drops each in the first round: the memory stays small)


def reach_excess(envelope: np.ndarray, design: np.ndarray, cell: float, radius: float) -> np.ndarray:
    """How far a tool's envelope (core.footprint.rest.tool_envelope, its corner `radius`) stays above the design
    beyond what the grid itself leaves, along the envelope's normal (the vertical gap times the cosine of the
    envelope's slope: a wall's vertical gap is many times its depth): between the grid's positions the envelope
    on a slope a keeps cusps of cell^2 / (8 r cos^2 a) along its normal. A cell is out of the tool's reach where
    this exceeds the tolerance (NaN where there is no design)."""
    cos = np.maximum(gentle_cosine(envelope, cell), math.cos(math.radians(STEEPEST_DEG)))
    return (envelope - design) * cos - cell * cell / (8.0 * radius * cos * cos)


def gentle_cosine(z: np.ndarray, cell: float) -> np.ndarray:
    """(ny, nx) cos of the slope of heights `z`, each axis' slope the gentler of its two one-sided differences (a
    smooth slope reads as with central ones; a step beside a cell, as the side without it). A central difference
    across a step reads the step's slope: the envelope of a D1 held up by its shank beside a letter rises 5 mm
    one cell off a floor cell it stands 0.2 mm above (at least 0.14 mm along the normal), and that cell was
    counted reached (pycam_textbox: 153 of the 154 mm2 left "in reach"); so was a ball's fillet at a wall's foot.
    1 where no slope is known (no neighbour with a height)."""
    z = np.asarray(z, dtype=float)
    out = []
    for axis in (0, 1):
        if z.shape[axis] < 2:
            out.append(np.zeros_like(z))
            continue
        step = np.diff(z, axis=axis) / cell
        pad = [(0, 0), (0, 0)]
        pad[axis] = (1, 0)
        back = np.abs(np.pad(step, pad, constant_values=np.nan))
        pad[axis] = (0, 1)
        ahead = np.abs(np.pad(step, pad, constant_values=np.nan))
        with np.errstate(invalid="ignore"):
            out.append(np.fmin(back, ahead))
    cos = 1.0 / np.sqrt(1.0 + out[0] ** 2 + out[1] ** 2)
    return np.where(np.isfinite(cos), cos, 1.0)


def nearest_reach(mesh: TriMesh, cutter: Cutter, grid: Grid, design: np.ndarray, cells: np.ndarray,
                  surface: Optional[DropSurface] = None, assembly: Optional[ToolAssembly] = None) -> np.ndarray:
    """(n,) mm: how near the tool (its whole `assembly` when given) comes to the design point of each of `cells`
    ((n, 2) row, column on `grid`) when dropped anywhere within its radius of it, not only at the grid's positions:
    on a wall of slope a these lie cell / cos a apart along it (1.15 mm on an 80 deg wall at 0.2 mm: more than a
    D1), so the envelope of those alone cannot tell what the tool reaches there. A pattern search: FIRST_SAMPLES^2
    drops over the tool's width, then REFINE rounds of 5 x 5 around the nearest so far, each half the last's
    spacing; the distance is the 3D one from the point to the cutter's profile (profile_distance)."""
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    surface = surface or DropSurface(mesh)
    drop = AssemblyDrop(mesh, assembly, surface) if assembly is not None else None
    batches = [cells[k:k + NEAREST_BATCH] for k in range(0, len(cells), NEAREST_BATCH)]
    return np.concatenate([np.zeros(0)] + [pattern_search(mesh, cutter, grid, design, b, surface, drop)
                                           for b in batches])


def pattern_search(mesh: TriMesh, cutter: Cutter, grid: Grid, design: np.ndarray, cells: np.ndarray,
                   surface: DropSurface, drop: Optional[AssemblyDrop]) -> np.ndarray:
    """nearest_reach on one batch of cells (`drop`: the whole tool's, None for the cutter alone); the tips may go a
    radius under the model's lowest point (the planner's reach envelope: beyond a rim there)."""
    return nearest_positions(mesh, cutter, grid, design, cells, surface, drop)[0]


def nearest_positions(mesh: Optional[TriMesh], cutter: Cutter, grid: Grid, design: np.ndarray, cells: np.ndarray,
                      surface: DropSurface, drop: Optional[AssemblyDrop], floor: Optional[float] = None
                      ) -> tuple[np.ndarray, np.ndarray]:
    """(distances (n,), tips (n, 3)): the pattern search of nearest_reach on `cells`, with the tip where the tool
    comes nearest to each (a rest's touch-up goes there); `floor`: the lowest tip (None: a radius under the lowest
    point of `mesh`)."""
    if floor is None:
        floor = float(mesh.vertices[:, 2].min()) - float(cutter.native.max_radius)
    iy, ix = cells[:, 0], cells[:, 1]
    point = np.column_stack([grid.xs()[ix], grid.ys()[iy], design[iy, ix]])
    centre = point[:, :2].copy()
    best = np.full(len(cells), np.inf)
    best_tip = np.full(len(cells), np.nan)
    half, samples = float(cutter.native.max_radius), FIRST_SAMPLES
    rows = np.arange(len(cells))
    for _ in range(REFINE + 1):
        u = np.linspace(-half, half, samples)
        offsets = np.column_stack([np.repeat(u, samples), np.tile(u, samples)])
        xy = (centre[:, None, :] + offsets[None, :, :]).reshape(-1, 2)
        tip = surface.drop(cutter, xy, floor) if drop is None else drop.heights(xy, floor)[0]
        gap = profile_distance(cutter, point[:, None, :], xy.reshape(len(cells), -1, 2), tip.reshape(len(cells), -1))
        k = np.argmin(gap, axis=1)
        better = gap[rows, k] < best
        best = np.where(better, gap[rows, k], best)
        centre[better] = xy.reshape(len(cells), -1, 2)[rows, k][better]
        best_tip[better] = tip.reshape(len(cells), -1)[rows, k][better]
        half, samples = 2.0 * half / (samples - 1), 5   # the next round spans the last one's spacing each side
    return np.maximum(best, 0.0), np.column_stack([centre, best_tip])


def profile_distance(cutter: Cutter, point: np.ndarray, xy: np.ndarray, tip: np.ndarray) -> np.ndarray:
    """The 3D distance from `point` (.., 3) to the cutter's surface with its tip at (`xy`, `tip`): its flat bottom,
    its corner's torus (a ball: the sphere) or its flutes' side above the corner (negative inside the tool)."""
    outer = cutter.radius
    r = cutter.corner_radius
    rho = np.linalg.norm(point[..., :2] - xy, axis=-1)
    z = point[..., 2] - tip
    torus = np.hypot(np.maximum(rho - (outer - r), 0.0), z - r) - r
    side = np.where(z > r, rho - outer, torus)
    return np.where(rho < outer - r, -z, side)   # under the flat bottom: straight down from it
