"""Z-map (height-map) simulation of a 5-axis toroidal tool: vertical needles cut down by the swept tool. The
slow, independent reference the kernel's sweep (core.sim, the product's stock simulation) and the multipoint
scallop are checked against; test code, not part of the add-on.

Each needle is a vertical line at (x, y) holding a height; the tool, moved linearly between consecutive
positions, lowers every needle to the lowest point of the tool solid on that vertical line. Needles may be
any set of (x, y) points: a grid (a full z-map) or a line of points (a section), all independent.

Tool solid: the same as the kernel's `MultipointPositioner.tool_distance` (native/include/tmm/multipoint.hpp):
  round_insert  the full torus (major radius Ro about the axis, minor radius Ri, centre C = tip + Ri a)
                united with the body above the centre plane out to Ro + Ri (an endless half-cylinder: the
                shank), which also closes the small hollow rho < Ro - Ri at the bottom (seed 001, 3.3.1);
  bull_nose     the torus, the flat-bottomed core {rho <= Ro, h >= -Ri} and the same half-cylinder;
  Ro = 0        a ball of radius Ri (both shapes).

The lowest point of the solid on a vertical line is solved exactly, never by sampling the tool:
  torus: with t the height above C, the line is a root of the depressed quartic
         t^4 + P t^2 + Q t + R = 0,  P = 2K - 4 Ro^2 (1 - a_z^2),  Q = 8 Ro^2 (q.a) a_z,
         R = K^2 - 4 Ro^2 (|q|^2 - (q.a)^2),  K = |q|^2 + Ro^2 - Ri^2,  q = (x - C_x, y - C_y, 0);
         all four roots in closed form (Ferrari: the resolvent cubic's largest root by Cardano / the
         trigonometric form, polished by Newton), each real part polished by Newton on the quartic (3
         steps), and kept if the point is on the torus: its distance to the tube
         | sqrt((rho - Ro)^2 + h^2) - Ri | <= TANGENT_TOL (1e-7 mm: a line passing that close to the tool
         counts as touching it, the tool grown by at most 1e-7 mm). Any line with a candidate within
         DOUBT_TOL (0.05 mm) of the tube but not on it (near-tangent lines, rounding in the closed form) is
         solved again from the companion matrix' eigenvalues (LAPACK). The lowest kept root is the entry.
  ball:  closed form; half-cylinders: a quadratic (the cylinder) clipped by a plane (its bottom), exact.

Motion between positions (tip_0, a_0) -> (tip_1, a_1), parameter s in [0, 1]:
  tip(s) = (1 - s) tip_0 + s tip_1 (linear),
  a(s)   = slerp(a_0, a_1, s) (constant angular rate about a_0 x a_1; default) or
           normalised linear interpolation ("nlerp", same path, non-uniform rate).
A real control interpolates the machine's joints (for a tilt-rotary table: the two rotary axes linearly, and
the tip linearly only with RTCP/TCPM active); the swept tool then differs from this model by the control's
nonlinearity error, which is not modelled here.

Sub-stepping. Each move is cut into n = ceil((|tip_1 - tip_0| + theta r_tool) / max_step) equal steps
(theta the angle between the axes, r_tool = sqrt((Ro + Ri)^2 + (2 Ri)^2) the farthest torus point from the
tip), so no point of the torus moves more than max_step between two sampled instances. Two consecutive
instances of a surface of curvature radius >= Ri moved by s leave a cusp of at most s^2 / (8 Ri) between
them (the ball of radius Ri moving along a line: exact); for the default max_step = 0.25 mm and Ri = 6 mm
that is 1.3e-3 mm. Because the torus also has saddle-shaped parts and the axis turns, the bound is checked,
not assumed: `simulate(..., verify_tol=1e-3)` halves the step (the doubled sample set contains the old one,
so it only adds the midpoints) until no needle moves by more than verify_tol, and reports the last change.
The cusp bound is along the surface normal: measured vertically it grows by 1 / cos(slope of the cut
surface), so it is tight only where the machined surface is moderately sloped (the seed patches: <= 31°).
The step counts the torus only: points of the shank far above the tip move more when the axis turns (they
cut only where the shank reaches the stock, which the verification would show as a change).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.axes import slerp

if TYPE_CHECKING:
    from tmm_workbench.core.tools.cutter import Cutter

TANGENT_TOL = 1e-7      # mm: a vertical line this close to the torus counts as touching it
NEWTON_STEPS = 3        # Newton polish of each quartic root
DOUBT_TOL = 0.05        # mm: candidates this close to the torus but not on it are re-solved by eigenvalues
SHAPES = ("round_insert", "bull_nose")


@dataclass(frozen=True)
class ZTool:
    """The tool solid (see the module docstring): major radius Ro >= 0, minor radius Ri > 0, mm."""
    Ro: float
    Ri: float
    shape: str = "round_insert"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.Ro) and math.isfinite(self.Ri) and self.Ro >= 0 and self.Ri > 0):
            raise TmmError(f"tool radii must be finite with Ro >= 0, Ri > 0; got Ro={self.Ro!r}, Ri={self.Ri!r}")
        if self.shape not in SHAPES:
            raise TmmError(f"tool shape must be one of {SHAPES}, got {self.shape!r}")

    @classmethod
    def of(cls, cutter: "Cutter", shape: str = "round_insert") -> "ZTool":
        """The simulated solid of the one tool model's toroidal view (core.tools.Cutter.torus_radii)."""
        Ro, Ri = cutter.torus_radii
        return cls(Ro, Ri, shape)

    @property
    def radius(self) -> float:
        return self.Ro + self.Ri

    @property
    def reach(self) -> float:
        """Farthest point of the torus from the tip (bounds the displacement of any cutting point)."""
        return math.hypot(self.Ro + self.Ri, 2.0 * self.Ri)


