"""Drop along any direction with the cutter axis in any orientation (seed 000 eq. 3.126-3.188: clean-up by
translating the cutter along a vector V; a fixed tilted axis gives 3+2 machining).

The cutter moves with its tip at ``start + t * direction`` from t = -inf until it first touches the mesh; the
travel t of that contact is returned with the tip position. Only the cutting part of the tool is checked
(up to its cutting length); the shank and the holder are not. With the axis opposite to the direction
(e.g. direction -Z, axis +Z) this is the plain drop-cutter: travel = start z - tip height.
"""
from __future__ import annotations

import math
from typing import Callable, Optional, Tuple

import numpy as np

from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.geometry.mesh import TriMesh

Progress = Callable[[float], bool]

_UNIT_TOL = 1e-9
_AXIS_OPPOSITE_TOL = 1e-12


def _unit(name: str, v: object) -> np.ndarray:
    try:
        a = np.asarray(v, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise TmmError(f"{name} must be 3 numbers, got {v!r}") from exc
    if a.shape != (3,):
        raise TmmError(f"{name} must have 3 components, got {a.size}")
    if not np.isfinite(a).all():
        raise TmmError(f"{name} contains a non-finite component: {a.tolist()}")
    n = float(np.linalg.norm(a))
    if n == 0:
        raise TmmError(f"{name} is the zero vector")
    if abs(n - 1.0) > _UNIT_TOL:
        raise TmmError(f"{name} must be a unit vector, got length {n:.12g}")
    return a


def _unit_rows(name: str, v: np.ndarray) -> np.ndarray:
    if not np.isfinite(v).all():
        raise TmmError(f"{name} contain a non-finite component")
    n = np.linalg.norm(v, axis=1)
    bad = np.flatnonzero(np.abs(n - 1.0) > _UNIT_TOL)
    if bad.size:
        i = int(bad[0])
        raise TmmError(f"{name} must be unit vectors; row {i} has length {n[i]:.12g}")
    return v


def _native_cutter(cutter: Cutter, needs_length: bool) -> "native.Cutter":
    """The kernel cutter. A tilted drop needs the cutting length: plain cutters carry it only in Python."""
    if not needs_length:
        return cutter.native
    if not math.isfinite(cutter.cutting_length):
        raise TmmError(f"a drop with the axis not opposite to the direction needs the cutting length of the "
                       f"{cutter.describe()} cutter (the cutter is modelled up to it; the shank is not)")
    if cutter.is_plain:
        try:
            return native.Cutter.apt(cutter.radius, cutter.corner_radius, float(cutter.cutting_length), 0.0, 0.0)
        except ValueError as exc:
            raise TmmError(f"impossible cutter {cutter.describe()}: {exc}") from exc
    return cutter.native


def check_starts(starts: np.ndarray, axis, direction: np.ndarray,
                 max_travel: float) -> Tuple[np.ndarray, np.ndarray, bool]:
    """The (n, 3) starts and the axes ((3,) or (n, 3) unit vectors) as float arrays, max_travel checked; and
    whether every axis is opposite to the unit `direction` (the drop along the tool's own axis)."""
    pts = np.ascontiguousarray(starts, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise TmmError(f"start points must have shape (n, 3), got {pts.shape}")
    if not np.isfinite(pts).all():
        raise TmmError("start points contain a non-finite coordinate")
    if isinstance(max_travel, bool) or not isinstance(max_travel, (int, float)) or math.isnan(max_travel):
        raise TmmError(f"max_travel must be a number, got {max_travel!r}")
    ax = np.ascontiguousarray(axis, dtype=np.float64)
    if ax.ndim == 2:
        if ax.shape != pts.shape:
            raise TmmError(f"axes must have shape (3,) or {pts.shape}, got {ax.shape}")
        axes = _unit_rows("cutter axes", ax)
        opposite = bool(np.all(np.linalg.norm(axes + direction, axis=1) <= _AXIS_OPPOSITE_TOL))
    else:
        axes = _unit("cutter axis", ax)
        opposite = float(np.linalg.norm(axes + direction)) <= _AXIS_OPPOSITE_TOL
    return pts, axes, opposite


class DirectionalDrop:
    """A mesh indexed for drops along one unit `direction` (build once per direction, e.g. per 3+2 setup)."""

    def __init__(self, mesh: TriMesh, direction) -> None:
        self.mesh = mesh
        self.direction = _unit("drop direction", direction)
        try:
            self._index = native.DirectionalIndex(mesh.vertices, mesh.triangles, self.direction)
        except ValueError as exc:
            raise TmmError(f"{mesh.name}: {exc}") from exc

    @property
    def index(self) -> "native.DirectionalIndex":
        """The kernel's index of the mesh for this direction (shared by the tool assembly's drop)."""
        return self._index

    def drop(self, cutter: Cutter, starts: np.ndarray, axis, max_travel: float = math.inf,
             progress: Optional[Progress] = None, threads: int = 0) -> Tuple[np.ndarray, np.ndarray]:
        """Travel (n,) and tip positions (n, 3) of the first contact from each (n, 3) start along the direction.
        `axis`: one unit vector (3,) or one per start (n, 3). Where nothing is touched within `max_travel`
        the travel is `max_travel` (inf by default: then the tip position is NaN)."""
        pts, axes, opposite = check_starts(starts, axis, self.direction, max_travel)
        ncut = _native_cutter(cutter, needs_length=not opposite)
        try:
            travel = native.drop_along(self._index, ncut, pts, axes, float(max_travel), threads, progress)
        except native.Cancelled as exc:
            raise Cancelled("tool path computation cancelled") from exc
        except ValueError as exc:
            raise TmmError(str(exc)) from exc
        with np.errstate(invalid="ignore"):
            tips = pts + travel[:, None] * self.direction[None, :]
        tips[~np.isfinite(travel)] = np.nan
        return travel, tips


def drop_along(mesh: TriMesh, cutter: Cutter, starts: np.ndarray, axis, direction,
               progress: Optional[Progress] = None, max_travel: float = math.inf,
               threads: int = 0) -> Tuple[np.ndarray, np.ndarray]:
    """One-shot DirectionalDrop(mesh, direction).drop(...): travel (n,) and tip positions (n, 3)."""
    return DirectionalDrop(mesh, direction).drop(cutter, starts, axis, max_travel, progress, threads)
