"""Cutter postures at a CC point in its local frame (seed 000 eq. 3.6-3.9).

A posture is (lambda, omega): the tool axis inclined by lambda about LY and yawed by omega about LZ. By eq.
3.8 the tool frame's rows in LCS coordinates are
    TX = (cos l cos w, cos l sin w, -sin l),  TY = (-sin w, cos w, 0),  TZ = (sin l cos w, sin l sin w, cos l),
TZ being the tool axis (tip -> spindle), and the lift delta moves the tool along TZ (eq. 3.8's translation is
applied in the tool frame; eq. 3.84 divides by cos lambda accordingly). The seed's text says "lifting along
LZ" first; its matrices lift along the axis, which is what is done here.

At delta = 0 the tool touches the tangent plane at the CC point: the point of the tool lowest along -LZ (its
support point) is the CC point. For the flat end mill this is the rim point on TX, the cutter centre lying R
behind it along -TX, as the seed's Figure 3-27 / eq. 3.25 place it; at lambda = 0 the limit lambda -> 0+ is
taken (the rim point towards the yaw direction). Only the plain APT cutters (ball, flat, bull-nose) are taken:
their lower surface is the disc of radius R - r at height r swept by a ball of radius r.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools.cutter import Cutter

# The seed's C-space box (eq. 3.20) and grid (3 degrees, section 3.5.5.1).
SEED_LAMBDA_DEG = (0.0, 45.0)
SEED_OMEGA_DEG = (-45.0, 45.0)
SEED_STEP_DEG = 3.0


def _angle_range(name: str, lo: float, hi: float, step: float, limit: float) -> np.ndarray:
    for v in (lo, hi, step):
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise TmmError(f"{name} range and step must be finite numbers of degrees, got {lo!r}..{hi!r} "
                           f"step {step!r}")
    if not (step > 0 and lo <= hi and -limit <= lo and hi <= limit):
        raise TmmError(f"{name} range {lo:g}..{hi:g} deg step {step:g} is outside -{limit:g}..{limit:g} deg "
                       "or has a step <= 0")
    n = int(math.floor((hi - lo) / step + 1e-9)) + 1
    return np.radians(lo + step * np.arange(n))


@dataclass(frozen=True)
class PostureGrid:
    """The (lambda, omega) grid in radians: lambdas (nl,), omegas (no,)."""
    lambdas: np.ndarray
    omegas: np.ndarray

    @classmethod
    def degrees(cls, lambda_range=SEED_LAMBDA_DEG, omega_range=SEED_OMEGA_DEG,
                step: float = SEED_STEP_DEG) -> "PostureGrid":
        """The grid from `lambda_range` and `omega_range` (deg, ends included when on the step)."""
        return cls(_angle_range("inclination lambda", *lambda_range, step, 89.0),
                   _angle_range("yaw omega", *omega_range, step, 180.0))

    @property
    def shape(self) -> tuple[int, int]:
        return len(self.lambdas), len(self.omegas)

    def mesh(self) -> tuple[np.ndarray, np.ndarray]:
        """lambda and omega of every posture, each (nl, no)."""
        return np.meshgrid(self.lambdas, self.omegas, indexing="ij")


def tool_rotation(lam: np.ndarray, omg: np.ndarray) -> np.ndarray:
    """(..., 3, 3): rows TX, TY, TZ of the tool frame in LCS coordinates (eq. 3.8)."""
    lam, omg = np.broadcast_arrays(np.asarray(lam, dtype=float), np.asarray(omg, dtype=float))
    cl, sl, cw, sw = np.cos(lam), np.sin(lam), np.cos(omg), np.sin(omg)
    z = np.zeros_like(lam)
    return np.stack([np.stack([cl * cw, cl * sw, -sl], -1),
                     np.stack([-sw, cw, z], -1),
                     np.stack([sl * cw, sl * sw, cl], -1)], -2)


def require_plain(cutter: Cutter) -> None:
    """The C-space here takes ball, flat and bull-nose cutters (a refusal naming the tool otherwise)."""
    if not cutter.is_plain:
        raise TmmError(f"the 3D C-space method takes a ball, flat or bull-nose cutter, not the "
                       f"{cutter.describe()} (bottom angle {cutter.bottom_angle_deg:g} deg, taper "
                       f"{cutter.taper_angle_deg:g} deg must be 0)")


def touch_tip(cutter: Cutter, rot: np.ndarray) -> np.ndarray:
    """(..., 3): the tip (centre of the bottom) in LCS coordinates when the tool with frame `rot` touches the
    tangent plane at the CC point (origin) with its lowest point: tip = r LZ - r TZ - (R - r) TX."""
    require_plain(cutter)
    r = cutter.corner_radius
    rp = cutter.radius - r
    ez = np.array([0.0, 0.0, 1.0])
    return r * ez - r * rot[..., 2, :] - rp * rot[..., 0, :]


def world_placement(cutter: Cutter, points: np.ndarray, frames: np.ndarray, lam: np.ndarray, omg: np.ndarray,
                    delta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The tool's tip (centre of the bottom) and unit axis (tip -> spindle) in world coordinates, (n, 3) each,
    for n C-space sets (lam, omg radians, delta mm) at CC points (n, 3) with LCS frames (n, 3, 3) (rows LX,
    LY, LZ): the CL point of eq. 3.6-3.9."""
    rot = tool_rotation(np.asarray(lam, dtype=float).reshape(-1), np.asarray(omg, dtype=float).reshape(-1))
    tip_l = touch_tip(cutter, rot) + np.asarray(delta, dtype=float).reshape(-1, 1) * rot[:, 2, :]
    F = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    tips = np.asarray(points, dtype=float).reshape(-1, 3) + np.einsum("nji,nj->ni", F, tip_l)
    axes = np.einsum("nji,nj->ni", F, rot[:, 2, :])
    return tips, axes
