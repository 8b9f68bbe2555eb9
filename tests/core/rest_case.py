"""A rest's starting point for the core tests: a model finished with a ball D10 raster (cusp 0.01 mm) on a box,
simulated on a grid, and the rest of a smaller tool over it (core.footprint.rest)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tmm_workbench.core.footprint import rest
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

D10 = Cutter.ball(10)


@dataclass
class Finished:
    grid: Grid
    design: np.ndarray
    left: np.ndarray        # what the D10 left
    envelope: np.ndarray    # the small tool's
    area: rest.RestArea


def after_d10(mesh: TriMesh, box: tuple, cell: float, small: Cutter, stock_top: float, safe: float,
              tol: float = 0.01) -> Finished:
    grid = Grid.covering(*box, cell)
    finish = raster_drop.compute_surface_toolpath(
        mesh, D10, SurfaceParams(boundary=box, stepover=2 * math.sqrt(2 * 5.0 * tol), sample_step=0.25),
        LinkPolicy(safe, safe + 2.0))
    left = simulate(finish, D10, grid, box_heights(grid, stock_top)).heights
    design = mesh_heights(mesh, grid)
    envelope = rest.tool_envelope(mesh, small, grid)
    return Finished(grid, design, left, envelope, rest.rest_area(left, design, envelope, grid, tol, small.radius))
