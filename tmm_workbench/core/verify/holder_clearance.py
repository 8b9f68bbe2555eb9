"""A finished tool path checked against the model for the tool's neck, shank and holder: every move sampled
along its length (arcs along the arc; 5-axis moves with the tip on its straight line and the axis by slerp,
as the simulation and the machine model interpolate), and at each sample whether a piece above the cutter
comes closer to the model than its clearance. The flutes and the cutter are the cutting tool: not checked.

Vertical tool (3-axis samples): the assembly drop of the pieces alone (query.drop_assembly, exact against
the triangles): a piece collides where it would hold the tip higher than the path has it; the intrusion is
vertical, how far the tool must rise. Tilted tool: the vertical drop does not apply; the exact distance from
a point sample of the model's surface to each tilted frustum (verify.body_distance); the intrusion is along
the normal, measured to the sample (at most `surface_step` / sqrt(3) short of the surface's).

`minimum_stick_out`: the shortest stick-out at which the holder sets no height at a 3-axis path's CL points.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Callable, Optional, Union

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_assembly import SET_BY_FLOOR, AssemblyDrop
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.verify.body_distance import SurfacePoints

Progress = Callable[[float], bool]
CHECKED = ("neck", "shank", "holder")
ARC_TOLERANCE = 1e-3  # mm: arcs read as chords this close, then sampled along the chords
_VERTICAL = 1e-12     # 1 - axis z below which the tool counts as vertical (tilt < 1.5e-6 rad)


def _length(what: str, v: object, allow_zero: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0 \
            or (v == 0 and not allow_zero):
        raise TmmError(f"{what} must be a finite length {'>= 0' if allow_zero else '> 0'} mm, got {v!r}")
    return float(v)


@dataclass
class HolderClearance:
    """The colliding samples of a holder clearance check, one row each, and what was checked."""
    assembly: str                  # the assembly's description
    samples: int                   # positions checked along the path
    moves: int
    tilted_samples: int            # of them with the tool off vertical (checked by distance)
    move: np.ndarray               # (k,) index of the move each colliding sample lies on
    piece: np.ndarray              # (k,) 'neck', 'shank' or 'holder'
    tip: np.ndarray                # (k, 3) tool tip
    axis: np.ndarray               # (k, 3) tool axis
    contact: np.ndarray            # (k, 3) the model point closest inside the clearance (NaN: not located)
    intrusion: np.ndarray          # (k,) mm closer than the clearance (vertical for a vertical tool)
    seconds: float = 0.0
    clearances: dict = field(default_factory=dict)  # piece -> its clearance (mm)

    @property
    def count(self) -> int:
        return len(self.move)

    @property
    def ok(self) -> bool:
        return self.count == 0

    @property
    def per_piece(self) -> dict[str, int]:
        return {p: int(np.sum(self.piece == p)) for p in CHECKED if np.any(self.piece == p)}

    @property
    def deepest(self) -> float:
        return float(self.intrusion.max()) if self.count else 0.0

    @property
    def colliding_moves(self) -> np.ndarray:
        return np.unique(self.move)

    def summary(self) -> str:
        if self.ok:
            kept = ", ".join(f"{p} {c:g} mm" for p, c in self.clearances.items())
            return (f"Tool holder clear: neither the shank nor the holder comes closer to the model than its "
                    f"clearance ({kept}) at {self.samples:,} positions along {self.moves:,} moves.")
        k = int(np.argmax(self.intrusion))
        pieces = ", ".join(f"{p} {n:,}" for p, n in self.per_piece.items())
        where = f"tip X{self.tip[k, 0]:.3f} Y{self.tip[k, 1]:.3f} Z{self.tip[k, 2]:.3f}"
        if np.isfinite(self.contact[k]).all():
            where += f", deepest model point X{self.contact[k, 0]:.3f} Y{self.contact[k, 1]:.3f} " \
                     f"Z{self.contact[k, 2]:.3f}"
        how = "too low" if self.axis[k, 2] >= 1 - _VERTICAL else "too close"
        return (f"Tool holder collision: {self.count:,} of {self.samples:,} positions on "
                f"{len(self.colliding_moves):,} of {self.moves:,} moves come closer to the model than the "
                f"clearance ({pieces}). Worst: the {self.piece[k]} {self.intrusion[k]:.3f} mm {how} on move "
                f"{int(self.move[k])} ({where}). Lengthen the stick-out, choose a slimmer holder, or tilt the tool.")


def _slerp_rows(a0: np.ndarray, a1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """geometry.axes.slerp row by row (a0[k] to a1[k] at s[k]): the same formula, vectorised over moves."""
    dot = np.clip(np.einsum("ij,ij->i", a0, a1), -1.0, 1.0)
    th = np.arccos(dot)[:, None]
    s = s[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        v = (np.sin((1.0 - s) * th) * a0 + np.sin(s * th) * a1) / np.sin(th)
    v = np.where(th < 1e-9, a0, v)
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def sample_moves(toolpath: Toolpath, step: float, reach: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(tips, axes, move) along the path: the first point, then every move to its end at most `step` apart:
    for a vertical tool in XY (the drop reads the height over XY; the tip's z is linear between), for a tilted
    one in the tip's travel and in the travel of the point `reach` up the axis as the axis turns by slerp."""
    p, a = toolpath.points(), toolpath.axes()
    if len(p) == 0:
        raise TmmError("the tool path to check has no moves")
    bad = np.flatnonzero(~(np.isfinite(p).all(axis=1) & np.isfinite(a).all(axis=1)))
    if len(bad):
        raise TmmError(f"tool path move {int(bad[0])} is not finite: tip {p[bad[0]].tolist()}, axis {a[bad[0]].tolist()}")
    norm = np.linalg.norm(a, axis=1)
    bad = np.flatnonzero(np.abs(norm - 1.0) > 1e-6)
    if len(bad):
        raise TmmError(f"tool path move {int(bad[0])}: the tool axis {a[bad[0]].tolist()} is not a unit vector")
    a = a / norm[:, None]
    d = np.diff(p, axis=0)
    vertical = (a[:-1, 2] >= 1 - _VERTICAL) & (a[1:, 2] >= 1 - _VERTICAL)
    turn = np.arccos(np.clip(np.einsum("ij,ij->i", a[:-1], a[1:]), -1.0, 1.0))
    travel = np.where(vertical, np.hypot(d[:, 0], d[:, 1]), np.maximum(np.linalg.norm(d, axis=1), turn * reach))
    k = np.maximum(1, np.ceil(travel / step)).astype(np.int64)
    move = np.repeat(np.arange(1, len(p)), k)
    s = (np.arange(len(move)) - np.repeat(np.cumsum(k) - k, k) + 1) / np.repeat(k, k)
    tips = p[move - 1] + s[:, None] * d[move - 1]
    axes = _slerp_rows(a[move - 1], a[move], s)
    tips, axes, move = np.vstack([p[:1], tips]), np.vstack([a[:1], axes]), np.concatenate([[0], move])
    if any(m.arc is not None for m in toolpath.moves[1:]):
        tips, axes, move = _arcs_along(toolpath, tips, axes, move, step)
    return tips, axes, move