# ---------------------------------------------------------------------------------------------------------
# Lowest point of the tool solid on vertical lines (pairs: one tool instance and one needle per row).
# ---------------------------------------------------------------------------------------------------------

def _half_cylinder_lowest(C: np.ndarray, a: np.ndarray, q: np.ndarray, radius: float, h_min: float) -> np.ndarray:
    """Lowest height (above C_z) of {rho <= radius, h >= h_min} (a convex set) on the vertical lines at
    horizontal offsets q (P, 2) from the centres C; +inf where missed. a: (P, 3) unit axes, a_z > 0."""
    az = a[:, 2]
    qa = q[:, 0] * a[:, 0] + q[:, 1] * a[:, 1]
    qq = q[:, 0] ** 2 + q[:, 1] ** 2
    z_h = (h_min - qa) / az                        # the bottom plane h = h_min
    A = 1.0 - az * az                              # rho^2(z) = A z^2 + B z + Cc + radius^2
    B = -2.0 * az * qa
    Cc = qq - qa * qa - radius * radius
    out = np.full(len(q), np.inf)
    vertical = A < 1e-14
    # Vertical axis: rho does not change along the line.
    vin = vertical & (Cc <= 0.0)
    out[vin] = z_h[vin]
    tilted = ~vertical
    if tilted.any():
        At, Bt, Ct = A[tilted], B[tilted], Cc[tilted]
        disc = Bt * Bt - 4.0 * At * Ct
        ok = disc >= 0.0
        sq = np.sqrt(np.where(ok, disc, 0.0))
        # Stable roots of the quadratic.
        qq_ = -0.5 * (Bt + np.copysign(sq, Bt))
        with np.errstate(divide="ignore", invalid="ignore"):
            r1 = qq_ / At
            r2 = np.where(qq_ != 0.0, Ct / qq_, r1)
        z1, z2 = np.minimum(r1, r2), np.maximum(r1, r2)
        lo = np.maximum(z1, z_h[tilted])
        res = np.where(ok & (lo <= z2), lo, np.inf)
        out[tilted] = res
    return out


def _torus_lowest(C: np.ndarray, a: np.ndarray, q: np.ndarray, Ro: float, Ri: float) -> np.ndarray:
    """Lowest height (above C_z) of the solid torus on the vertical lines at offsets q (P, 2); +inf if missed."""
    n = len(q)
    out = np.full(n, np.inf)
    if n == 0:
        return out
    az = a[:, 2]
    qa = q[:, 0] * a[:, 0] + q[:, 1] * a[:, 1]
    qq = q[:, 0] ** 2 + q[:, 1] ** 2
    if Ro == 0.0:  # a ball
        hit = qq <= Ri * Ri
        out[hit] = -np.sqrt(Ri * Ri - qq[hit])
        return out
    R2 = Ro * Ro
    K = qq + R2 - Ri * Ri
    P = 2.0 * K - 4.0 * R2 * (1.0 - az * az)
    Q = 8.0 * R2 * qa * az
    R = K * K - 4.0 * R2 * (qq - qa * qa)
    t, g = _accept(_ferrari(P, Q, R), P, Q, R, qa, qq, az, Ro, Ri)
    # Doubtful pairs (a candidate close to, but not on, the torus: a near-tangent line or a closed-form root
    # spoiled by rounding) are solved again from the companion matrix' eigenvalues.
    doubt = np.any((g > TANGENT_TOL) & (g < DOUBT_TOL), axis=1)
    if doubt.any():
        t2, _ = _accept(_eig_roots(P[doubt], Q[doubt], R[doubt]), P[doubt], Q[doubt], R[doubt], qa[doubt],
                        qq[doubt], az[doubt], Ro, Ri)
        t[doubt] = t2
    return t.min(axis=1)


