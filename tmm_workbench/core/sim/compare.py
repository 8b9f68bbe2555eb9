"""The simulated stock against the design: per cell the vertical deviation (simulated height minus the
design's on the same vertical line; positive = material left, negative = gouge), its extremes and
percentiles, removed and remaining volume, overall and per region (boolean masks over the grid: selected
faces, seed 003's buckets). Deviations are measured vertically: on a wall of slope a the distance along the
surface normal is the vertical one times cos a (`slope_deg`, `normal_deviation`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Optional

import numpy as np

from tmm_workbench.core.sim.simulate import SimResult

PERCENTILES = (50, 90, 95, 99)


@dataclass
class DeviationStats:
    cells: int                      # cells compared (the design under them, the stock cut or not)
    max_left: float                 # largest deviation, mm (material left: the scallop); 0 if none
    min_deviation: float            # smallest, mm (negative: the deepest gouge)
    percentiles: dict               # {p: deviation at percentile p}
    remaining_volume: float         # mm^3 above the design
    gouge_volume: float             # mm^3 cut below the design
    gouge_cells: int                # cells below the design by more than the tolerance

    def as_dict(self) -> dict:
        return {"cells": self.cells, "max_left": self.max_left, "min_deviation": self.min_deviation,
                "percentiles": dict(self.percentiles), "remaining_volume": self.remaining_volume,
                "gouge_volume": self.gouge_volume, "gouge_cells": self.gouge_cells}


@dataclass
class Comparison:
    deviation: np.ndarray           # (ny, nx), NaN where there is no design under the cell
    tolerance: float
    overall: DeviationStats
    regions: dict = field(default_factory=dict)   # name -> DeviationStats
    removed_volume: float = 0.0

    @property
    def gouged(self) -> bool:
        return self.overall.gouge_cells > 0


def _stats(dev: np.ndarray, cell_area: float, tolerance: float) -> DeviationStats:
    d = dev[np.isfinite(dev)]
    if not d.size:
        return DeviationStats(0, 0.0, 0.0, {p: 0.0 for p in PERCENTILES}, 0.0, 0.0, 0)
    pct = np.percentile(d, PERCENTILES)
    return DeviationStats(int(d.size), max(0.0, float(d.max())), float(d.min()),
                          {p: float(v) for p, v in zip(PERCENTILES, pct)},
                          float(np.clip(d, 0, None).sum() * cell_area), float(-np.clip(d, None, 0).sum() * cell_area),
                          int(np.sum(d < -tolerance)))


def compare(result: SimResult, design: np.ndarray, tolerance: float = 0.01,
            regions: Optional[Mapping[str, np.ndarray]] = None) -> Comparison:
    """`design`: (ny, nx) design heights on the same grid, NaN where there is none (core.sim.stock
    .mesh_heights); `regions`: name -> (ny, nx) bool mask."""
    design = np.asarray(design, dtype=float)
    if design.shape != result.heights.shape:
        raise ValueError(f"design heights have shape {design.shape}, the simulation {result.heights.shape}")
    dev = result.heights - design
    area = result.grid.cell_area
    out = Comparison(dev, tolerance, _stats(dev, area, tolerance), removed_volume=result.removed_volume)
    for name, mask in (regions or {}).items():
        out.regions[name] = _stats(np.where(mask, dev, np.nan), area, tolerance)
    return out


def slope_deg(design: np.ndarray, cell: float) -> np.ndarray:
    """(ny, nx) slope of the design from the horizontal, degrees, by central differences of its heights
    (cells without design take its lowest height: a wall where the design ends). A vertical deviation is
    the distance along the design's normal divided by cos of this slope."""
    finite = np.isfinite(design)
    filled = np.where(finite, design, design[finite].min() if finite.any() else 0.0)
    # a grid one cell wide has no slope across it (np.gradient needs two cells)
    gy = np.gradient(filled, cell, axis=0) if filled.shape[0] > 1 else np.zeros_like(filled)
    gx = np.gradient(filled, cell, axis=1) if filled.shape[1] > 1 else np.zeros_like(filled)
    return np.degrees(np.arctan(np.hypot(gx, gy)))


STEEP_DEG = 45.0     # a wall: its vertical deviation is over 1.4 times the one along its normal
STEEP_SHARE = 0.02   # a design with this share of its cells on walls reads better along the normal


def slope_cosine(design: np.ndarray, cell: float) -> np.ndarray:
    """(ny, nx) cos of the design's slope from its heights' central differences: 1 where a neighbour has no
    design (no slope known there: the vertical deviation is kept)."""
    z = np.asarray(design, dtype=float)
    gy = np.gradient(z, cell, axis=0) if z.shape[0] > 1 else np.zeros_like(z)
    gx = np.gradient(z, cell, axis=1) if z.shape[1] > 1 else np.zeros_like(z)
    cos = 1.0 / np.sqrt(1.0 + gx * gx + gy * gy)
    return np.where(np.isfinite(cos), cos, 1.0)


def normal_deviation(deviation: np.ndarray, design: np.ndarray, cell: float) -> np.ndarray:
    """The deviation along the design's normal, estimated from the vertical one: on a plane of slope a the
    distance along the normal is the vertical one times cos a (a wall's +2 mm vertical is a few µm normal)."""
    return np.asarray(deviation, dtype=float) * slope_cosine(design, cell)


def has_steep_walls(design: np.ndarray, cell: float) -> bool:
    """Whether at least STEEP_SHARE of the design's cells slope more than STEEP_DEG: where the vertical
    deviation misleads."""
    finite = np.isfinite(np.asarray(design, dtype=float))
    if not finite.any():
        return False
    steep = slope_cosine(design, cell) < np.cos(np.radians(STEEP_DEG))
    return float(np.sum(steep & finite)) >= STEEP_SHARE * float(finite.sum())
