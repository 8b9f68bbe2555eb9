"""The top bound delta_1 of the C-space: the largest lift whose remaining material at the side step stays
within the tolerance (seed 000 eq. 3.82-3.84, section 3.5.5.1).

How the seed's equations are read. Eq. 3.82: at the lateral distance d (LY, the half step-over on that side of
the pass) the point of the tool's bottom P(alpha) and the point of the surface's cross-section P(d) (the cut
by the plane through the CC point across the drive plane, i.e. the LY-LZ plane) have the same LY, and their
LZ difference is the remaining height, set equal to the tolerance tau. The seed's C-space box (eq. 3.20)
also keeps delta < tau: the lift leaves material at the CC point itself; here that is the same rule at LY = 0
(remaining height at the CC point <= tau), which eq. 3.82 alone misses (a tool resting on a groove's
shoulders would pass it). Eq. 3.84 then gives delta_1 for the
flat end mill, dividing by cos(lambda) because the lift is along the tool axis. The seed takes P(alpha) on
the bottom rim (eq. 3.25) and leaves A of eq. 3.83 undefined; for omega != 0 its C also mixes in the lift.

What is computed instead, exactly and for ball, flat and bull-nose alike: the tool's effective cutting
profile, i.e. the lower envelope of the tool swept along the feed LX and seen in the LY-LZ plane. The lower
surface is the disc of radius R - r (at height r) swept by a ball of radius r, so the profile is the lower
boundary of (the disc's projection, an ellipse) + (a disc of radius r) in 2D, obtained from its support
points. Lifting by delta moves the profile by delta (TZ_y, TZ_z) (sideways too when omega != 0). The bound
on one side is the lift at which the profile passes through Q = (d, S(d) + tau), S(d) being the mesh's
height along LZ at LY = d (a ray along -LZ): delta_1 = min over the two sides. Where the profile does not
reach the side step at any lift (Q beside it), delta_1 = -inf; where the mesh ends before the side step
(no ray hit), that side sets no bound. The side wall of the tool above the corner is left out of the
profile: the profile can only be higher, the bound smaller (on the safe side).
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.posture import tool_rotation, touch_tip
from tmm_workbench.core.tools.cutter import Cutter

PROFILE_SAMPLES = 4001


def profile_arcs(cutter: Cutter, lam: np.ndarray, omg: np.ndarray,
                 samples: int = PROFILE_SAMPLES) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For P postures: the lift direction a2 = (TZ_y, TZ_z) (P, 2) and the profile's entry arc seen along
    it, as its coordinate across a2 (P, samples, increasing) and along the unit a2 (P, samples), at delta = 0
    in LCS (LY, LZ). The same for every CC point and pass: kept for the last few (cutter, grid)s."""
    lam = np.ascontiguousarray(lam, dtype=float).reshape(-1)
    omg = np.ascontiguousarray(omg, dtype=float).reshape(-1)
    return _profile_arcs(cutter, lam.tobytes(), omg.tobytes(), int(samples))


