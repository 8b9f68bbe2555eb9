"""Layer heights (tip z) of z-level roughing: a fixed step-down, or as deep as the remaining material allows
(seed 000 section 3.4.2, eq. 3.10-3.11), plus extra layers at the model's plateaus.

Eq. 3.10 gives the material left between two layers a cutting depth eps apart on a slope alpha (from the
horizontal) for a ball of radius R: delta = R - sqrt(R^2 - (eps / (2 sin alpha))^2): the cusp of two circles
eps / sin alpha apart along the slope. Eq. 3.11 inverts it: eps = 2 sin alpha sqrt(2 delta R - delta^2).
What the seed leaves open, decided here:
- which alpha: the cusp grows as the slope flattens, so a layer takes the shallowest slope of the model's
  triangles in its height band (the worst case there), but not below MIN_SLOPE_DEG: eq. 3.11 goes to 0 on a
  flat, which would need endless layers. Plateaus (triangles within PLATEAU_DEG of horizontal) get a layer of
  their own instead (flat_layers); on slopes between PLATEAU_DEG and MIN_SLOPE_DEG the stairs may exceed
  delta (semi-finishing takes them).
- other cutters: a bull-nose touches a slope with its corner torus, so eq. 3.10 holds with R replaced by
  the corner radius r while the cusp stays on the corner (delta < r); a flat end mill (or delta >= r) leaves
  the stair's corner, delta = eps cos alpha from the slope, so eps = delta / cos alpha.
- the step-down is the deepest layer the material and tool allow (the seed: hardness); the tolerance only
  makes layers shallower.
"""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.tools.cutter import Cutter

PLATEAU_DEG = 0.5       # a triangle this close to horizontal (facing up) is part of a plateau
MIN_SLOPE_DEG = 10.0    # tolerance mode: shallower slopes count as this steep (eq. 3.11 -> 0 on flats)
_SAME_Z = 1e-6          # mm: layers closer than this are one
PLATEAU_LIFT = 1e-5     # mm: a plateau layer sits this far above the plateau, so the drop of the flat
                        # itself (equal to the layer in exact arithmetic) never blocks it by rounding


def fixed_layers(top: float, final: float, step: float) -> np.ndarray:
    """Tip heights top - step, top - 2 step, ... and the last exactly at `final` (descending)."""
    if not top > final:
        return np.zeros(0)
    n = max(1, math.ceil((top - final) / step - 1e-9))
    z = top - step * np.arange(1, n + 1, dtype=float)
    z[-1] = final
    return z


def tolerance_depth(cutter: Cutter, delta: float, slope_deg: float) -> float:
    """The cutting depth eps of eq. 3.11 that leaves `delta` on a slope of `slope_deg` (see the module doc
    for the cutters other than the ball)."""
    a = math.radians(min(90.0, max(slope_deg, MIN_SLOPE_DEG)))
    r = cutter.radius if cutter.kind == "ball" else cutter.corner_radius
    if r > 0 and delta < r:
        return 2.0 * math.sin(a) * math.sqrt(2.0 * delta * r - delta * delta)
    cos_a = math.cos(a)
    return math.inf if cos_a < 1e-12 else delta / cos_a


def triangle_slopes(mesh: TriMesh) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per triangle: slope from the horizontal (deg), lowest and highest z, and whether it faces up."""
    v = mesh.vertices[mesh.triangles]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(n, axis=1)
    ok = length > 0
    nz = np.where(ok, n[:, 2] / np.where(ok, length, 1.0), 0.0)
    slope = np.degrees(np.arccos(np.clip(np.abs(nz), 0.0, 1.0)))
    return slope, v[:, :, 2].min(axis=1), v[:, :, 2].max(axis=1), (nz > 0) & ok


def tolerance_layers(mesh: TriMesh, cutter: Cutter, top: float, final: float, step_down: float, delta: float,
                     lift: float) -> np.ndarray:
    """Descending tip heights from `top` to `final`: each layer as deep as eq. 3.11 allows for the shallowest
    non-plateau slope of the model (raised by `lift`, the axial stock to leave) in its band, at most
    `step_down`; the last exactly at `final`."""
    slope, zlo, zhi, _ = triangle_slopes(mesh)
    sloped = slope >= PLATEAU_DEG
    slope, zlo, zhi = slope[sloped], zlo[sloped] + lift, zhi[sloped] + lift
    out: list[float] = []
    z = top
    while z > final + _SAME_Z:
        band = (zhi >= z - step_down) & (zlo <= z)
        eps = step_down
        if band.any():
            eps = min(step_down, tolerance_depth(cutter, delta, float(slope[band].min())))
        z = max(final, z - eps)
        out.append(z)
    if out:
        out[-1] = final
    return np.asarray(out)


def plateau_heights(mesh: TriMesh) -> np.ndarray:
    """Heights of the model's plateaus: the highest point of each up-facing triangle within PLATEAU_DEG of
    horizontal, distinct to _SAME_Z, descending."""
    slope, _, zhi, up = triangle_slopes(mesh)
    flat = zhi[(slope < PLATEAU_DEG) & up]
    if not len(flat):
        return np.zeros(0)
    flat = np.sort(flat)[::-1]
    keep = np.concatenate([[True], np.diff(flat) < -_SAME_Z])
    return flat[keep]


def with_plateaus(layers: np.ndarray, plateaus: np.ndarray, top: float, final: float, lift: float,
                  tolerance: float) -> np.ndarray:
    """`layers` plus a layer at each plateau (raised by `lift` + PLATEAU_LIFT) that would otherwise keep more
    than `tolerance` above it (the next layer above it is higher than that), highest plateau first so a layer
    added for one also serves the plateaus below it."""
    zs = sorted(float(z) for z in layers)
    for p in plateaus:
        t = float(p) + lift + PLATEAU_LIFT
        if not (final < t < top):
            continue
        above = [z for z in zs if z >= t - PLATEAU_LIFT - _SAME_Z]   # the final layer may sit on it
        nearest = min(above) if above else top
        if nearest - t > tolerance:
            zs.append(t)
            zs.sort()
    return np.asarray(sorted(zs, reverse=True))
