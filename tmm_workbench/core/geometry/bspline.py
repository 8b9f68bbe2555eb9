"""Exact conversion of a B-spline surface into Bézier patches by knot insertion (Boehm), with numpy.

Every distinct knot inside the parameter range is inserted until its multiplicity equals the degree; the
poles between two consecutive breakpoints are then the control net of that span's Bézier patch. Knot
insertion does not change the surface, so the patches are the B-spline exactly (up to rounding).

Supported: non-rational, non-periodic (clamped or unclamped) surfaces of any degree. Rational surfaces whose
weights are all 1 are taken as non-rational; other rational surfaces are refused (TmmError): a rational
patch is not a polynomial Bézier patch. Periodic surfaces are refused too: make them non-periodic first
(in FreeCAD: `surface.setUNotPeriodic()`, `surface.setVNotPeriodic()`, which keeps the geometry).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError


@dataclass
class BezierPieces:
    """nu x nv Bézier nets (row-major over (i in u, j in v)) and the breakpoints they span."""
    nets: list[np.ndarray]
    nu: int
    nv: int
    breaks_u: np.ndarray
    breaks_v: np.ndarray


def flat_knots(knots: Sequence[float], mults: Sequence[int]) -> np.ndarray:
    """Knot values repeated by their multiplicities."""
    k = np.asarray(knots, dtype=float)
    m = np.asarray(mults, dtype=int)
    if k.ndim != 1 or k.shape != m.shape or len(k) < 2:
        raise TmmError(f"knots and multiplicities must be two lists of the same length >= 2, got {k.shape}, {m.shape}")
    if np.any(np.diff(k) <= 0):
        raise TmmError("knots must increase strictly (repeats go in the multiplicities)")
    if np.any(m < 1):
        raise TmmError("knot multiplicities must be >= 1")
    return np.repeat(k, m)


def _insert(poles: np.ndarray, U: list[float], p: int, t: float, left: bool) -> np.ndarray:
    """Insert t once into knot vector U (in place) of a curve family along axis 0 of `poles`; new poles.

    left: use the span ending at t (for the right end of the range)."""
    n = poles.shape[0]
    if left:
        k = max(i for i in range(len(U) - 1) if U[i] < t)
    else:
        k = max(i for i in range(len(U) - 1) if U[i] <= t)
    new = np.empty((n + 1,) + poles.shape[1:])
    new[: k - p + 1] = poles[: k - p + 1]
    for i in range(k - p + 1, k + 1):
        den = U[i + p] - U[i]
        a = 0.0 if den == 0 else (t - U[i]) / den
        new[i] = (1.0 - a) * poles[i - 1] + a * poles[i]
    new[k + 1:] = poles[k:]
    U.insert(k + 1, t)
    return new


def _to_bezier_1d(poles: np.ndarray, U: np.ndarray, p: int) -> tuple[np.ndarray, list[int], np.ndarray]:
    """Knot insertion along axis 0; returns the refined poles, the first pole index of each span's Bézier
    piece and the breakpoints."""
    n = poles.shape[0]
    if len(U) != n + p + 1:
        raise TmmError(f"a B-spline of degree {p} with {n} poles needs {n + p + 1} flat knots, got {len(U)}")
    a, b = U[p], U[n]
    if not b > a:
        raise TmmError("empty B-spline parameter range")
    knots = list(map(float, U))
    for t in np.unique(U[(U >= a) & (U <= b)]):
        s = sum(1 for x in knots if x == t)
        for _ in range(max(0, p - s)):
            poles = _insert(poles, knots, p, float(t), left=(t == b))
    breaks = np.unique(np.asarray(knots)[(np.asarray(knots) >= a) & (np.asarray(knots) <= b)])
    starts = []
    for d in breaks[:-1]:
        k = max(i for i in range(len(knots) - 1) if knots[i] <= d and knots[i + 1] > d)
        starts.append(k - p)
    return poles, starts, breaks


def bspline_to_bezier(poles, degree_u: int, degree_v: int, knots_u: Sequence[float], mults_u: Sequence[int],
                      knots_v: Sequence[float], mults_v: Sequence[int], weights: Optional[np.ndarray] = None,
                      periodic_u: bool = False, periodic_v: bool = False) -> BezierPieces:
    """Bézier pieces of a B-spline surface given as FreeCAD/OCC gives it (poles (nu, nv, 3), degrees, distinct
    knots with multiplicities per direction, optional weights (nu, nv), periodic flags)."""
    P = np.asarray(poles, dtype=float)
    if P.ndim != 3 or P.shape[2] != 3:
        raise TmmError(f"B-spline poles must have shape (nu, nv, 3), got {P.shape}")
    if not np.isfinite(P).all():
        raise TmmError("B-spline poles contain a non-finite coordinate")
    if periodic_u or periodic_v:
        raise TmmError("periodic B-spline surfaces are not supported: make them non-periodic first "
                       "(FreeCAD: setUNotPeriodic() / setVNotPeriodic(), the geometry is kept)")
    if weights is not None:
        w = np.asarray(weights, dtype=float)
        if w.shape != P.shape[:2]:
            raise TmmError(f"weights must have shape {P.shape[:2]}, got {w.shape}")
        if np.max(np.abs(w - 1.0)) > 1e-12:
            raise TmmError("rational B-spline surface (weights not all 1) is not supported: a rational patch is "
                           "not a polynomial Bézier patch")
    p, q = int(degree_u), int(degree_v)
    if p < 1 or q < 1:
        raise TmmError(f"B-spline degrees must be >= 1, got {p} x {q}")
    U = flat_knots(knots_u, mults_u)
    V = flat_knots(knots_v, mults_v)
    Pu, su, bu = _to_bezier_1d(P, U, p)
    Puv, sv, bv = _to_bezier_1d(np.swapaxes(Pu, 0, 1), V, q)
    Puv = np.swapaxes(Puv, 0, 1)
    nets = [np.ascontiguousarray(Puv[i0:i0 + p + 1, j0:j0 + q + 1]) for i0 in su for j0 in sv]
    return BezierPieces(nets, len(su), len(sv), bu, bv)
