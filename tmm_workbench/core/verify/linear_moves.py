"""3-axis moves as written, checked against the model: how far below the exact drop-cutter height the tool
passes on the straight line between two CL points (a ridge between two samples is cut into there). Reads
the tool path's points (or the G-code's, rounded as the post wrote them); vertical depth, which is never
less than the depth along the surface normal.
"""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter


def deepest_cut(surface: DropSurface, cutter: Cutter, points: np.ndarray, cutting: np.ndarray,
                step: float = 0.05) -> tuple[float, int]:
    """(deepest mm, index of the move) over the moves ending at points[i] where cutting[i], sampled every
    `step` mm along each move (ends excluded: they are dropped points)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    xy, z, owner = [], [], []
    for i in range(1, len(p)):
        if not cutting[i]:
            continue
        d = p[i] - p[i - 1]
        n = int(math.ceil(math.hypot(d[0], d[1]) / step))
        if n < 2:
            continue
        s = np.arange(1, n) / n
        seg = p[i - 1][None, :] + s[:, None] * d[None, :]
        xy.append(seg[:, :2])
        z.append(seg[:, 2])
        owner.append(np.full(len(s), i))
    if not xy:
        return 0.0, -1
    xy_all, z_all, who = np.vstack(xy), np.concatenate(z), np.concatenate(owner)
    floor = float(z_all.min()) - 1e3
    drop = surface.drop(cutter, xy_all, floor)
    cut = drop - z_all
    k = int(np.argmax(cut))
    return max(0.0, float(cut[k])), int(who[k])
