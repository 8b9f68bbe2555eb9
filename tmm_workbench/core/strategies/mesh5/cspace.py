"""The 3D C-space at CC points (seed 000 section 3.5.5.1): on a (lambda, omega) grid, the bottom surface S2
(the lift that clears every triangle, lift.py) and the top surface S1 (the largest lift meeting the tolerance,
top_bound.py); a posture is available when S2 <= S1, and its C-space slice is the lifts between them. A CC
point with no available posture is marked for clean-up (seed: "inside a clean-up machining strip").

The seed builds S2 from five contact cases per facet (VTCBT, VTCBD, ETCBT, ETCBD, TTCBT) and intersects them;
here the kernel's exact drop along the tool axis gives S2 for all of them at once. Lifts are only asked where
the top bound is >= 0 (elsewhere the posture is unavailable whatever the lift), unless `all_lifts`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, List, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, require_plain
from tmm_workbench.core.strategies.mesh5.top_bound import profile_arcs, top_bounds
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]


@dataclass(frozen=True)
class CSpace:
    """The C-spaces of n CC points on a posture grid (nl, no): lift (S2) and top (S1) in mm, (n, nl, no).
    lift is NaN where it was not computed (top < 0: unavailable anyway), inf above the lift limit."""
    grid: PostureGrid
    lift: np.ndarray
    top: np.ndarray

    @property
    def available(self) -> np.ndarray:
        """(n, nl, no): gouge-free within the tolerance (S2 <= S1)."""
        with np.errstate(invalid="ignore"):
            return np.isfinite(self.lift) & (self.lift <= self.top)

    @property
    def empty(self) -> np.ndarray:
        """(n,): CC points with no available posture (for clean-up)."""
        return ~self.available.any(axis=(1, 2))

    def report(self, names: Optional[List[str]] = None) -> str:
        """One line: how many CC points have an empty C-space, and which (first few)."""
        e = np.flatnonzero(self.empty)
        if e.size == 0:
            return f"all {len(self.lift)} CC points have a non-empty C-space"
        which = [names[i] if names else f"#{i}" for i in e[:10]]
        more = f" and {e.size - 10} more" if e.size > 10 else ""
        return (f"{e.size} of {len(self.lift)} CC points have an empty C-space (left for clean-up): "
                f"{', '.join(which)}{more}")


def build_cspace(mesh: TriMesh | MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray,
                 grid: PostureGrid, tolerance: float, side_step, lift_limit: Optional[float] = None,
                 tool_length: Optional[float] = None, all_lifts: bool = False,
                 progress: Optional[Progress] = None, assembly: Optional[ToolAssembly] = None,
                 interior: int = 0, ask: Optional[np.ndarray] = None) -> CSpace:
    """The C-spaces at the n CC points (points (n, 3), frames (n, 3, 3) rows LX, LY, LZ, as cc_paths gives
    them). `side_step`: the half step-over on each side (number, (n,) or (n, 2): left +LY, right -LY).
    `lift_limit`: lifts above it count as unavailable (default: the largest finite top bound, at least the
    tolerance; with `all_lifts` the cutter radius). `assembly`: the cutter's ToolAssembly, whose shank and
    holder (with their clearances) then bound S2 too. `interior`: points checked inside each side step too
    (top_bounds). `ask` (n, nl, no) bool: the postures that may be taken at all (e.g. those whose axis the
    machine reaches); S2 is not asked elsewhere (NaN: unavailable)."""
    require_plain(cutter)
    reach = mesh if isinstance(mesh, MeshReach) else MeshReach(mesh)
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    if len(frm) != len(pts):
        raise TmmError(f"{len(pts)} CC points but {len(frm)} frames")
    shape = (len(pts),) + grid.shape
    if len(pts) == 0:
        return CSpace(grid, np.zeros(shape), np.zeros(shape))
    lam, omg = (g.ravel() for g in grid.mesh())
    top = top_bounds(reach, cutter, pts, frm, lam, omg, tolerance, side_step, profile_arcs(cutter, lam, omg),
                     interior)
    finite = top[np.isfinite(top)]
    if lift_limit is None:
        lift_limit = cutter.radius if all_lifts else max(float(tolerance), float(finite.max()) if finite.size else 0.0)
    elif not (isinstance(lift_limit, (int, float)) and math.isfinite(lift_limit) and lift_limit >= 0):
        raise TmmError(f"lift limit must be a finite number of mm >= 0, got {lift_limit!r}")
    mask = None if all_lifts else top >= 0
    if ask is not None:
        ask = np.asarray(ask, dtype=bool)
        if ask.shape != shape:
            raise TmmError(f"ask must be a {shape} array of postures, got shape {ask.shape}")
        ask = ask.reshape(len(pts), -1)
        mask = ask if mask is None else mask & ask
    lf = lifts(reach, cutter, pts, frm, lam, omg, float(lift_limit), mask, tool_length, progress, assembly)
    return CSpace(grid, lf.reshape(shape), top.reshape(shape))
