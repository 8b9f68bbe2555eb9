"""How deep the tool cuts into a face along a motion: tool instances (tip, axis) checked against the face
densely sampled, by the kernel's exact signed distance to the tool solid (the multipoint positioner's
`tool_distance`: the torus, its core or the shank as positioned). Used between multipoint positions (the
straight tip line, the axis by slerp) and on the motion a machine makes from the G-code (machine_view).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.geometry.face import BezierFace

_CELL_MM = 4.0


@dataclass
class FaceSamples:
    """Points on a face at most `spacing` apart in parameter-scaled steps, bucketed in XY cells."""
    points: np.ndarray       # (n, 3)
    spacing: float
    origin: np.ndarray       # (2,) of the cell grid
    cells: dict              # (i, j) -> indices

    @classmethod
    def of(cls, face: BezierFace, spacing: float = 0.5) -> "FaceSamples":
        x0, y0, x1, y1 = face.xy_extent()
        count = int(min(2000, max(16, math.ceil(max(x1 - x0, y1 - y0) / spacing))))
        u0, u1, v0, v1 = face.domain
        U, V = np.meshgrid(np.linspace(u0, u1, count + 1), np.linspace(v0, v1, count + 1), indexing="ij")
        pts = face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
        origin = pts[:, :2].min(0)
        keys = np.floor((pts[:, :2] - origin) / _CELL_MM).astype(int)
        cells: dict = {}
        order = np.lexsort((keys[:, 1], keys[:, 0]))
        k_sorted = keys[order]
        breaks = np.flatnonzero(np.any(np.diff(k_sorted, axis=0) != 0, axis=1)) + 1
        for chunk in np.split(order, breaks):
            cells[tuple(keys[chunk[0]])] = chunk
        return cls(pts, spacing, origin, cells)

    def near(self, xy: np.ndarray, radius: float) -> np.ndarray:
        """Indices of the points whose cell lies within `radius` of xy (a superset of the points there)."""
        lo = np.floor((xy - radius - self.origin) / _CELL_MM).astype(int)
        hi = np.floor((xy + radius - self.origin) / _CELL_MM).astype(int)
        found = [self.cells[(i, j)] for i in range(lo[0], hi[0] + 1) for j in range(lo[1], hi[1] + 1)
                 if (i, j) in self.cells]
        return np.concatenate(found) if found else np.zeros(0, dtype=int)


def penetration(positioner, samples: FaceSamples, reach: float, tips: np.ndarray, axes: np.ndarray
                ) -> np.ndarray:
    """(m,) how deep (mm, >= 0) each tool instance (tips[k], axes[k]) is inside the face samples; `reach`
    bounds the tool's XY extent from its tip (for a torus Ro + Ri plus what the tilt adds)."""
    out = np.zeros(len(tips))
    for k, (t, a) in enumerate(zip(tips, axes)):
        idx = samples.near(t[:2], reach)
        if len(idx):
            d = positioner.tool_distance(t, a, samples.points[idx])
            out[k] = max(0.0, -float(d.min()))
    return out


def between(positioner, samples: FaceSamples, reach: float, tip0, axis0, tip1, axis1, checks: int = 8) -> float:
    """The deepest cut (mm) at `checks` instances strictly between two positions: tip on its straight line,
    axis by slerp (the motion a control with tool-centre-point mode makes)."""
    s = np.arange(1, checks + 1) / (checks + 1)
    tips = np.asarray(tip0, float)[None, :] * (1 - s[:, None]) + np.asarray(tip1, float)[None, :] * s[:, None]
    return float(penetration(positioner, samples, reach, tips, slerp(axis0, axis1, s)).max())


def signed_clearance(positioner, samples: FaceSamples, reach: float, tip, axis) -> float:
    """The smallest signed distance (mm) from the face samples to the tool at (tip, axis): negative inside
    (a gouge), positive the gap; +inf where no sample lies under the tool."""
    idx = samples.near(np.asarray(tip, float)[:2], reach)
    return float(positioner.tool_distance(tip, axis, samples.points[idx]).min()) if len(idx) else math.inf


def worst_between(positioner, samples: FaceSamples, reach: float, segments, spacing: float = 0.5
                  ) -> tuple[float, float]:
    """(deepest cut, widest gap) along the moves of 5-axis cut segments (tip straight, axis by slerp), at
    instances `spacing` apart: the gap is how much further off the face the tool stands than the ends'
    gaps, interpolated, say (the chord error). Sampled independently of the kernel's clearance."""
    deepest = widest = 0.0
    for seg in segments:
        ends = [signed_clearance(positioner, samples, reach, t, a) for t, a in zip(seg.tips, seg.axes)]
        for k in range(len(seg.tips) - 1):
            n = max(2, int(math.ceil(float(np.linalg.norm(seg.tips[k + 1] - seg.tips[k])) / spacing)))
            s = np.arange(1, n) / n
            for sk, axis in zip(s, slerp(seg.axes[k], seg.axes[k + 1], s)):
                c = signed_clearance(positioner, samples, reach, seg.tips[k] * (1 - sk) + seg.tips[k + 1] * sk, axis)
                expected = ends[k] * (1 - sk) + ends[k + 1] * sk
                deepest = max(deepest, -c)
                if math.isfinite(c) and math.isfinite(expected):
                    widest = max(widest, c - expected)
    return deepest, widest


class FaceGouge:
    """Depths (mm) of tool instances in a face, exact to about 0.0013 mm for a torus of minor radius 6 mm:
    every instance on samples 0.5 mm apart, those deeper there than `screen` again on samples 0.25 mm apart
    (module functions above; the same screening as core.strategies.multipoint_refine)."""

    def __init__(self, positioner, face: BezierFace, reach: float, screen: float = 0.005) -> None:
        self.positioner, self.reach, self.screen = positioner, reach, screen
        self.coarse = FaceSamples.of(face, 0.5)
        self.fine = FaceSamples.of(face, 0.25)

    def __call__(self, tips: np.ndarray, axes: np.ndarray) -> np.ndarray:
        d = penetration(self.positioner, self.coarse, self.reach, tips, axes)
        again = d > self.screen
        if again.any():
            d[again] = penetration(self.positioner, self.fine, self.reach, tips[again], axes[again])
        return d
