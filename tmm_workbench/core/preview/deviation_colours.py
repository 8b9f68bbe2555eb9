"""The colours of a simulated stock's deviation, shared by the heat map PNG (deviation_png) and the GUI's
coloured stock (gui/stock_view): RdBu_r with 0 mm at the centre (blue gouge, red material left), linear on
each side from at least -+tolerance, grey where there is no design; and the decimation of a heights grid
for drawing, keeping what matters in each block (numpy only)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

MAX_VERTICES_PER_SIDE = 400   # the mesh shown: a few 100k vertices draw fast, finer adds nothing visible
# grey where there is no design: darker than a light grey, which lighting makes look like RdBu_r's
# near-white centre (0 mm) on a lit face
NO_DESIGN_HEX = "#8c8c8c"
NO_DESIGN_RGB = tuple(int(NO_DESIGN_HEX[i:i + 2], 16) / 255.0 for i in (1, 3, 5))


def decimate(heights: np.ndarray, deviation: np.ndarray, tolerance: float,
             limit: int = MAX_VERTICES_PER_SIDE) -> tuple[np.ndarray, np.ndarray, int]:
    """(heights, deviation, block) at most `limit` x `limit`: each block of block x block cells is shown by one
    of its cells, the deepest gouge (beyond the tolerance) if any, else the largest |deviation| (so scallop
    crests stay), else (no design under the block) the lowest height."""
    ny, nx = heights.shape
    b = max(1, math.ceil(max(nx, ny) / limit))
    if b == 1:
        return heights, deviation, 1
    nby, nbx = math.ceil(ny / b), math.ceil(nx / b)
    H = np.full((nby * b, nbx * b), np.inf)
    D = np.full((nby * b, nbx * b), np.nan)
    H[:ny, :nx], D[:ny, :nx] = heights, deviation

    def blocks(a: np.ndarray) -> np.ndarray:
        return a.reshape(nby, b, nbx, b).transpose(0, 2, 1, 3).reshape(nby, nbx, b * b)
    Hb, Db = blocks(H), blocks(D)
    finite = np.isfinite(Db)
    low = np.where(finite, Db, np.inf)
    deepest = np.argmin(low, axis=2)
    largest = np.argmax(np.where(finite, np.abs(Db), -1.0), axis=2)
    gouge = np.take_along_axis(low, deepest[..., None], 2)[..., 0] < -tolerance
    pick = np.where(gouge, deepest, largest)
    pick = np.where(finite.any(axis=2), pick, np.argmin(Hb, axis=2))

    def take(a: np.ndarray) -> np.ndarray:
        return np.take_along_axis(a, pick[..., None], 2)[..., 0]
    return take(Hb), take(Db), b


def block_centres(start: float, cell: float, n: int, b: int) -> np.ndarray:
    """Centres of the blocks of `b` cells along one axis of `n` cells (the last block may be shorter)."""
    first = np.arange(0, n, b)
    last = np.minimum(first + b, n)
    return start + cell * (first + last) / 2.0


def colour_range(deviation: np.ndarray, tolerance: float) -> tuple[float, float]:
    """The colour map's ends, mm, as deviation_png's: at least +-tolerance, 0 at the centre."""
    d = deviation[np.isfinite(deviation)]
    low = min(-tolerance, float(d.min())) if d.size else -tolerance
    high = max(tolerance, float(d.max())) if d.size else tolerance
    if not low < 0.0 < high:  # a zero tolerance and no deviation: still a centred map
        low, high = min(low, -1e-6), max(high, 1e-6)
    return low, high


# inside a colour band the map's [0.1, 0.9] is used: its darkest ends mark the cells beyond the band
BAND_INSIDE = (0.1, 0.9)


def band_position(deviation: np.ndarray, band: float) -> np.ndarray:
    """Deviation -> place on the colour map for a band of +-`band` mm: 0 mm at 0.5, the band's ends at
    BAND_INSIDE, 0.0 below -band and 1.0 above +band (the extremes stand out, not scaled into the band)."""
    if not (math.isfinite(band) and band > 0):
        raise ValueError(f"colour band must be > 0 mm, got {band!r}")
    d = np.asarray(deviation, dtype=float)
    lo, hi = BAND_INSIDE
    t = 0.5 + 0.5 * (hi - lo) * np.clip(d / band, -1.0, 1.0)
    return np.where(d > band, 1.0, np.where(d < -band, 0.0, t))


def band_colours(deviation: np.ndarray, band: float) -> np.ndarray:
    """(n, 3) RGB in [0, 1] per deviation value (flattened) for a band of +-`band` mm: RdBu_r inside, its
    darkest ends beyond, grey where NaN."""
    d = np.asarray(deviation, dtype=float).ravel()
    rgb = cmap()(band_position(np.nan_to_num(d), band))[:, :3]
    rgb[~np.isfinite(d)] = NO_DESIGN_RGB
    return rgb


def beyond_band(deviation: np.ndarray, band: float) -> tuple[int, int, float, float]:
    """(cells above +band, cells below -band, largest, smallest deviation; 0.0 without design): the extremes
    a colour band shows only as its darkest ends."""
    d = np.asarray(deviation, dtype=float)
    d = d[np.isfinite(d)]
    if not d.size:
        return 0, 0, 0.0, 0.0
    return int(np.sum(d > band)), int(np.sum(d < -band)), float(d.max()), float(d.min())


def cmap() -> Any:
    """matplotlib's RdBu_r (imported here: no GUI backend at import)."""
    from matplotlib import colormaps

    return colormaps["RdBu_r"]


def normalised(deviation: np.ndarray, low: float, high: float) -> np.ndarray:
    """Deviation -> [0, 1] with 0 mm at 0.5, linear on each side (matplotlib's TwoSlopeNorm)."""
    d = np.asarray(deviation, dtype=float)
    t = np.where(d < 0, 0.5 * (1.0 - d / low), 0.5 * (1.0 + d / high))
    return np.clip(t, 0.0, 1.0)


def colours(deviation: np.ndarray, low: float, high: float) -> np.ndarray:
    """(n, 3) RGB in [0, 1] per deviation value (flattened): RdBu_r, grey where NaN."""
    d = np.asarray(deviation, dtype=float).ravel()
    rgb = cmap()(normalised(np.nan_to_num(d), low, high))[:, :3]
    rgb[~np.isfinite(d)] = NO_DESIGN_RGB
    return rgb