def _arcs_along(toolpath: Toolpath, tips: np.ndarray, axes: np.ndarray, move: np.ndarray,
                step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arc moves' samples replaced by samples along their chords (an arc keeps one axis: its end's)."""
    bounds = np.searchsorted(move, np.arange(len(toolpath) + 1))
    out_t, out_a, out_m = [], [], []
    for i, m in enumerate(toolpath.moves):
        lo, hi = bounds[i], bounds[i + 1]
        if i == 0 or m.arc is None:
            out_t.append(tips[lo:hi]), out_a.append(axes[lo:hi]), out_m.append(move[lo:hi])
            continue
        prev = toolpath.moves[i - 1]
        poly = np.vstack([[prev.x, prev.y, prev.z], m.arc.chords((prev.x, prev.y, prev.z), (m.x, m.y, m.z),
                                                                 ARC_TOLERANCE)])
        d = np.diff(poly, axis=0)
        k = np.maximum(1, np.ceil(np.linalg.norm(d, axis=1) / step)).astype(np.int64)
        seg = np.repeat(np.arange(len(d)), k)
        s = (np.arange(len(seg)) - np.repeat(np.cumsum(k) - k, k) + 1) / np.repeat(k, k)
        out_t.append(poly[seg] + s[:, None] * d[seg])
        out_a.append(np.repeat(np.array([m.axis], dtype=float), len(seg), axis=0))
        out_m.append(np.full(len(seg), i))
    return np.vstack(out_t), np.vstack(out_a), np.concatenate(out_m)


def _reach(bodies: list) -> float:
    """How far from the tip the checked bodies reach at most (their clearance included)."""
    return max((math.hypot(z1, max(r0, r1)) + c for z0, z1, r0, r1, c in bodies), default=0.0)


def check_holder_clearance(mesh: TriMesh, assembly: ToolAssembly, toolpath: Toolpath,
                           surface: Optional[DropSurface] = None, *, sample_step: float = 0.5,
                           tolerance: float = 1e-3, surface_step: float = 0.25, max_contacts: int = 1_000,
                           progress: Optional[Progress] = None, threads: int = 0) -> HolderClearance:
    """Where along `toolpath` the neck, shank or holder of `assembly` comes closer to `mesh` than its clearance
    by more than `tolerance` (mm). Moves sampled at most `sample_step` apart (module doc); the model's surface
    sampled `surface_step` apart for tilted poses and for locating the contact of the deepest `max_contacts`
    vertical collisions. `surface`: a DropSurface of `mesh` whose index is reused. `progress` as DropSurface
    (core.cancel)."""
    t0 = time.perf_counter()
    if not isinstance(toolpath, Toolpath):
        raise TmmError(f"toolpath must be a Toolpath, got {toolpath!r}")
    step = _length("sample step", sample_step)
    tol = _length("tolerance", tolerance, allow_zero=True)
    _length("surface sample step", surface_step)
    if isinstance(max_contacts, bool) or not isinstance(max_contacts, int) or max_contacts < 0:
        raise TmmError(f"max_contacts must be a whole number >= 0, got {max_contacts!r}")
    drop = AssemblyDrop(mesh, assembly, surface)
    checked = [i for i, p in enumerate(drop.pieces) if p in CHECKED]
    bodies = [drop.bodies[i] for i in checked]
    with cancel.watching(progress):
        tips, axes, move = sample_moves(toolpath, step, _reach(bodies))
        tilted = axes[:, 2] < 1 - _VERTICAL
        intrusion = np.full(len(tips), -np.inf)
        owner = np.full(len(tips), -1, dtype=np.int64)
        contact = np.full((len(tips), 3), np.nan)
        points: Optional[SurfacePoints] = None
        up = np.flatnonzero(~tilted)
        if len(up) and bodies:
            z, who = drop.heights_of(CHECKED, tips[up, :2], float(tips[up, 2].min()) - 1.0, threads=threads)
            hit = (who >= 0) & (z > tips[up, 2] + tol)
            intrusion[up[hit]], owner[up[hit]] = z[hit] - tips[up[hit], 2], who[hit]
            located = up[hit][np.argsort(-intrusion[up[hit]], kind="stable")[:max_contacts]]
            if len(located):
                points = SurfacePoints(drop.mesh, surface_step)
                _, _, contact[located] = points.worst(tips[located], axes[located], bodies, slack=points.error + tol)
        side = np.flatnonzero(tilted)
        if len(side) and bodies:
            points = points or SurfacePoints(drop.mesh, surface_step)
            v, b, c = points.worst(tips[side], axes[side], bodies)
            hit = v > tol
            intrusion[side[hit]], owner[side[hit]], contact[side[hit]] = v[hit], np.array(checked)[b[hit]], c[hit]
    rows = np.flatnonzero(owner >= 0)
    return HolderClearance(
        assembly.describe(), len(tips), len(toolpath), int(tilted.sum()), move[rows], drop.piece_names(owner[rows]),
        tips[rows], axes[rows], contact[rows], intrusion[rows], time.perf_counter() - t0,
        {p: c for p, c in (("shank", assembly.shank_clearance), ("holder", assembly.holder_clearance))
         if p in drop.pieces})


@dataclass
class StickOut:
    """The shortest stick-out at which the holder sets no height at the points, and why."""
    stick_out: float               # mm, never below the assembly's own minimum (flutes, neck, cone)
    current: float                 # the assembly's stick-out
    needed: np.ndarray             # (n,) per point: the stick-out it needs (-inf: the holder never reaches down)
    limiting: int                  # the point needing the most (-1: the tool's own minimum governs)
    shank_points: np.ndarray       # indices where the shank or neck itself lifts the tool off the cutter's
    overall_length: Optional[float] = None  # the tool's length, when known

    @property
    def fits(self) -> bool:
        return self.overall_length is None or self.stick_out <= self.overall_length + 1e-9

    def summary(self) -> str:
        text = (f"Shortest stick-out at which the holder never holds the tool up: {self.stick_out:.3f} mm "
                f"(now {self.current:g} mm).")
        if not self.fits:
            text += f" That is more than the tool's length, {self.overall_length:g} mm: choose a longer tool."
        if len(self.shank_points):
            text += (f" At {len(self.shank_points):,} points the shank itself holds the tool up: no stick-out "
                     "helps there (a longer flute or neck, or a slimmer tool, does).")
        return text


def _monotone(assembly: ToolAssembly) -> None:
    """The needed stick-out is H - z_tool exactly only if the grown holder covers the grown shank it replaces
    as the stick-out grows: every holder piece at least as wide as the shank, clearances included. Then the
    drop with stick-out s is max(z_tool, H - s): monotone in s."""
    rs = assembly.shank_diameter / 2 + assembly.shank_clearance
    for z0, z1, r0, r1, c in assembly.holder.bodies(0.0, assembly.holder_clearance):
        if min(r0, r1) + c < rs - 1e-9:
            raise TmmError(f"holder '{assembly.holder.name}' narrows to {2 * min(r0, r1):g} mm (clearance {c:g}) "
                           f"below the shank's {assembly.shank_diameter:g} mm (clearance "
                           f"{assembly.shank_clearance:g}): the shortest stick-out is not one number there")


def minimum_stick_out(mesh: TriMesh, assembly: ToolAssembly, xy_or_toolpath: Union[np.ndarray, Toolpath],
                      surface: Optional[DropSurface] = None, floor_z: Optional[float] = None,
                      progress: Optional[Progress] = None, threads: int = 0) -> StickOut:
    """The shortest stick-out with which the holder sets no drop height at the (n, 2) points, or at a 3-axis
    path's cutting points. The holder's constraint on the tip is H - s for stick-out s (H: the lowest height of
    the holder's face that keeps the holder clear); the tool below it (cutter, neck, shank as a column up)
    needs z_tool; so each point needs s >= H - z_tool (see _monotone)."""
    xy = _cl_points(xy_or_toolpath)
    if not isinstance(assembly, ToolAssembly):
        raise TmmError(f"assembly must be a ToolAssembly, got {assembly!r}")
    tool = AssemblyDrop(mesh, replace(assembly, holder=None), surface, progress)
    with cancel.watching(progress):
        z_tool, who = tool.heights(xy, floor_z, threads=threads)
        shank = np.flatnonzero(np.isin(tool.piece_names(who), ("neck", "shank")))
        needed = np.full(len(xy), -np.inf)
        if assembly.holder is not None:
            _monotone(assembly)
            face, set_by = AssemblyDrop(mesh, assembly, tool.surface).face_heights(
                xy, float(z_tool.min()) + assembly.minimum_stick_out - 1.0, threads=threads)
            needed = np.where(set_by != SET_BY_FLOOR, face - z_tool, -np.inf)
    k = int(np.argmax(needed)) if len(needed) else -1
    lowest = assembly.minimum_stick_out
    if k < 0 or needed[k] <= lowest:
        k = -1
    return StickOut(max(lowest, float(needed[k])) if k >= 0 else lowest, assembly.stick_out, needed, k, shank,
                    assembly.overall_length)


def _cl_points(xy_or_toolpath: Union[np.ndarray, Toolpath]) -> np.ndarray:
    if isinstance(xy_or_toolpath, Toolpath):
        if xy_or_toolpath.is_five_axis():
            raise TmmError("the shortest stick-out is found for 3-axis paths (a vertical tool) only")
        pts = np.array([(m.x, m.y) for m in xy_or_toolpath.moves if m.kind is not MoveKind.RAPID], dtype=float)
        if len(pts) == 0:
            raise TmmError("the tool path has no cutting moves to find the stick-out for")
        return pts
    return np.asarray(xy_or_toolpath, dtype=float)
