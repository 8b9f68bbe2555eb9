"""The Surface's second stage, positioning: the pattern's runs of XY points (core.strategies.surface.pattern)
dropped on the mesh in one batch (Positioner: stock to leave, the floor, air where the tool is over no part of the
model with off-model "skip"), points inserted where a straight move between two would pass below the drop height
or leave more than the cusp modes allow (core.strategies.raster_refine), and the points outside the slope range
flagged as air (core.strategies.raster_region.slope_flags)."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.stage import Field, Stage
from tmm_workbench.core.strategies.surface.params import (OFF_MODEL_FLOOR, OFF_MODEL_SKIP, SPIRAL, ZIGZAG,
                                                          SurfaceParams)
from tmm_workbench.core.strategies.surface.pattern import Run
from tmm_workbench.core.tools.cutter import Cutter

if TYPE_CHECKING:
    from tmm_workbench.core.strategies.lean_kernel import ExactDrop

_AIR_DEPTH_MM = 1e6  # SKIP drops onto a floor this far below the model: only air points end there


class Positioner:
    """Tip heights (on the floor at least) and air flags of the cutter dropped at XY points, as the raster drops
    them (`drop`, called); `exact` the same drop for the lean passes' kernel (core.strategies.lean_kernel)."""

    def __init__(self, mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: SurfaceParams,
                 floor_z: float) -> None:
        self.surface, self.cutter, self.floor_z = surface, cutter, floor_z
        self.stock = params.stock_to_leave
        self.skip = params.off_model == OFF_MODEL_SKIP
        self.air_floor = float(mesh.bounds[0][2]) - _AIR_DEPTH_MM

    def __call__(self, points: np.ndarray, report: Optional[Progress] = None) -> tuple[np.ndarray, np.ndarray]:
        s = self.stock
        zz = self.surface.drop(self.cutter.offset(s), points, (self.air_floor if self.skip else self.floor_z) - s,
                               report) + s
        aa = zz <= self.air_floor + 1.0 if self.skip else np.zeros(len(zz), dtype=bool)
        return np.maximum(zz, self.floor_z), aa

    def exact(self) -> ExactDrop:
        from tmm_workbench.core.strategies.lean_kernel import ExactDrop

        s = self.stock
        return ExactDrop(self.surface.index, self.cutter.offset(s), (self.air_floor if self.skip else self.floor_z) - s,
                         s, self.floor_z, self.air_floor + 1.0 if self.skip else -math.inf)


def position(runs: list[Run], passes: int, drop: Positioner, cutter: Cutter, params: SurfaceParams, leave: float,
             diagnostics: dict, progress: Optional[Progress]) -> tuple[list[Run], np.ndarray, np.ndarray]:
    """The runs dropped (see the module): (runs, z, air), the runs with the points refinement added. `leave` the
    share of the cusp a move may pass above the exact drop height (inf: not checked). diagnostics: "points",
    "passes", "between" (raster_refine's), "slope_filtered", "top" (the highest tip on the model)."""
    xy = np.concatenate([r for _, r in runs])
    z, air = drop(xy, progress)
    if air.all():
        raise TmmError("the cutter is over no part of the model anywhere in the boundary (off-model: skip)")
    diagnostics.update(points=len(xy), passes=passes)
    if params.gouge_tol > 0 or math.isfinite(leave):
        from tmm_workbench.core.strategies import raster_refine

        runs, z, air, diagnostics["between"] = raster_refine.refine(
            runs, z, air, drop, params.gouge_tol or math.inf, chained=params.pattern in (ZIGZAG, SPIRAL),
            leave_tol=leave)
    if params.slope_min_deg > 0 or params.slope_max_deg < 90:
        from tmm_workbench.core.strategies import raster_region

        air = raster_region.slope_flags(runs, z, air, drop, cutter, params, diagnostics)
    diagnostics["top"] = float(z[~air].max())
    return runs, z, air


# --- the stage's declaration (core.stage) ---------------------------------------------------------------------
OFF_MODEL = {"Floor": OFF_MODEL_FLOOR, "Skip": OFF_MODEL_SKIP}
STAGE = Stage("positioning", (
    Field("SampleStep", "length", "Surface", "Sampling step along a pass", "sample_step", "sample_step",
          widget="sampleStep"),
    Field("StockToLeave", "length", "Surface", "Material left on the surface", "stock_to_leave", "stock_to_leave",
          widget="stockToLeave"),
    Field("OffModel", "choice", "Surface",
          "Where no part of the model is under the tool (beside an open surface, in a hole): Floor cuts along the "
          "floor (the model's lowest point); Skip lifts over it and cuts only over the model", "off_model",
          "off_model", choices=OFF_MODEL, widget="offModel"),
))