def _eig_roots(P, Q, R):
    """Real parts of the four roots of t^4 + P t^2 + Q t + R (companion matrix, LAPACK)."""
    n = len(P)
    M = np.zeros((n, 4, 4))
    M[:, 1, 0] = M[:, 2, 1] = M[:, 3, 2] = 1.0
    M[:, 0, 3] = -R
    M[:, 1, 3] = -Q
    M[:, 2, 3] = -P
    return np.linalg.eigvals(M).real


def _ferrari(P, Q, R):
    """Real parts of the four roots of t^4 + P t^2 + Q t + R (Ferrari, vectorised; complex pairs give their
    real part, to be checked by the caller)."""
    # Resolvent: (t^2 + y)^2 = (2y - P) t^2 - Q t + y^2 - R is a square when
    # y^3 - P/2 y^2 - R y + (4 P R - Q^2) / 8 = 0; its largest root has 2y - P >= 0.
    a, b, c = -0.5 * P, -R, (4.0 * P * R - Q * Q) / 8.0
    p = b - a * a / 3.0
    q = 2.0 * a ** 3 / 27.0 - a * b / 3.0 + c
    D = (0.5 * q) ** 2 + (p / 3.0) ** 3
    sq = np.sqrt(np.maximum(D, 0.0))
    w1 = np.cbrt(-0.5 * q + sq) + np.cbrt(-0.5 * q - sq)
    mp = np.maximum(-p / 3.0, 0.0)
    r = np.sqrt(mp)
    with np.errstate(divide="ignore", invalid="ignore"):
        cosarg = np.clip(np.where(r > 0, -0.5 * q / (r ** 3), 0.0), -1.0, 1.0)
    w3 = 2.0 * r * np.cos(np.arccos(cosarg) / 3.0)
    y = np.where(D > 0, w1, w3) - a / 3.0
    for _ in range(2):  # polish the resolvent root
        f = ((y + a) * y + b) * y + c
        df = (3.0 * y + 2.0 * a) * y + b
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.where(np.abs(df) > 1e-300, y - f / df, y)
    y = np.maximum(y, 0.5 * P)
    # (t^2 + y)^2 = (s t - h)^2 with s^2 = 2y - P, h^2 = y^2 - R, 2 s h = Q: h from Q / (2 s) when s is
    # the larger (well conditioned), else from sqrt(y^2 - R) with the sign of Q (s ~ 0: Q ~ 0, biquadratic).
    s = np.sqrt(2.0 * y - P)
    h2 = np.copysign(np.sqrt(np.maximum(y * y - R, 0.0)), Q)
    with np.errstate(divide="ignore", invalid="ignore"):
        h1 = Q / (2.0 * s)
    h = np.where(s > np.abs(h2), h1, h2)
    out = np.empty((len(P), 4))
    # t^2 - s t + (y + h) = 0 and t^2 + s t + (y - h) = 0.
    for k, (bb, cc) in enumerate(((-s, y + h), (s, y - h))):
        disc = bb * bb - 4.0 * cc
        sd = np.sqrt(np.maximum(disc, 0.0))
        out[:, 2 * k] = 0.5 * (-bb - sd)
        out[:, 2 * k + 1] = 0.5 * (-bb + sd)
    return out


def _accept(t, P, Q, R, qa, qq, az, Ro, Ri):
    """Newton-polish candidate roots t (n, 4) on the quartic and keep those on the torus (distance to the tube
    <= TANGENT_TOL); the others become +inf. Returns (t, distance to the tube)."""
    Pc, Qc, Rc = P[:, None], Q[:, None], R[:, None]
    for _ in range(NEWTON_STEPS):
        f = ((t * t + Pc) * t + Qc) * t + Rc
        df = (4.0 * t * t + 2.0 * Pc) * t + Qc
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            step = np.where(np.abs(df) > 1e-300, f / df, 0.0)
        # Keep the polish local (a double root makes Newton slow, never far).
        t = t - np.clip(step, -1e-3, 1e-3)
    h = qa[:, None] + t * az[:, None]
    rho = np.sqrt(np.maximum(qq[:, None] + t * t - h * h, 0.0))
    g = np.abs(np.sqrt((rho - Ro) ** 2 + h * h) - Ri)
    return np.where(g <= TANGENT_TOL, t, np.inf), g


