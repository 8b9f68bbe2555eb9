"""The spiral footprint (seed 003's "parallel spiral" idea, as an Archimedean spiral): r = stepover * turns
from the machining region's centre (the centroid of its area) out to its farthest vertex, sampled at most
`sample_step` apart along the curve (and at most 22.5 deg apart round the centre), clipped to the region.
Inward: the same curve cut from the outside in.

Consecutive turns are `stepover` apart along every ray from the centre, so every point of the region is
within stepover / 2 of the curve (measured along the ray; the curve's own points are no farther apart
than sample_step).
"""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.polygons import Shape

_CHUNK = 4000          # points per Clipper call: the pieces of a chunk are put back in curve order cheaply
_MAX_TURN = math.pi / 8


def centre_of(shape: Shape) -> np.ndarray:
    """The centroid of the region's area (holes subtracted)."""
    total, moment = 0.0, np.zeros(2)
    for p in shape:
        q = np.roll(p, -1, axis=0)
        cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
        total += 0.5 * float(cross.sum())
        moment += ((p + q) * cross[:, None]).sum(axis=0) / 6.0
    if abs(total) <= 1e-12:
        raise TmmError("the machining region has no area")
    return moment / total


def spiral_length(r_max: float, stepover: float) -> float:
    """Length of the spiral from its centre out to radius r_max, mm."""
    b = stepover / (2 * math.pi)
    t = r_max / b
    return 0.5 * b * (t * math.sqrt(1 + t * t) + math.asinh(t))


def spiral_points(centre: np.ndarray, r_max: float, stepover: float, sample_step: float) -> np.ndarray:
    """(n, 2) points of r = b theta (b = stepover / 2 pi) from the centre out to r_max."""
    b = stepover / (2 * math.pi)
    t_max = r_max / b
    s = np.append(np.arange(0.0, spiral_length(r_max, stepover), sample_step), spiral_length(r_max, stepover))
    theta = np.minimum(s / b, np.sqrt(2 * s / b))  # above the root: Newton from there falls monotonically
    for _ in range(60):
        f = 0.5 * b * (theta * np.sqrt(1 + theta * theta) + np.arcsinh(theta)) - s
        step = f / (b * np.sqrt(1 + theta * theta))
        theta = theta - step
        if np.max(np.abs(step)) < 1e-12 * max(1.0, t_max):
            break
    limit = math.sqrt(max(0.0, (sample_step / (b * _MAX_TURN)) ** 2 - 1.0))  # below it the angle step is larger
    theta = np.union1d(np.clip(theta, 0.0, t_max), np.arange(0.0, min(limit, t_max), _MAX_TURN))
    r = b * theta
    return np.column_stack([centre[0] + r * np.cos(theta), centre[1] + r * np.sin(theta)])


def _params(points: np.ndarray, curve: np.ndarray, cum: np.ndarray) -> np.ndarray:
    """Arc-length parameters on the polyline `curve` of points lying on it."""
    a, b = curve[:-1], curve[1:]
    ab = b - a
    ll = np.maximum((ab * ab).sum(axis=1), 1e-300)
    out = np.empty(len(points))
    for k, p in enumerate(points):
        t = np.clip(((p - a) * ab).sum(axis=1) / ll, 0.0, 1.0)
        d = np.hypot(*(a + t[:, None] * ab - p).T)
        i = int(np.argmin(d))
        out[k] = cum[i] + t[i] * math.sqrt(ll[i])
    return out


def clip_curve(curve: np.ndarray, shape: Shape) -> list[np.ndarray]:
    """The pieces of the polyline `curve` inside `shape`, each in the curve's direction, in curve order
    (Clipper clips open paths exactly to its 1 nm grid; it does not keep their direction, so each piece is
    put back by where its ends lie on the curve)."""
    out: list[np.ndarray] = []
    for start in range(0, max(1, len(curve) - 1), _CHUNK):
        chunk = curve[start:start + _CHUNK + 1]
        if len(chunk) < 2:
            break
        pieces = polygons.clip_open([chunk], shape)
        if not pieces:
            continue
        cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(chunk, axis=0).T))])
        ends = _params(np.array([q for p in pieces for q in (p[0], p[-1])]), chunk, cum).reshape(-1, 2)
        order = np.argsort(ends.min(axis=1))
        for k in order:
            p = pieces[k] if ends[k, 0] <= ends[k, 1] else pieces[k][::-1]
            if out and np.hypot(*(out[-1][-1] - p[0])) <= 1e-5:
                out[-1] = np.vstack([out[-1], p[1:]])       # the same piece across a chunk border
            else:
                out.append(p)
    return [p for p in out if float(np.hypot(*np.diff(p, axis=0).T).sum()) > 1e-6]


def spiral_pieces(shape: Shape, stepover: float, sample_step: float, inward: bool = False) -> list[np.ndarray]:
    """The spiral footprint of the region: its pieces inside the region in cutting order."""
    centre = centre_of(shape)
    r_max = float(np.hypot(*(np.vstack(shape) - centre).T).max()) + 1e-6  # raster_region.spiral_radius
    pieces = clip_curve(spiral_points(centre, r_max, stepover, sample_step), shape)
    if inward:
        pieces = [p[::-1] for p in pieces[::-1]]
    return pieces
