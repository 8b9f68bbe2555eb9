"""Stock for the simulation as heights per cell: a box top, a cylinder (cells outside the circle hold no
stock), or the top of a mesh (a height field: the highest point of the mesh on each cell's vertical line);
and the same vertical-line heights of a design model, to compare the simulated stock with."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.tools.cutter import Cutter

# mm: the "cutter" whose drop is a vertical line's hit (a flat disc this small). It finds the highest point within
# its radius, so on a wall of slope a the design comes out r tan(a) high: with 1e-4 mm the walls of mount_rush's
# relief (81-88 deg) read 0.001-0.0035 mm high and a path within 0.0009 mm of the exact CL path showed a 0.0044 mm
# "gouge" there; at 1e-6 mm it is below 1e-4 mm up to 89.4 deg (the drop is as robust at this size).
NEEDLE_RADIUS = 1e-6


def box_heights(grid: Grid, top: float) -> np.ndarray:
    if not math.isfinite(top):
        raise TmmError(f"stock top must be finite, got {float(top)!r}")
    return np.full((grid.ny, grid.nx), float(top))


def cylinder_heights(grid: Grid, centre: tuple[float, float], radius: float, top: float, bottom: float
                     ) -> np.ndarray:
    """A vertical cylinder stock: `top` inside the circle, `bottom` (no stock) outside."""
    if not (math.isfinite(radius) and radius > 0):
        raise TmmError(f"cylinder stock radius must be a length > 0 mm, got {float(radius)!r}")
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    inside = (X - centre[0]) ** 2 + (Y - centre[1]) ** 2 <= radius * radius
    return np.where(inside, float(top), float(bottom))


_BLOCK_CELLS = 250_000  # cells per needle batch (about 0.1-0.3 s)


def op_within(params: object) -> float:
    """How near the mesh's heights an op's material is the design's (without a rest's design): the stock to
    leave (not below 0) and what the op's own cuts leave on it (its chord tolerance)."""
    return max(float(getattr(params, "stock_to_leave", 0.0)), 0.0) + float(getattr(params, "chord_tol", 0.0))


def mesh_heights(mesh: TriMesh, grid: Grid, surface: DropSurface | None = None, progress=None,
                 threads: int = 0) -> np.ndarray:
    """(ny, nx) highest point of the mesh on each cell centre's vertical line (a disc of NEEDLE_RADIUS
    dropped: higher by at most tan(slope) x NEEDLE_RADIUS); NaN where the line misses the mesh."""
    floor = float(mesh.vertices[:, 2].min()) - 1.0
    surface = surface or DropSurface(mesh)
    needle = Cutter.flat(2 * NEEDLE_RADIUS)
    # in blocks of rows: the needle's batch is one long kernel call otherwise, seconds before a cancel is seen
    rows = max(1, _BLOCK_CELLS // grid.nx)
    xs, ys = grid.xs(), grid.ys()
    z = np.empty((grid.ny, grid.nx))
    for j0 in range(0, grid.ny, rows):
        block = ys[j0:j0 + rows]
        X, Y = np.meshgrid(xs, block)
        part = None if progress is None else (lambda f, j0=j0, k=len(block): progress((j0 + f * k) / grid.ny))
        z[j0:j0 + len(block)] = surface.drop(needle, np.column_stack([X.ravel(), Y.ravel()]), floor, part,
                                             threads).reshape(len(block), grid.nx)
    return np.where(z > floor + 0.5, z, np.nan)
