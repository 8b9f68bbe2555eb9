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
# times a move is split to keep it there, and the most (tool radii) a middle is lifted before the move is refused
BETWEEN_TOL, BETWEEN_ROUNDS, FAR_RADII = 0.002, 8, 4.0

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
    ends = []
    for k, sgn in ((0, -1.0), (-1, 1.0)):
        # an end moved inside the mesh (CCPath.inset): the overrun goes that much further (from the moved end,
        # a radius on left the tool's centre short of the mesh's edge by the inset, and its bottom's chord
        # there too short to reach the scallop between two passes: seed 000's complex surface, 1.69 mm)
        run = overrun + (0.0 if path.cut_short[k] else path.inset[k])
        n = max(steps, int(round(steps * run / overrun))) if overrun > 0 else steps
        s = run * np.arange(1, n + 1) / n
        frame = path.frames[k]
        pts = path.points[k] + sgn * s[:, None] * frame[0]
        frm = np.repeat(frame[None], n, 0)
        lam, omg = np.array([postures.lam[k]]), np.array([postures.omg[k]])
        lift = lifts(reach, cutter, pts, frm, lam, omg, cutter.radius, assembly=assembly)[:, 0]
        blocked = np.flatnonzero(~np.isfinite(lift))
        keep = int(blocked[0]) if blocked.size else n
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


def _halfway(t0: np.ndarray, t1: np.ndarray, a0: np.ndarray, a1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The position halfway along each move: tip linear, axis by slerp at one half (the normalised sum)."""
    a = a0 + a1
    return 0.5 * (t0 + t1), a / np.linalg.norm(a, axis=-1, keepdims=True)


def between_positions(reach: MeshReach, cutter: Cutter, tips: np.ndarray, axes: np.ndarray, frames: np.ndarray,
                      tol: float = BETWEEN_TOL, rounds: int = BETWEEN_ROUNDS,
                      assembly: Optional[ToolAssembly] = None) -> tuple[np.ndarray, np.ndarray]:
    """The run's positions (tips, axes, their LCS frames (n, 3, 3)) with a position inserted into each move
    that cuts into the mesh deeper than `tol` at its quarter, middle or three-quarter point (tip linear, axis
    slerp), at the deepest of them, lifted clear along its axis; the two new moves checked again, up to
    `rounds` times. The C-space clears the tool at the CL points; between two, the move is a straight line,
    and where the least lift curves along the pass (a surface concave along the feed, a saddle) the line sags
    into the surface by about step^2 / (8 radius). The middle alone misses a move whose tool's side passes
    over the mesh's edge near one end (an overrun off a steep edge: 0.13 mm at three quarters, none at the
    middle)."""
    fresh = np.ones(max(len(tips) - 1, 0), dtype=bool)
    for _ in range(rounds):
        k = np.flatnonzero(fresh)
        if k.size == 0:
            break
        mt, ma = _halfway(tips[k], tips[k + 1], axes[k], axes[k + 1])
        qt, qa = _halfway(tips[k], mt, axes[k], ma)
        rt, ra = _halfway(mt, tips[k + 1], ma, axes[k + 1])
        # the middle first: of equal lifts the middle is taken
        at_t, at_a = np.stack([mt, qt, rt], 1).reshape(-1, 3), np.stack([ma, qa, ra], 1).reshape(-1, 3)
        frm = np.repeat(frames[k], 3, axis=0)
        lift = clear_lifts(reach, cutter, at_t, at_a, frm, assembly)
        far = np.flatnonzero(~np.isfinite(lift))   # deeper than a radius: asked again, never left to gouge
        if far.size:
            lift[far] = clear_lifts(reach, cutter, at_t[far], at_a[far], frm[far], assembly, FAR_RADII)
        if not np.isfinite(lift).all():
            j = k[int(np.argmin(np.isfinite(lift))) // 3]
            raise TmmError(f"the move from {np.round(tips[j], 3).tolist()} to {np.round(tips[j + 1], 3).tolist()}"
                           f" would cut the model: no lift of {FAR_RADII:g} tool radii clears it")
        lift = lift.reshape(-1, 3)
        worst = np.argmax(lift, axis=1)
        pick = np.arange(len(k)) * 3 + worst
        deep = lift[np.arange(len(k)), worst] > tol
        if not deep.any():
            break
        split = np.zeros(len(fresh), dtype=bool)
        split[k[deep]] = True
        at, new = k[deep] + 1, pick[deep]
        tips = np.insert(tips, at, at_t[new] + lift.reshape(-1)[new, None] * at_a[new], axis=0)
        axes = np.insert(axes, at, at_a[new], axis=0)
        frames = np.insert(frames, at, frames[k[deep]], axis=0)
        fresh = np.repeat(split, np.where(split, 2, 1))
    return tips, axes
