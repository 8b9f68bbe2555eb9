"""The simulation grid: square cells over an XY box, a height per cell centre (the kernel's ZMap layout:
row j, column i, centre (x0 + (i + 1/2) cell, y0 + (j + 1/2) cell)). Sized and checked against the work
limits before anything is allocated."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.limits import check_work

# heights of the stock, the initial stock and the design, the deviation, and a mask: what a simulation
# holds per cell at its peak (8-byte floats)
BYTES_PER_CELL = 5 * 8


@dataclass(frozen=True)
class Grid:
    x0: float
    y0: float
    cell: float
    nx: int
    ny: int

    @classmethod
    def covering(cls, xmin: float, ymin: float, xmax: float, ymax: float, cell: float) -> "Grid":
        """The grid of `cell` mm cells covering the box; TmmError naming the cell size when it is not a
        length > 0 or the grid is more than the machine can hold."""
        if not (isinstance(cell, (int, float)) and math.isfinite(cell) and cell > 0):
            shown = float(cell) if isinstance(cell, (int, float)) else cell  # numpy 2 repr: np.float64(...)
            raise TmmError(f"simulation cell size must be a length > 0 mm, got {shown!r}")
        for name, v in (("xmin", xmin), ("ymin", ymin), ("xmax", xmax), ("ymax", ymax)):
            if not math.isfinite(float(v)):
                raise TmmError(f"simulation box {name} must be finite, got {float(v)!r}")
        if not (xmax > xmin and ymax > ymin):
            raise TmmError(f"simulation box is empty: x {xmin:g}..{xmax:g}, y {ymin:g}..{ymax:g} mm")
        nx = max(1, math.ceil((xmax - xmin) / cell - 1e-9))
        ny = max(1, math.ceil((ymax - ymin) / cell - 1e-9))
        check_work("simulation cells", float(nx) * ny, BYTES_PER_CELL,
                   f"cell size {cell:g} mm over {xmax - xmin:g} x {ymax - ymin:g} mm ({nx} x {ny})")
        return cls(float(xmin), float(ymin), float(cell), int(nx), int(ny))

    @property
    def cell_area(self) -> float:
        return self.cell * self.cell

    def xs(self) -> np.ndarray:
        return self.x0 + (np.arange(self.nx) + 0.5) * self.cell

    def ys(self) -> np.ndarray:
        return self.y0 + (np.arange(self.ny) + 0.5) * self.cell

    def centres(self) -> np.ndarray:
        """(ny * nx, 2) cell centres, row-major (the order of the heights' ravel())."""
        X, Y = np.meshgrid(self.xs(), self.ys())
        return np.column_stack([X.ravel(), Y.ravel()])

    @property
    def extent(self) -> tuple[float, float, float, float]:
        return self.x0, self.x0 + self.nx * self.cell, self.y0, self.y0 + self.ny * self.cell
