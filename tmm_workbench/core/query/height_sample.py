"""A coarse view of the model for estimates: the cutter's tip heights on a grid over a box (at most a few
thousand drops, milliseconds), from which an estimate reads the slopes its passes will climb and the spacing a
cusp rule will ask for, without computing a path. Off the model the tip rests on the floor (a flat)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter

CELLS = 80   # grid nodes along the box's longer side


@dataclass(frozen=True)
class HeightSample:
    """Tip heights z[j, i] of a cutter at (xs[i], ys[j]), a grid `step` apart."""
    xs: np.ndarray
    ys: np.ndarray
    z: np.ndarray

    @property
    def step(self) -> float:
        return float(self.xs[1] - self.xs[0]) if len(self.xs) > 1 else 0.0

    def inside(self, shape: Optional[polygons.Shape]) -> np.ndarray:
        """(ny, nx) bool: the nodes in `shape` (None: all)."""
        if shape is None:
            return np.ones(self.z.shape, dtype=bool)
        return polygons.grid_inside(shape, self.xs, self.ys)

    def slopes(self, angle_deg: float) -> tuple[np.ndarray, np.ndarray]:
        """(along, across): tan of the tip surface's slope along passes at `angle_deg` from +X and across them
        (absolute values, (ny, nx) each)."""
        s = max(self.step, 1e-9)
        gy, gx = np.gradient(self.z, s, s) if min(self.z.shape) > 1 else (np.zeros_like(self.z),) * 2
        c, n = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
        return np.abs(gx * c + gy * n), np.abs(-gx * n + gy * c)

    def curvature(self, angle_deg: float) -> np.ndarray:
        """(ny, nx): the curvature (1/mm) of the tip surface's section across passes at `angle_deg`, positive
        where it is concave (a valley), negative where convex."""
        s = max(self.step, 1e-9)
        if min(self.z.shape) < 3:
            return np.zeros_like(self.z)
        gy, gx = np.gradient(self.z, s, s)
        gyy, gyx = np.gradient(gy, s, s)
        gxy, gxx = np.gradient(gx, s, s)
        c, n = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
        # across the passes: the direction (-n, c)
        slope = -gx * n + gy * c
        second = gxx * n * n - (gxy + gyx) * n * c + gyy * c * c
        return second / (1.0 + slope ** 2) ** 1.5


def sample_heights(surface: DropSurface, cutter: Cutter, box: Sequence[float], floor_z: float,
                   cells: int = CELLS) -> HeightSample:
    """The cutter dropped on a grid over the XY `box` (xmin, ymin, xmax, ymax) with `cells` nodes along its
    longer side, from `floor_z`."""
    x0, y0, x1, y1 = (float(v) for v in box)
    step = max(x1 - x0, y1 - y0, 1e-6) / max(cells - 1, 1)
    xs = x0 + step * np.arange(max(int(math.ceil((x1 - x0) / step)) + 1, 2))
    ys = y0 + step * np.arange(max(int(math.ceil((y1 - y0) / step)) + 1, 2))
    gx, gy = np.meshgrid(xs, ys)
    z = surface.drop(cutter, np.column_stack([gx.ravel(), gy.ravel()]), floor_z, threads=1)
    return HeightSample(xs, ys, z.reshape(gx.shape))
