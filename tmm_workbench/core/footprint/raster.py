"""Footprints: where the cutter goes in XY before it is dropped on the surface."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.rect import Rect  # noqa: F401 - the footprints' rectangle


EVEN, FIXED = "even", "fixed"


def raster_lines(boundary: Rect, stepover: float, angle_deg: float = 0.0, spacing: str = EVEN) -> list[np.ndarray]:
    """Parallel passes at `angle_deg` from +X, clipped to the rectangle `boundary`.

    Returns one (2, 2) array [start, end] per pass, all running the same way, ordered across the
    rectangle. The first and last passes lie on the boundary so the whole rectangle is covered.
    spacing EVEN: the passes spread evenly, at most `stepover` apart. FIXED: exactly `stepover` apart from
    the side of the rectangle nearest its (xmin, ymin) corner, the last strip narrower (seed 001's footprint:
    x = 0, 18, ..., 144 and 150).
    """
    if spacing not in (EVEN, FIXED):
        raise TmmError(f"pass spacing must be '{EVEN}' or '{FIXED}', got {spacing!r}")
    xmin, ymin, xmax, ymax = boundary
    if not (xmax > xmin and ymax > ymin):
        raise TmmError(f"boundary is empty: x {xmin:g}..{xmax:g}, y {ymin:g}..{ymax:g}")
    if not (math.isfinite(stepover) and stepover > 0):
        raise TmmError(f"step-over must be a positive length, got {stepover!r}")
    a = math.radians(angle_deg)
    d = np.array([math.cos(a), math.sin(a)])       # along the pass
    n = np.array([-math.sin(a), math.cos(a)])      # across the passes
    corners = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]])
    across = corners @ n
    lo, hi = across.min(), across.max()
    count = pass_count(hi - lo, stepover)
    if count > 200000:
        raise TmmError(f"step-over {stepover:g} mm gives {count} passes over the boundary: too many")
    if spacing == EVEN:
        offsets = np.linspace(lo, hi, count)
    else:  # from the corner's side; a pass closer than 1e-9 mm to the far edge is that edge's
        corner = np.array([xmin, ymin]) @ n
        start, end = (lo, hi) if abs(corner - lo) <= abs(corner - hi) else (hi, lo)
        steps = np.arange(count - 1) * stepover
        inside = steps[steps < (hi - lo) - 1e-9]
        offsets = np.concatenate([start + math.copysign(1.0, end - start) * inside, [end]])
    lines = []
    for c in offsets:
        seg = clip_line_to_rect(c * n, d, boundary)
        if seg is not None:
            lines.append(seg)
    return lines


def pass_count(width: float, stepover: float) -> int:
    """Passes at most `stepover` apart across `width`, both edges included (>= 2)."""
    return max(1, math.ceil(width / stepover - 1e-9)) + 1


def clip_line_to_rect(p: np.ndarray, d: np.ndarray, r: Rect) -> np.ndarray | None:
    """The part of the line p + t d inside the rectangle (Liang-Barsky), or None."""
    t0, t1 = -math.inf, math.inf
    for k, (lo, hi) in enumerate(((r[0], r[2]), (r[1], r[3]))):
        if abs(d[k]) < 1e-15:
            if p[k] < lo - 1e-9 or p[k] > hi + 1e-9:
                return None
            continue
        ta, tb = (lo - p[k]) / d[k], (hi - p[k]) / d[k]
        t0, t1 = max(t0, min(ta, tb)), min(t1, max(ta, tb))
    if t1 - t0 <= 1e-9:
        return None
    return np.array([p + t0 * d, p + t1 * d])


def sample_segment(start: np.ndarray, end: np.ndarray, step: float) -> np.ndarray:
    """Points from start to end (both included) no more than `step` apart, (k, 2)."""
    length = float(np.linalg.norm(end - start))
    k = max(1, math.ceil(length / step - 1e-9))
    t = np.linspace(0.0, 1.0, k + 1)[:, None]
    return start[None, :] * (1 - t) + end[None, :] * t
