"""A face of Bézier patches for the kernel (any degree; B-splines split exactly by knot insertion), evaluated
exactly. FreeCAD surfaces are turned into one by the App layer (app.geometry.bezier_face)."""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.bspline import BezierPieces, bspline_to_bezier
from tmm_workbench.core.geometry.rect import Rect
from tmm_workbench.core.kernel import native


class BezierFace:
    """A face of nu x nv Bézier patches (any degree) in the kernel, evaluated exactly."""

    def __init__(self, nets: Sequence[np.ndarray], nu: int = 1, nv: int = 1,
                 breaks_u: Optional[Sequence[float]] = None, breaks_v: Optional[Sequence[float]] = None,
                 name: str = "face") -> None:
        arrs = [np.ascontiguousarray(n, dtype=np.float64) for n in nets]
        for a in arrs:
            if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] < 2 or a.shape[1] < 2:
                raise TmmError(f"{name}: a Bézier control net must have shape (p+1, q+1, 3), p, q >= 1; got {a.shape}")
            if not np.isfinite(a).all():
                raise TmmError(f"{name}: Bézier control net has a non-finite coordinate")
        bu = list(map(float, breaks_u)) if breaks_u is not None else list(np.linspace(0.0, float(nu), nu + 1))
        bv = list(map(float, breaks_v)) if breaks_v is not None else list(np.linspace(0.0, float(nv), nv + 1))
        self.name = name
        try:
            self._surface = native.PatchSurface(arrs, int(nu), int(nv), bu, bv)
        except ValueError as exc:
            raise TmmError(f"{name}: {exc}") from exc

    @classmethod
    def from_net(cls, net: np.ndarray, name: str = "face") -> "BezierFace":
        return cls([net], 1, 1, [0.0, 1.0], [0.0, 1.0], name=name)

    @classmethod
    def from_pieces(cls, pieces: BezierPieces, name: str = "face") -> "BezierFace":
        return cls(pieces.nets, pieces.nu, pieces.nv, pieces.breaks_u, pieces.breaks_v, name=name)

    @classmethod
    def from_bspline(cls, poles, degree_u: int, degree_v: int, knots_u, mults_u, knots_v, mults_v,
                     weights=None, periodic_u: bool = False, periodic_v: bool = False,
                     name: str = "face") -> "BezierFace":
        """Exact: the B-spline split into its Bézier patches by knot insertion (see core.bspline)."""
        return cls.from_pieces(bspline_to_bezier(poles, degree_u, degree_v, knots_u, mults_u, knots_v, mults_v,
                                                 weights, periodic_u, periodic_v), name=name)

    @property
    def native(self):
        return self._surface

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return self._surface.domain

    @property
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Box of the control nets (it holds the face)."""
        return self._surface.bounds

    def evaluate(self, uv: np.ndarray) -> dict[str, np.ndarray]:
        """S, Su, Sv, Suu, Suv, Svv at (n, 2) global parameters."""
        return self._surface.evaluate(np.ascontiguousarray(uv, dtype=np.float64).reshape(-1, 2))

    def xy_extent(self, samples: int = 64) -> Rect:
        """XY extent of the face itself (sampled densely, not the control hull)."""
        u0, u1, v0, v1 = self.domain
        u = np.linspace(u0, u1, samples + 1)
        v = np.linspace(v0, v1, samples + 1)
        U, V = np.meshgrid(u, v, indexing="ij")
        S = self.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
        return float(S[:, 0].min()), float(S[:, 1].min()), float(S[:, 0].max()), float(S[:, 1].max())
