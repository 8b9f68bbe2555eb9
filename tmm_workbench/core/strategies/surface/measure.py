"""The Surface's cusp measurement, the strategy's side of it: the measuring cell for a cusp height (measure_cell),
the dense raster's parameters (dense_params) and its envelope cut into the stock simulation (dense_raster: the
reference core.sim.cusp_field measures a pass set against, made by the raster strategy passed in), and the
measurement's work estimate (estimate_work). The verification (variable_step) and the check (cusp_check) measure
with them."""
from __future__ import annotations

from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.geometry.rect import Rect
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.sim.cusp_field import DenseRaster, measure_grid_size
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.strategies.surface.params import _BYTES_PER_POINT, SurfaceParams, raster_points
from tmm_workbench.core.tools.cutter import Cutter

# raster_drop.compute: (mesh, cutter, params, progress, surface) -> StrategyResult
Compute = Callable[[TriMesh, Cutter, SurfaceParams, Optional[Progress], Optional[DropSurface]], Any]
_CELLS_PER_STEP = 8     # the measuring cell: the planar step-over for the tolerance / 8 (0.06 mm for D6, 0.01)
_MIN_CELL, _MAX_CELL = 0.02, 1.0


def measure_cell(cutter: Cutter, tolerance: float) -> float:
    """The simulation cell for `tolerance`: an eighth of the planar step-over (0.06 mm for a ball D6 at 0.01 mm)."""
    return float(np.clip(stepover_for_cusp(cutter, tolerance, 0.0) / _CELLS_PER_STEP, _MIN_CELL, _MAX_CELL))


def dense_params(boundary: Rect, cutter: Cutter, cell: float, sample_step: float,
                 stock_to_leave: float = 0.0) -> SurfaceParams:
    """The dense raster's parameters: passes a cell apart over `boundary` grown by the tool radius across."""
    r = cutter.radius
    return SurfaceParams(boundary=(boundary[0], boundary[1] - r, boundary[2], boundary[3] + r), stepover=cell,
                         sample_step=sample_step, stock_to_leave=stock_to_leave)


def dense_raster(compute: Compute, mesh: TriMesh, cutter: Cutter, boundary: Rect, sample_step: float,
                 stock_to_leave: float = 0.0) -> DenseRaster:
    """The envelope core.sim.cusp_field.cusp_field measures against: the raster `compute` makes with passes a grid
    cell apart (dense_params, points `sample_step` apart), linked and cut into the box stock."""
    def envelope(grid: Grid, surface: DropSurface, stock_top: float, progress: Optional[Progress]) -> np.ndarray:
        dense = compute(mesh, cutter, dense_params(boundary, cutter, grid.cell, sample_step, stock_to_leave),
                        progress, surface)
        path = link(dense.segments, LinkPolicy(stock_top, stock_top + 5))
        return simulate(path, cutter, grid, box_heights(grid, stock_top)).heights

    return envelope


def estimate_work(boundary: Rect, cutter: Cutter, tolerance: float, cell: float, what: str = "verify cusp") -> float:
    """The measurement's CL points: the dense raster (a cell apart both ways, over the boundary grown by the tool
    radius across: core.sim.cusp_field) and the design dropped on every cell, refused above the limits before
    anything runs."""
    nx, ny = measure_grid_size(boundary, cutter, cell)
    count = raster_points(dense_params(boundary, cutter, cell, cell)) + nx * ny
    check_work("CL points", count, _BYTES_PER_POINT,
               f"{what}: cusp height {tolerance:g} mm measured on {cell:.3g} mm cells (the planar step-over / "
               f"{_CELLS_PER_STEP}, at least {_MIN_CELL:g} mm) over a {boundary[2] - boundary[0]:.6g} x "
               f"{boundary[3] - boundary[1]:.6g} mm boundary")
    return count
