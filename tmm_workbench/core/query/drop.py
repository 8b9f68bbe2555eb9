"""Drop-cutter over a mesh: the kernel's spatial index and batch query, with core errors."""
from __future__ import annotations

import math
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.geometry.mesh import TriMesh

Progress = Callable[[float], bool]


class DropSurface:
    """A mesh indexed for drop-cutter queries along -Z. Build once, drop many cutters and points."""

    def __init__(self, mesh: TriMesh, progress: Optional[Progress] = None) -> None:
        """Indexes `mesh` (seconds for millions of triangles): reports to `progress`, or without one asks the
        strategy's watched callback (core.cancel); Cancelled when either says stop."""
        self.mesh = mesh
        try:
            self._index = cancel.native_call(native.MeshIndex, mesh.vertices, mesh.triangles, progress=progress)
        except ValueError as exc:
            raise TmmError(f"{mesh.name}: {exc}") from exc

    @property
    def index(self) -> "native.MeshIndex":
        """The kernel's spatial index of the mesh, for other kernel queries over the same mesh (waterline)."""
        return self._index

    def drop(self, cutter: Cutter, xy: np.ndarray, floor_z: float,
             progress: Optional[Progress] = None, threads: int = 0) -> np.ndarray:
        """Tip heights (n,) of `cutter` dropped at the (n, 2) points `xy`: the lowest tip position on or
        above `floor_z` where the cutter touches the mesh without penetrating it."""
        pts = np.ascontiguousarray(xy, dtype=np.float64).reshape(-1, 2)
        if not np.isfinite(pts).all():
            raise TmmError("drop points contain a non-finite coordinate")
        floor = float(floor_z)
        if math.isnan(floor):  # every height would come back NaN
            raise TmmError("drop floor_z is NaN: it must be a finite height (mm)")
        if progress is None:  # a drop deep in a helper still honours the strategy's cancel (core.cancel)
            progress = cancel.asker()
        try:
            return native.drop_cutter(self._index, cutter.native, pts, floor, threads, progress)
        except native.Cancelled as exc:
            raise Cancelled("tool path computation cancelled") from exc
        except ValueError as exc:  # the kernel's range (points, floor) with its message
            raise TmmError(f"{self.mesh.name}: {exc}") from exc