def lowest_z(tool: ZTool, tips: np.ndarray, axes: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Lowest z of the tool solid at (tips[k], axes[k]) on the vertical line at xy[k] (row-wise pairs),
    +inf where the line misses the tool. Axes must be unit with a_z > 0 (the tool pointing down)."""
    tips = np.asarray(tips, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    if np.any(axes[:, 2] <= 1e-6):
        raise TmmError("z-map: the tool axis must point upwards (a_z > 0) for a vertical needle simulation")
    C = tips + tool.Ri * axes
    q = xy - C[:, :2]
    z = _torus_lowest(C, axes, q, tool.Ro, tool.Ri)
    z = np.minimum(z, _half_cylinder_lowest(C, axes, q, tool.radius, 0.0))
    if tool.shape == "bull_nose" and tool.Ro > 0:
        z = np.minimum(z, _half_cylinder_lowest(C, axes, q, tool.Ro, -tool.Ri))
    return z + C[:, 2]


# ---------------------------------------------------------------------------------------------------------
# Motion: interpolation and sub-stepping.
# ---------------------------------------------------------------------------------------------------------

def interpolate_axis(a0: np.ndarray, a1: np.ndarray, s: np.ndarray, mode: str = "slerp") -> np.ndarray:
    """Unit axes between a0 and a1 at parameters s (m,): "slerp" (constant angular rate) or "nlerp"."""
    a0 = np.asarray(a0, dtype=float)
    a1 = np.asarray(a1, dtype=float)
    s = np.asarray(s, dtype=float)[:, None]
    if mode == "nlerp":
        v = (1.0 - s) * a0 + s * a1
        return v / np.linalg.norm(v, axis=1, keepdims=True)
    if mode != "slerp":
        raise TmmError(f"axis interpolation must be 'slerp' or 'nlerp', got {mode!r}")
    return slerp(a0, a1, s)


def substeps(tool: ZTool, tip0, a0, tip1, a1, max_step: float) -> int:
    """Number of equal steps so that no torus point moves more than max_step between instances."""
    d = float(np.linalg.norm(np.asarray(tip1, float) - np.asarray(tip0, float)))
    th = math.acos(float(np.clip(np.dot(a0, a1), -1.0, 1.0)))
    return max(1, math.ceil((d + th * tool.reach) / max_step - 1e-12))


def move_instances(tool: ZTool, tips: np.ndarray, axes: np.ndarray, max_step: float, interp: str = "slerp",
                   refine: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """All tool instances (tips, axes) of the linear moves along the polyline of positions, each move cut
    into refine * substeps(...) equal steps; the positions themselves are included."""
    tips = np.asarray(tips, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    out_t, out_a = [tips[:1]], [axes[:1]]
    for k in range(len(tips) - 1):
        n = refine * substeps(tool, tips[k], axes[k], tips[k + 1], axes[k + 1], max_step)
        s = np.arange(1, n + 1) / n
        out_t.append((1.0 - s)[:, None] * tips[k] + s[:, None] * tips[k + 1])
        out_a.append(interpolate_axis(axes[k], axes[k + 1], s, interp))
    return np.vstack(out_t), np.vstack(out_a)


# ---------------------------------------------------------------------------------------------------------
# Needles.
# ---------------------------------------------------------------------------------------------------------

def cut(tool: ZTool, needles: np.ndarray, z: np.ndarray, tips: np.ndarray, axes: np.ndarray,
             chunk: int = 256) -> int:
    """Lower the heights z (N,) of the needles (N, 2) in place by the tool at every instance (tips, axes);
    returns the number of quartic solves. Pairs are pruned by exact bounds only: every tool point has
    h >= -Ri (the plane below the torus), and the torus lies in the ball |x - C| <= Ro + Ri; the shank
    (half-cylinder, closed form) is solved for every pair the plane bound keeps."""
    needles = np.asarray(needles, dtype=float).reshape(-1, 2)
    tips = np.asarray(tips, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    Rt, Ri = tool.radius, tool.Ri
    solves = 0
    nx, ny = needles[:, 0], needles[:, 1]
    for c0 in range(0, len(tips), chunk):
        T = tips[c0:c0 + chunk]
        A = axes[c0:c0 + chunk]
        C = T + Ri * A
        dx = nx[None, :] - C[:, 0:1]
        dy = ny[None, :] - C[:, 1:2]
        qa = dx * A[:, 0:1] + dy * A[:, 1:2]
        az = A[:, 2:3]
        zlb = C[:, 2:3] + (-Ri - qa) / az          # plane h = -Ri: below every tool point
        cand = zlb < z[None, :]
        ii, jj = np.nonzero(cand)
        if len(ii) == 0:
            continue
        Ci, Ai = C[ii], A[ii]
        q = needles[jj] - Ci[:, :2]
        # Shank and hollow cover: exact, cheap.
        zz = _half_cylinder_lowest(Ci, Ai, q, Rt, 0.0)
        if tool.shape == "bull_nose" and tool.Ro > 0:
            zz = np.minimum(zz, _half_cylinder_lowest(Ci, Ai, q, tool.Ro, -Ri))
        # Torus: only lines within Rt of C horizontally can meet it (it lies in the ball |x - C| <= Rt), and
        # only if the ball's lowest point on the line is below the needle.
        qq = q[:, 0] ** 2 + q[:, 1] ** 2
        near = qq <= Rt * Rt
        ball_lb = np.where(near, -np.sqrt(np.maximum(Rt * Rt - qq, 0.0)), np.inf)
        need = near & (np.maximum(ball_lb, zlb[ii, jj] - Ci[:, 2]) + Ci[:, 2] < np.minimum(z[jj], zz + Ci[:, 2]))
        if need.any():
            zt = _torus_lowest(Ci[need], Ai[need], q[need], tool.Ro, Ri)
            zz[need] = np.minimum(zz[need], zt)
            solves += int(need.sum())
        np.minimum.at(z, jj, zz + Ci[:, 2])
    return solves


@dataclass
class SimulationReport:
    z: np.ndarray                     # final needle heights
    instances: int                    # tool instances at the last refinement
    refine: int                       # sub-step refinement factor reached (1, 2, 4, ...)
    last_change: float                # max needle change of the last refinement (mm)
    changes: list = field(default_factory=list)
    solves: int = 0


def simulate(tool: ZTool, needles: np.ndarray, z0, paths: Sequence[tuple[np.ndarray, np.ndarray]],
             max_step: float = 0.25, interp: str = "slerp", verify_tol: Optional[float] = 1e-3,
             max_refine: int = 16) -> SimulationReport:
    """Cut the needles (N, 2), starting at heights z0 (scalar or (N,)), by the tool moving linearly along each
    path (tips (m, 3), axes (m, 3)) in turn. With verify_tol, the sub-step is halved (only midpoints added)
    until no needle changes by more than verify_tol (or max_refine is reached)."""
    needles = np.asarray(needles, dtype=float).reshape(-1, 2)
    z = np.broadcast_to(np.asarray(z0, dtype=float), (len(needles),)).copy()
    solves = 0
    count = 0
    for tips, axes in paths:
        T, A = move_instances(tool, tips, axes, max_step, interp, 1)
        count += len(T)
        solves += cut(tool, needles, z, T, A)
    report = SimulationReport(z, count, 1, math.inf if verify_tol is not None else float("nan"), [], solves)
    if verify_tol is None:
        return report
    refine = 1
    while refine < max_refine:
        refine *= 2
        before = z.copy()
        count = 0
        for tips, axes in paths:
            T, A = move_instances(tool, tips, axes, max_step, interp, refine)
            count += len(T)
            # Odd-numbered instances are the new midpoints (the even ones were cut before).
            Tm, Am = _new_instances(T, A, tool, tips, axes, max_step, refine)
            report.solves += cut(tool, needles, z, Tm, Am)
        finite = np.isfinite(before)
        change = float(np.max(before[finite] - z[finite])) if finite.any() else 0.0
        report.changes.append(change)
        report.refine, report.instances, report.last_change = refine, count, change
        if change <= verify_tol:
            break
    report.z = z
    return report


def _new_instances(T, A, tool, tips, axes, max_step, refine):
    """The instances of refinement `refine` that were not in refinement refine // 2 (every other one)."""
    tips = np.asarray(tips, dtype=float).reshape(-1, 3)
    axes = np.asarray(axes, dtype=float).reshape(-1, 3)
    axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
    keep = np.zeros(len(T), dtype=bool)
    pos = 1
    for k in range(len(tips) - 1):
        n = refine * substeps(tool, tips[k], axes[k], tips[k + 1], axes[k + 1], max_step)
        idx = np.arange(1, n + 1)
        keep[pos:pos + n] = (idx % 2) == 1
        pos += n
    return T[keep], A[keep]
