"""The simulated cusp of a 3-axis pass set against the raster strategy's own dense raster: core.sim.cusp_field's
measurement with its reference made here, above the strategy (core.strategies.raster_drop), for the tests and
the benchmarks (the op's own check, core.strategies.surface.variable_step, puts the same pieces together)."""
from __future__ import annotations

from typing import Optional

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.geometry.rect import Rect
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.sim import cusp_field as field
from tmm_workbench.core.sim.cusp_field import SLOPE_LIMIT_DEG, CuspField
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.strategies.raster_drop import compute
from tmm_workbench.core.strategies.surface.measure import dense_raster
from tmm_workbench.core.tools.cutter import Cutter


def cusp_field(mesh: TriMesh, cutter: Cutter, boundary: Rect, tolerance: float, cell: float,
               slope_limit_deg: float = SLOPE_LIMIT_DEG, sample_step: float = 0.25, stock_to_leave: float = 0.0,
               surface: Optional[DropSurface] = None, grid: Optional[Grid] = None,
               progress: Optional[Progress] = None, fast_envelope: bool = False) -> CuspField:
    """The field for rasters over `boundary` (xmin, ymin, xmax, ymax) with `cutter` (core.sim.cusp_field); `cell`
    is the simulation's cell and the dense raster's step-over, `sample_step` its points' spacing along its
    passes. With `stock_to_leave` the dense raster leaves it too, and a cell is reachable when the envelope comes
    within tolerance + stock_to_leave of the design. `fast_envelope`: the dense raster as one batch drop on its
    grid of points (core.sim.cusp_field.grid_envelope: several times faster than through the strategy and the
    linker)."""
    dense = None if fast_envelope else dense_raster(compute, mesh, cutter, boundary, sample_step, stock_to_leave)
    return field.cusp_field(mesh, cutter, boundary, tolerance, cell, slope_limit_deg, stock_to_leave, surface, grid,
                            progress, fast_envelope, dense)