def _support(cutter: Cutter, rot: np.ndarray, ny: np.ndarray, nz: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(LY, LZ) (P, S) of the profile's support points for the unit normals (ny, nz) (P, S), at delta = 0:
    the ellipse (the disc of radius R - r seen along LX) grown by a disc of radius r; and their LX (P, S)
    (where along the feed the tool's point that forms the profile lies)."""
    r = cutter.corner_radius
    rp = cutter.radius - r
    tip = touch_tip(cutter, rot)
    c3 = tip + r * rot[:, 2, :]                                            # disc centre (LX, LY, LZ)
    c2 = c3[:, 1:]
    M = rp * np.stack([rot[:, 0, 1:], rot[:, 1, 1:]], axis=-1)            # (P, 2, 2): columns TX, TY seen
    m = [[M[:, i, j][:, None] for j in range(2)] for i in range(2)]
    s0 = m[0][0] * ny + m[1][0] * nz                                       # M^T n
    s1 = m[0][1] * ny + m[1][1] * nz
    norm = np.hypot(s0, s1)
    inv = np.where(norm > 1e-15, 1.0 / np.where(norm > 1e-15, norm, 1.0), 0.0)
    s0 *= inv
    s1 *= inv
    py = c2[:, :1] + m[0][0] * s0 + m[0][1] * s1 + r * ny
    pz = c2[:, 1:] + m[1][0] * s0 + m[1][1] * s1 + r * nz
    px = c3[:, :1] + rp * (rot[:, 0, :1] * s0 + rot[:, 1, :1] * s1)
    return py, pz, px


@lru_cache(maxsize=4)
def _profile_arcs(cutter: Cutter, lam_bytes: bytes, omg_bytes: bytes, samples: int):
    lam, omg = np.frombuffer(lam_bytes), np.frombuffer(omg_bytes)
    rot = tool_rotation(lam, omg)                                          # (P, 3, 3)
    a2 = rot[:, 2, 1:]                                                     # lift direction in (LY, LZ)
    au = a2 / np.linalg.norm(a2, axis=1, keepdims=True)
    bu = np.stack([au[:, 1], -au[:, 0]], axis=1)                           # across the lift, towards +LY
    th = np.linspace(-0.5 * math.pi, 0.5 * math.pi, samples)[None, :]
    # outward normals of the arc that faces against the lift: n = -cos(th) a + sin(th) b
    py, pz, _ = _support(cutter, rot, -np.cos(th) * au[:, :1] + np.sin(th) * bu[:, :1],
                         -np.cos(th) * au[:, 1:] + np.sin(th) * bu[:, 1:])
    across = py * bu[:, :1] + pz * bu[:, 1:]
    along = py * au[:, :1] + pz * au[:, 1:]
    arcs = (a2, np.maximum.accumulate(across, axis=1), along)
    for a in arcs:
        a.flags.writeable = False                                          # shared by the cache
    return arcs


def lower_profile(cutter: Cutter, lam: np.ndarray, omg: np.ndarray, samples: int = PROFILE_SAMPLES,
                  lead: bool = False) -> tuple[np.ndarray, ...]:
    """The effective cutting profile's lower boundary along LZ for P postures (lam, omg radians) at delta =
    0: LY (P, samples, increasing) and LZ (P, samples) in the CC point's LCS; with `lead` also the LX (P,
    samples) of the tool's point that forms it (behind the CC point < 0: the swept tool forms the profile
    there when it has gone that far beyond, which a curving pass bends: mesh5.widths.bent_profile)."""
    lam = np.asarray(lam, dtype=float).reshape(-1)
    rot = tool_rotation(lam, np.asarray(omg, dtype=float).reshape(-1))
    th = np.linspace(-0.5 * math.pi, 0.5 * math.pi, samples)[None, :]
    ny = np.repeat(np.sin(th), len(lam), axis=0)
    py, pz, px = _support(cutter, rot, ny, -np.cos(th) + 0 * ny)
    py = np.maximum.accumulate(py, axis=1)
    return (py, pz, px) if lead else (py, pz)


def surface_heights(reach: MeshReach, points: np.ndarray, frames: np.ndarray, lateral: np.ndarray,
                    radius: float) -> np.ndarray:
    """(n, k): the mesh's height along LZ at (LX, LY) = (0, lateral[j]) of each CC point's LCS (the highest
    hit of a ray along -LZ among the triangles within `radius`), NaN where no triangle lies there."""
    lat = np.asarray(lateral, dtype=float).reshape(len(points), -1)
    out = np.full(lat.shape, np.nan)
    for i, (p, f) in enumerate(zip(points, frames)):
        idx = reach.near(p, radius)
        t = (reach.corners[idx] - p) @ f.T                                 # (k, 3, 3) in LCS
        # only the triangles that cross LX = 0 (the rays' plane) can be hit; the margin is far above the
        # barycentric test's own 1e-12
        x = t[:, :, 0]
        t = t[(x.min(axis=1) <= 1e-9) & (x.max(axis=1) >= -1e-9)]
        a, b, c = t[:, 0], t[:, 1], t[:, 2]
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        ok = np.abs(det) > 1e-300
        a, b, c, det = a[ok], b[ok], c[ok], det[ok]
        px, py = -a[:, 0][:, None], lat[i][None, :] - a[:, 1][:, None]                 # (k, L)
        u = (px * (c[:, 1] - a[:, 1])[:, None] - (c[:, 0] - a[:, 0])[:, None] * py) / det[:, None]
        v = ((b[:, 0] - a[:, 0])[:, None] * py - px * (b[:, 1] - a[:, 1])[:, None]) / det[:, None]
        tol = 1e-12
        inside = (u >= -tol) & (v >= -tol) & (u + v <= 1 + tol)
        z = a[:, 2][:, None] + u * (b[:, 2] - a[:, 2])[:, None] + v * (c[:, 2] - a[:, 2])[:, None]
        z = np.where(inside, z, -np.inf).max(axis=0, initial=-np.inf)
        out[i] = np.where(np.isfinite(z), z, np.nan)
    return out


def half_steps(side_step, n: int, radius: float) -> np.ndarray:
    """(n, 2) lateral distances (left = +LY, right = -LY) from a number, an (n,) or an (n, 2) array."""
    w = np.asarray(side_step, dtype=float)
    if w.ndim == 0:
        w = np.full((n, 2), float(w))
    elif w.shape == (n,):
        w = np.repeat(w[:, None], 2, axis=1)
    elif w.shape != (n, 2):
        raise TmmError(f"side step must be a number, ({n},) or ({n}, 2) mm, got shape {w.shape}")
    bad = ~(np.isfinite(w) & (w > 0) & (w <= 2 * radius))
    if bad.any():
        raise TmmError(f"side step {float(w[bad][0])!r} mm must be > 0 and at most the cutter's diameter "
                       f"{2 * radius:g} mm")
    return w


def top_bounds(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, lam: np.ndarray,
               omg: np.ndarray, tolerance: float, side_step, arcs: Optional[tuple] = None,
               interior: int = 0) -> np.ndarray:
    """delta_1 (n, P) of the P postures (lam, omg radians) at the n CC points for the remaining height
    `tolerance` at the half side steps (see half_steps), and with `interior` > 0 also at that many evenly
    spaced points inside each side (where the section curves up between the CC point and the side step):
    -inf where no lift meets it, inf where the mesh ends on both sides."""
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"tolerance must be a positive number of mm, got {tolerance!r}")
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    w = half_steps(side_step, len(pts), cutter.radius)
    # LY of the CC point itself (the lift leaves material there too: the seed's delta < tau, eq. 3.20) and of
    # the two sides
    frac = np.arange(1, int(interior) + 2) / (int(interior) + 1)
    lateral = np.concatenate([np.zeros((len(w), 1)), w[:, :1] * frac, -w[:, 1:] * frac], axis=1)
    S = surface_heights(reach, pts, frm, lateral, 2 * cutter.radius + 4 * float(w.max()))
    a2, across, along = profile_arcs(cutter, lam, omg) if arcs is None else arcs
    norm2 = np.linalg.norm(a2, axis=1)
    au = a2 / norm2[:, None]
    bu = np.stack([au[:, 1], -au[:, 0]], axis=1)
    out = np.full((len(pts), len(a2)), np.inf)
    for side in range(lateral.shape[1]):
        qy, qz = lateral[:, side], S[:, side] + tolerance                  # (n,)
        has = np.isfinite(qz)
        for p in range(len(a2)):
            qb = qy * bu[p, 0] + qz * bu[p, 1]
            qa = qy * au[p, 0] + qz * au[p, 1]
            pa = np.interp(qb, across[p], along[p])
            d1 = (qa - pa) / norm2[p]
            beside = (qb < across[p, 0]) | (qb > across[p, -1])
            d1 = np.where(beside, -np.inf, d1)
            out[:, p] = np.where(has, np.minimum(out[:, p], d1), out[:, p])
    return out
