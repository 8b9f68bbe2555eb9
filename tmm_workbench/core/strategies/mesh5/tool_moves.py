"""The tool positions of a planned 5-axis pass beyond its CL points: the overruns beyond both ends of a path
and the positions inserted between two CL points where the straight move would cut into the mesh, each lifted
clear along its axis by the C-space's own least lift (lift.lifts, S2)."""
from __future__ import annotations

from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.optimal import PassPostures
from tmm_workbench.core.strategies.mesh5.posture import tool_rotation, touch_tip, world_placement
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

# positions along each overrun, each lifted clear of the mesh (a radius in 4: about the CC points' spacing)
OVERRUN_STEPS = 4
# between_positions: the deepest a straight move between two tool positions may cut into the mesh (mm), how many
# times a move is halved to keep it there, and the most (tool radii) a middle is lifted before the move is refused
BETWEEN_TOL, BETWEEN_ROUNDS, FAR_RADII = 0.002, 2, 4.0

def overrun_positions(reach: MeshReach, cutter: Cutter, path: CCPath, postures: PassPostures, overrun: float,
                      steps: int = OVERRUN_STEPS, assembly: Optional[ToolAssembly] = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(tips, axes, LCS frames) of the path's tool with its overruns: `overrun` mm beyond both end CC points along their
    feed LX at the end postures (at the ends the CC point lies on the mesh's boundary, and a tool stopping
    there would narrow its track within a radius of it), in `steps` positions each, every one lifted along
    the axis by the least lift that clears the mesh there (the C-space's S2 at that place). Straight along
    LX at the end's own lift, the tool ran into the mesh where it goes on beyond the path's end (a boundary
    slanted across the planes, the tool's body yawed over the surface beside the path: 0.07 mm deep on seed
    000's concave surface). An overrun stops before a position no lift within the tool's radius clears."""
    s = overrun * np.arange(1, steps + 1) / steps
    ends = []
    for k, sgn in ((0, -1.0), (-1, 1.0)):
        frame = path.frames[k]
        pts = path.points[k] + sgn * s[:, None] * frame[0]
        frm = np.repeat(frame[None], steps, 0)
        lam, omg = np.array([postures.lam[k]]), np.array([postures.omg[k]])
        lift = lifts(reach, cutter, pts, frm, lam, omg, cutter.radius, assembly=assembly)[:, 0]
        blocked = np.flatnonzero(~np.isfinite(lift))
        keep = int(blocked[0]) if blocked.size else steps
        tips, axes = world_placement(cutter, pts[:keep], frm[:keep], np.repeat(lam, keep),
                                     np.repeat(omg, keep), lift[:keep])
        ends.append((tips, axes, frm[:keep]))
    (t0, a0, f0), (t1, a1, f1) = ends
    return (np.concatenate([t0[::-1], postures.tips, t1]), np.concatenate([a0[::-1], postures.axes, a1]),
            np.concatenate([f0, path.frames, f1]))


def clear_lifts(reach: MeshReach, cutter: Cutter, tips: np.ndarray, axes: np.ndarray,
                frames: np.ndarray, assembly: Optional[ToolAssembly] = None, radii: float = 1.0) -> np.ndarray:
    """(n,) the least lift along its axis that clears the mesh for the tool at each (tip, axis) (0 where it is
    clear already; inf above `radii` tool radii), by the C-space's S2 (lift.lifts): the posture read in the LCS
    `frames` (n, 3, 3) of a CC point nearby, the tip's touching point as the CC point."""
    a = np.einsum("nij,nj->ni", frames, axes)                              # the axis in each LCS
    lam, omg = np.arccos(np.clip(a[:, 2], -1.0, 1.0)), np.arctan2(a[:, 1], a[:, 0])
    pts = tips - np.einsum("nji,nj->ni", frames, touch_tip(cutter, tool_rotation(lam, omg)))
    return lifts(reach, cutter, pts, frames, lam, omg, radii * cutter.radius, paired=True, assembly=assembly)


def between_positions(reach: MeshReach, cutter: Cutter, tips: np.ndarray, axes: np.ndarray, frames: np.ndarray,
                      tol: float = BETWEEN_TOL, rounds: int = BETWEEN_ROUNDS,
                      assembly: Optional[ToolAssembly] = None) -> tuple[np.ndarray, np.ndarray]:
    """The run's positions (tips, axes, their LCS frames (n, 3, 3)) with a position inserted in the middle of
    each move whose midpoint (tip halfway, axis halfway) cuts into the mesh deeper than `tol`, lifted clear
    along its axis; `rounds` times. The C-space clears the tool at the CL points; between two, the move is a
    straight line, and where the least lift curves along the pass (a surface concave along the feed, a saddle)
    the line sags into the surface by about step^2 / (8 radius)."""
    for _ in range(rounds):
        if len(tips) < 2:
            break
        mid_t = 0.5 * (tips[:-1] + tips[1:])
        mid_a = axes[:-1] + axes[1:]
        mid_a /= np.linalg.norm(mid_a, axis=1, keepdims=True)               # slerp at one half
        lift = clear_lifts(reach, cutter, mid_t, mid_a, frames[:-1], assembly)
        far = np.flatnonzero(~np.isfinite(lift))   # deeper than a radius: asked again, never left to gouge
        if far.size:
            lift[far] = clear_lifts(reach, cutter, mid_t[far], mid_a[far], frames[far], assembly, FAR_RADII)
        if not np.isfinite(lift).all():
            k = int(np.argmin(np.isfinite(lift)))
            raise TmmError(f"the move from {np.round(tips[k], 3).tolist()} to {np.round(tips[k + 1], 3).tolist()}"
                           f" would cut the model: no lift of {FAR_RADII:g} tool radii clears its middle")
        deep = np.flatnonzero(lift > tol)
        if deep.size == 0:
            break
        at = deep + 1
        tips = np.insert(tips, at, mid_t[deep] + lift[deep, None] * mid_a[deep], axis=0)
        axes = np.insert(axes, at, mid_a[deep], axis=0)
        frames = np.insert(frames, at, frames[deep], axis=0)
    return tips, axes

