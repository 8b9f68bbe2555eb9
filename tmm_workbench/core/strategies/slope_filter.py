"""Slope range filter for 3-axis finishing: keep only the CL points where the surface's
slope lies in [low, high] deg, so steep areas can be left to waterline and shallow ones to the raster.

The slope is that of the drop height z(x, y) (the CL surface), by central differences of the cutter
dropped `h` mm either side in X and in Y: for a ball the CL surface is the offset surface, whose normal at
a CL point is the model's normal at the contact point, so this is the contact slope; for other cutters it
is the slope the tool centre follows. Points out of range are treated like air (the pass is split there,
the tool lifts over them; a link through one is left out), and kept pieces shorter than `min_length`
(the tool radius by default: a dab, not a cut) are dropped too.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

Drop = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # xy (n, 2) -> (z (n,), air (n,) bool)
FULL_RANGE = (0.0, 90.0)


def active(low: float, high: float) -> bool:
    return (low, high) != FULL_RANGE


def slopes_deg(xy: np.ndarray, drop: Drop, h: float) -> np.ndarray:
    """(n,) slope of the drop height at each XY, degrees (NaN where a neighbour is in air)."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    n = len(xy)
    offsets = np.array([[h, 0.0], [-h, 0.0], [0.0, h], [0.0, -h]])
    z, air = drop((xy[None, :, :] + offsets[:, None, :]).reshape(-1, 2))
    z, air = z.reshape(4, n), air.reshape(4, n)
    gx, gy = (z[0] - z[1]) / (2 * h), (z[2] - z[3]) / (2 * h)
    out = np.degrees(np.arctan(np.hypot(gx, gy)))
    out[air.any(axis=0)] = math.nan
    return out


def out_of_range(runs: list[tuple[bool, np.ndarray]], slope: np.ndarray, air: np.ndarray, low: float, high: float,
                 min_length: float) -> np.ndarray:
    """(n,) flags (flattened as the runs): air, a slope outside [low, high], or in a kept piece of a pass
    shorter than `min_length` mm."""
    flag = air | ~((slope >= low - 1e-9) & (slope <= high + 1e-9))
    k = 0
    for is_link, xy in runs:
        m = len(xy)
        if not is_link and m:
            f = flag[k:k + m]
            s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
            edges = np.flatnonzero(np.diff(np.concatenate([[True], f, [True]]).astype(np.int8)))
            for a, b in zip(edges[::2], edges[1::2]):
                if s[b - 1] - s[a] < min_length:
                    f[a:b] = True
        k += m
    return flag
