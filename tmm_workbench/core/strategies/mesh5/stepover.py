"""Adaptive 5-axis step-over from the tilted cutter's effective cutting profile (seed 000 section 3.5.3,
eq. 3.21-3.33, generalised from the flat end mill to the bull-nose).

Half-widths (widths.half_widths): how far to each side of a CC point the posture's effective cutting profile
over the surface's cross-section leaves at most the tolerance, as the curving pass sweeps it (widths module
doc); the seed solves the same for one rim point of the flat end mill (eq. 3.29-3.32) at a CM2 guess and takes
0.9 of it (eq. 3.33), here at the posture that will be cut.

Passes. The drive planes are placed one after another across the mesh (along their normal m); how far
across the surface is finished is kept per 2 mm bin of the feed coordinate (passes end where the mesh's
boundary runs slanted across the planes). The first plane lies 0.125 D inside the mesh (eq. 3.22). Each next
plane goes a gap beyond the least finished level of the open bins its own path runs through, and no higher
than the top of any open bin. Its C-space is built with, per CC point, the right side step reaching back to
the level of its bins and the left one a share of the gap; a CC point with no posture for its left step gets a
smaller one, a CC point with none for its right step moves the plane nearer (next to a path's end it is left
out instead, its bins for clean-up; after SPLIT_AFTER tries, a few inside a path are too, the path split
there). In the C-space each CC point keeps the postures that finish the widest
strip (widest_cspace: the right side back to its bins' level, the left as far along the plane normal as the
pass can reach at nearly all its CC points; the seed measures the half-widths at its ideal posture), and among
them the postures are chosen for the motion time (optimal.smooth_postures); the next gap is half the width the
pass finished (eq. 3.21's d_step_{i+1,R} = d_step_{i,L}, split evenly). The real half-widths are measured (a side
that runs off the mesh again under the pass's own tools, the slivers they leave listed: widths.edge_by_tools); a
bin advances to the least left boundary of its CC points where their right boundaries reach its level, and
keeps its level (for the next pass) where they do not. A plane that would come back to the last one's offset,
pulled back by a few such bins, leaves them for clean-up instead. The passes are planned at MARGIN of the
tolerance (the bends of the pass are measured: widths.path_bending). The tools go on an overrun of a radius
beyond the ends of each path, each position lifted clear of the mesh (tool_moves.overrun_positions), which the
bins count (coverage.Coverage).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Callable, List, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath, cc_paths, plane_normal
from tmm_workbench.core.strategies.mesh5.coverage import Coverage
from tmm_workbench.core.strategies.mesh5.cspace import CSpace, build_cspace
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.optimal import PassPostures, smooth_postures
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, require_plain, tool_rotation
from tmm_workbench.core.strategies.mesh5.tool_moves import between_positions, overrun_positions
from tmm_workbench.core.strategies.mesh5.top_bound import surface_heights
from tmm_workbench.core.strategies.mesh5.unfinished import beyond_tilt, list_ends, list_slivers
from tmm_workbench.core.strategies.mesh5.widths import edge_by_tools, half_widths, path_bending, reach_widths
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
SHRINK = 0.8            # gap factor when a pass must be rebuilt
MAX_TRIES = 12
# the passes are planned for this share of the tolerance: the profile is swept straight along LX with the
# posture of its CC point, while the path curves along the feed and the posture turns between CC points (the
# slow check on seed 000's convex surface found up to 1.26 tau where the full tolerance was planned; 0.85 until
# the pass's bends were measured, widths.path_bending: at 0.9 the complex surface simulated leaves none inside)
MARGIN = 0.9
# points checked inside each side step by the C-space's top bound: where the section curves up between the
# CC point and the side step, the ends alone pass postures that leave more there
INTERIOR = 3
# the postures kept at each CC point: those reaching at least this share of the left reach the pass can make
# at the WIDE_QUANTILE of its CC points (or of the point's own widest, where less)
WIDE_SHARE = 0.97
WIDE_QUANTILE = 0.05
# a CC point at a path's end whose widest left reach is below this share of the pass's median (the end runs
# down a slope near the machine's tilt, or across a curve the flat bottom cannot follow) is left out, its bins
# for clean-up, up to END_PEEL of them at each end: kept, it held every next plane back to its bins
NARROW = 0.5
END_PEEL = 3
# from this try on (the gap shrunk twice), runs of up to END_PEEL CC points with no posture inside a path are
# left out too, the path split there and their bins for clean-up (kept, they refused every pass there)
SPLIT_AFTER = 2
# a plane that would come back to less than REPEAT x the gap beyond the last one, pulled back by at most LAGGING
# bins, leaves those for clean-up instead (each such plane cut a sliver: 8 passes for 5 mm)
REPEAT = 0.3
LAGGING = 6
GAP_QUANTILE = 0.25     # of the pass's finished widths, whose half is the next gap
AHEAD_SHARE = 0.75      # the left side step the C-space asks, of the gap (the widest posture is chosen in it)
# in radii: the first plane and the first left step asked (seed 000 eq. 3.22-3.23: 0.125 D, 0.25 D), the next
# gap's range, and the strip skipped where no pass advances the least finished bins (a quarter diameter)
FIRST_GAP, FIRST_AHEAD, LEAST_GAP, MOST_GAP, SKIP = 0.25, 0.5, 0.05, 2.0, 0.5
EDGE = 1e-3             # Coverage's edge: a bin within this many radii of its top is finished
# s/rad the posture's turn against the surface costs in the motion-time choice near a side the tools leave short of
# the mesh's edge (_hold; the Tarus's moves between CC points take ~0.01-0.1 s)
HOLD = 2.0
# the right side step the C-space asks: this share of the way back to the level its bins are finished to, and mm more
BACK_SHARE, BACK_MORE = 1.01, 1e-3


def settled(nxt: float, offset: float, gap: float) -> bool:
    """Whether a plane's placement has come to rest: the offset its paths' bins ask (`nxt`) within a
    thousandth of the gap of where it was cut (`offset`)."""
    return abs(nxt - offset) < 1e-3 * gap


def widest_cspace(reach: MeshReach, cutter: Cutter, tolerance: float, points: np.ndarray, frames: np.ndarray,
                  cs: CSpace, back: np.ndarray, m: np.ndarray, bend: Optional[np.ndarray] = None
                  ) -> tuple[CSpace, np.ndarray]:
    """The C-space kept to the postures that finish the widest strip: at each CC point those whose right
    half-width reaches `back` (n,) along -m (the level of its bins; all that reach furthest where none does)
    and whose left one reaches, along the plane normal m, as far as the pass can uniformly
    (WIDE_QUANTILE of the CC points' widest) or its own widest where less. The seed measures the half-widths
    at the ideal posture; chosen for the motion time alone, the postures only just meet the side steps asked,
    and the passes are no wider than the guess. Also (n,): the CC points that fall short, their right side
    short of its step or their left reach below NARROW of the pass's."""
    left, rgt = reach_widths(reach, cutter, points, frames, cs, tolerance, m, bend)
    ok = rgt >= back[:, None] - 1e-6
    none = ~ok.any(axis=1)
    best_r = np.nanmax(np.where(np.isnan(rgt), -np.inf, rgt), axis=1)
    ok[none] = rgt[none] >= best_r[none, None] - 0.05 * cutter.radius
    reach_l = np.where(ok, left, -np.inf)
    best = reach_l.max(axis=1)
    fin = best[np.isfinite(best)]
    target = float(np.quantile(fin, WIDE_QUANTILE)) if fin.size else np.inf
    # where some posture covers the section to the mesh's edge, only those (the pass finishes the side)
    keep = ok & (reach_l >= WIDE_SHARE * np.where(np.isinf(best), np.inf, np.minimum(best, target))[:, None])
    lift = np.where(keep.reshape(cs.lift.shape), cs.lift, np.nan)
    narrow = none | (best < NARROW * float(np.median(fin)) if fin.size else none)
    return CSpace(cs.grid, lift, cs.top), narrow


@dataclass(frozen=True)
class PlannedPass:
    """One drive plane's pass: its CC paths with their chosen postures, the half-widths (n, 2) of its CC
    points (all paths in order), the band it covers on the plane-normal axis (right, left), mm, and the
    tool positions (tips, axes) of each path with its overruns (overrun_positions)."""
    offset: float
    paths: List[CCPath]
    postures: List[PassPostures]
    widths: np.ndarray
    band: tuple[float, float]
    side_step: float
    runs: List[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)

    def tool_positions(self) -> List[tuple[np.ndarray, np.ndarray]]:
        """(tips, axes) of each path with its overruns: every CL point, beyond both ends the overrun's positions
        and between two where the straight move would cut in, each clear of the mesh."""
        return self.runs


@dataclass
class AdaptivePlan:
    passes: List[PlannedPass] = field(default_factory=list)
    builds: int = 0                 # C-spaces built (passes + rebuilds)
    shrunk: int = 0                 # rebuilt with a smaller gap: no posture, or nothing gained
    partial: int = 0                # passes accepted with some CC points short of the finished level
    # (feed from, feed to, across from, across to) of the strips no pass could finish: for clean-up
    unfinished: List[tuple[float, float, float, float]] = field(default_factory=list)
    seconds: float = 0.0
    extent: tuple[float, float] = (0.0, 0.0)   # the mesh along the plane normal
    overrun: float = 0.0            # mm the tool goes on beyond the ends of each path (overrun_positions)

    def tool_positions(self) -> List[tuple[np.ndarray, np.ndarray]]:
        """(tips, axes) of every path of every pass, with the overrun."""
        return [tp for p in self.passes for tp in p.tool_positions()]

    def report(self) -> str:
        return (f"{len(self.passes)} passes over {self.extent[1] - self.extent[0]:.1f} mm, "
                f"{self.builds} C-spaces built ({self.shrunk} with a smaller gap, {self.partial} "
                f"{'pass' if self.partial == 1 else 'passes'} left some bins to the next), {self.seconds:.1f} s" + (
                    "; left unfinished (feed from, to, across from, to; mm): " + ", ".join(
                        f"({a:.1f}, {b:.1f}, {c:.2f}, {d:.2f})" for a, b, c, d in self.unfinished)
                    if self.unfinished else ""))



def tilt_reached(machine: TarusMachine, frm: np.ndarray, grid: PostureGrid) -> np.ndarray:
    """(n, nl, no): the postures whose axis the machine's tilt C reaches at each CC point (the others are
    never taken: their lift S2, the costly half of the C-space, is not asked)."""
    axes = np.einsum("nji,pj->npi", frm, tool_rotation(*(g.ravel() for g in grid.mesh()))[:, 2, :])
    return machine.tilt_within(axes).reshape((len(frm),) + grid.shape)


def _cspace(reach: MeshReach, cutter: Cutter, tolerance: float, pts: np.ndarray, frm: np.ndarray,
            side: np.ndarray, grid: PostureGrid, machine: TarusMachine,
            assembly: Optional[ToolAssembly] = None) -> tuple[CSpace, np.ndarray]:
    """The C-space of the CC points for the side steps `side` (n, 2) (left, right), and the side steps used:
    where a CC point has no posture (within the machine's tilt), its left step (the guess for the next pass)
    is halved, down to a quarter of what was asked, and only those CC points rebuilt."""
    side = np.minimum(side, 2 * cutter.radius)
    ask = tilt_reached(machine, frm, grid)
    cs = build_cspace(reach, cutter, pts, frm, grid, tolerance, side, interior=INTERIOR, ask=ask, assembly=assembly)
    floor = 0.25 * side[:, 0]
    for _ in range(2):
        redo = np.flatnonzero(cs.empty & (side[:, 0] > floor + 1e-9))
        if redo.size == 0:
            break
        side[redo, 0] = np.maximum(0.5 * side[redo, 0], floor[redo])
        sub = build_cspace(reach, cutter, pts[redo], frm[redo], grid, tolerance, side[redo], interior=INTERIOR,
                           ask=ask[redo], assembly=assembly)
        lift, top = cs.lift.copy(), cs.top.copy()
        lift[redo], top[redo] = sub.lift, sub.top
        cs = CSpace(cs.grid, lift, top)
    return cs, side


def _plan_pass(reach: MeshReach, cutter: Cutter, tolerance: float, paths: List[CCPath], side: np.ndarray,
               grid: PostureGrid, machine: TarusMachine, ideal_weight: float, m: np.ndarray, back: np.ndarray,
               assembly: Optional[ToolAssembly] = None, split: bool = False):
    """The pass along `paths` with the side steps `side` (n, 2) (left, right) of its CC points (the left
    ones relaxed where no posture meets them), each CC point's postures kept to the widest (widest_cspace:
    `back` (n,) the reach along -m to its bins' level, inf at the mesh's own edge): (postures, widths, ends,
    side steps, paths, the CC points left out inside the paths (k, 3)), or None where some CC point still has
    no posture. CC points with no posture, or narrow, at a path's end are left out (_peel; next to an end cut
    short by the machine's tilt, all with no posture: the tool there reaches the slope); with `split`, runs of
    up to END_PEEL with no posture inside a path too (the path split there, its bins for clean-up)."""
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    cs, side = _cspace(reach, cutter, tolerance, pts, frm, side, grid, machine, assembly)
    dropped = np.zeros((0, 3))
    if cs.empty.any():
        paths, keep = _peel(paths, cs.empty)
        if paths and split and cs.empty[keep].any() and _runs(cs.empty[keep]).max() <= END_PEEL:
            dropped = pts[keep][cs.empty[keep]]
            paths, inner = _split(paths, cs.empty[keep])
            keep = keep[inner]
        if not paths or cs.empty[keep].any():
            return None
        pts, frm, side, back = pts[keep], frm[keep], side[keep], back[keep]
        cs = CSpace(cs.grid, cs.lift[keep], cs.top[keep])
    cs, narrow = widest_cspace(reach, cutter, tolerance, pts, frm, cs, back, m, path_bending(paths))
    narrow &= np.isfinite(back)                            # not for the mesh's own edge alone
    if narrow.any():
        paths, keep = _peel(paths, narrow, through_cut=False)
        if not paths:
            return None
        pts, frm, side = pts[keep], frm[keep], side[keep]
        cs = CSpace(cs.grid, cs.lift[keep], cs.top[keep])
    postures = _choose(cs, cutter, paths, machine, ideal_weight)
    if postures is None:
        return None                                                         # out of the machine's reach
    widths, ends, tools, short = _measure(reach, cutter, tolerance, paths, postures)
    if short.any():
        # a side run to the mesh's edge that the tools leave short of it: the posture turned along the pass
        # there (seed 000's concave upper edge: omega -7.6 -> 30 deg over 7 CC points); chosen again, held
        held = _choose(cs, cutter, paths, machine, ideal_weight, _hold(paths, short, cutter.radius))
        if held is not None:
            again = _measure(reach, cutter, tolerance, paths, held)
            # taken where it leaves less short and covers no fewer sides to the edge (a side that no longer
            # reaches it would hold its bins for the next planes)
            if again[3].sum() < short.sum() and np.isinf(again[0]).sum() >= np.isinf(widths).sum():
                postures, (widths, ends, tools, short) = held, again
    cut = [np.isinf(widths[:, k]) & ~np.isnan(tools[:, k, 0]) & (short > 0) for k in (0, 1)]
    return postures, widths, ends, side, paths, dropped, (tools[cut[0], 0], tools[cut[1], 1])


def _choose(cs: CSpace, cutter: Cutter, paths: List[CCPath], machine: TarusMachine, ideal_weight: float,
            hold: Optional[np.ndarray] = None) -> Optional[List[PassPostures]]:
    """The postures of each path (optimal.smooth_postures; `hold` (n,) all paths in order), None where some
    CC point has none within the machine's reach."""
    postures, start = [], 0
    for p in paths:
        part = slice(start, start + len(p))
        sub = CSpace(cs.grid, cs.lift[part], cs.top[part])
        try:
            postures.append(smooth_postures(sub, cutter, p.points, p.frames, machine, ideal_weight,
                                            None if hold is None else hold[part]))
        except TmmError:
            return None
        start += len(p)
    return postures


def _measure(reach: MeshReach, cutter: Cutter, tolerance: float, paths: List[CCPath], postures: List[PassPostures]):
    """(widths, ends, where the tools stop at the mesh's edge, how far short of it) of the chosen postures:
    the half-widths, and a side run off the mesh under the pass's own tools (the slivers they leave at the
    edge are listed for clean-up, the bins counted finished: held open, they brought the next planes back
    for them, whose postures turned as much: seed 000's concave surface took 85 passes for 62)."""
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    cat = lambda name: np.concatenate([getattr(q, name) for q in postures])  # noqa: E731
    widths, ends = half_widths(reach, cutter, pts, frm, cat("lam"), cat("omg"), cat("delta"), tolerance,
                               path_bending(paths))
    _, tools, short = edge_by_tools(reach, cutter, paths, cat("tips"), cat("axes"), widths, ends, tolerance)
    return widths, ends, tools, short


def _hold(paths: List[CCPath], short: np.ndarray, radius: float) -> np.ndarray:
    """(n,) HOLD s/rad at the CC points within 1.5 radii along their path of one whose edge side the tools
    leave `short` (n,) (those whose tools form its profile), 0 elsewhere."""
    out, start = [], 0
    for p in paths:
        s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p.points, axis=0), axis=1))]
        bad = s[short[start:start + len(p)] > 0]
        near = (np.abs(s[:, None] - bad[None, :]) <= 1.5 * radius).any(axis=1) if bad.size else np.zeros(len(p), bool)
        out.append(np.where(near, HOLD, 0.0))
        start += len(p)
    return np.concatenate(out)


def _runs(mask: np.ndarray) -> np.ndarray:
    """The lengths of the runs of True in `mask` (0 where none)."""
    e = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return e[1::2] - e[::2] if e.size else np.zeros(1, dtype=np.int64)


def _split(paths: List[CCPath], drop: np.ndarray) -> tuple[List[CCPath], np.ndarray]:
    """The paths split where CC points are in `drop` (n,), those left out (the pieces' ends there cut short),
    pieces of fewer than 2 CC points dropped; and the kept CC points' indices (all paths in order)."""
    out, keep, start = [], [], 0
    for p in paths:
        e = np.flatnonzero(np.diff(np.r_[0, (~drop[start:start + len(p)]).astype(np.int8), 0]))
        for a, b in zip(e[::2], e[1::2]):
            if b - a >= 2:
                cut = (p.cut_short[0] or bool(a > 0), p.cut_short[1] or bool(b < len(p)))
                out.append(p if (a, b) == (0, len(p)) else p.take(slice(a, b), cut_short=cut))
                keep.append(np.arange(start + a, start + b))
        start += len(p)
    return out, np.concatenate(keep) if keep else np.zeros(0, dtype=np.int64)


def _peel(paths: List[CCPath], drop: np.ndarray, through_cut: bool = True) -> tuple[List[CCPath], np.ndarray]:
    """The paths without the runs of CC points in `drop` (n,) at their ends: up to END_PEEL at any end (that
    end then cut short, its bins left for clean-up: unfinished.beyond_tilt), and with `through_cut` all of a run next
    to an end already cut short (beyond the machine's tilt: the tool there reaches the slope); and the kept CC
    points' indices (all paths in order). A path left with fewer than 2 CC points is dropped."""
    out, keep, start = [], [], 0
    for p in paths:
        e = drop[start:start + len(p)]
        a, b = 0, len(p)
        while ((through_cut and p.cut_short[0]) or a < END_PEEL) and a < b and e[a]:
            a += 1
        while ((through_cut and p.cut_short[1]) or b > len(p) - END_PEEL) and b > a and e[b - 1]:
            b -= 1
        if b - a >= 2:
            cut = (p.cut_short[0] or a > 0, p.cut_short[1] or b < len(p))
            out.append(p if (a, b) == (0, len(p)) else p.take(slice(a, b), cut_short=cut))
            keep.append(np.arange(start + a, start + b))
        start += len(p)
    return out, np.concatenate(keep) if keep else np.zeros(0, dtype=np.int64)


def _unfolded(path: CCPath) -> CCPath:
    """The path without the CC points its moved-in ends (_Planes.paths) went past along the end's feed LX (an
    end moved a radius in passed several: the tool went on, back and on again, and the overrun from the moved
    end stopped short of the mesh's edge by the points it passed); at least its two ends kept."""
    if len(path) < 3:
        return path
    d0 = (path.points - path.points[0]) @ path.frames[0, 0]
    d1 = (path.points[-1] - path.points) @ path.frames[-1, 0]
    a, b = 1, len(path) - 1                                 # the runs next to each end that lie beyond it
    while a < b and d0[a] <= 0:
        a += 1
    while b > a and d1[b - 1] <= 0:
        b -= 1
    keep = np.zeros(len(path), dtype=bool)
    keep[[0, -1]] = True
    keep[a:b] = True
    return path if keep.all() else path.take(keep)


class _Planes:
    """Where the next drive plane goes: a gap beyond the least finished level of the open bins its own path
    runs through (not of all bins: the passes end where the mesh's boundary runs slanted), and no higher than
    the top of any open bin (a plane beyond it never comes back to finish that bin)."""

    def __init__(self, mesh: TriMesh, direction, cover: Coverage, forward_step: float, chord_tolerance: float,
                 radius: float, machine: TarusMachine, grid: PostureGrid):
        self.mesh, self.direction, self.cover, self.radius = mesh, direction, cover, radius
        self.forward_step, self.chord_tolerance = forward_step, chord_tolerance
        self.machine, self.grid = machine, grid

    def _reachable(self, offset: float, trim: bool = True) -> List[CCPath]:
        """The plane's CC paths split where no posture of the grid has an axis within the machine's tilt
        (a slope steeper than the tilt limit, falling along the feed: no gap helps there; those CC points are
        left out, their bins reported for clean-up by the plan), runs of fewer than 2 CC points dropped."""
        out = []
        for p in cc_paths(self.mesh, self.direction, np.array([offset]), self.forward_step,
                          self.chord_tolerance):
            ok = tilt_reached(self.machine, p.frames, self.grid).any(axis=(1, 2)) if trim else True
            out += [p] if np.all(ok) else _split([p], ~ok)[0]
        return out

    def paths(self, offset: float, trim: bool = True) -> List[CCPath]:
        """The plane's CC paths (within the machine's tilt: _reachable), their end points moved inside along
        the feed: on the mesh's boundary the sections' rays graze it, and a side that reads "off the mesh" is
        neither bounded by the C-space nor measured by the half-widths. The section (LX = 0) drifts along the
        feed by LY's and LZ's share of it as it goes out to the side, so the end points go in by that drift
        over a diameter across (at most a radius; the overrun covers it). `trim` False: not split."""
        out = []
        for p in self._reachable(offset, trim):
            pts, inset = p.points.copy(), [0.0, 0.0]
            if len(pts) > 1:
                most = min(self.radius, float(np.linalg.norm(pts[-1] - pts[0])) / 3)
                for k, sgn in ((0, 1.0), (-1, -1.0)):
                    f, feed = p.frames[k], self.cover.feed
                    drift = 2 * self.radius * abs(f[1] @ feed) + self.radius * abs(f[2] @ feed)
                    inset[k] = min(0.02 * self.radius + drift, most)
                    pts[k] += sgn * inset[k] * f[0]
            out.append(_unfolded(replace(p, points=pts, inset=(inset[0], inset[1]))))
        return out

    def place(self, guess: float, gap: float) -> tuple[float, List[CCPath], float]:
        """(offset, its paths, the least level it starts from) for a plane `gap` beyond the level its path
        runs through, starting the search at `guess`."""
        cover = self.cover
        top = float(cover.hi[cover.open].min()) - cover.edge
        offset = min(guess, top)
        for _ in range(4):
            paths = self.paths(offset)
            span = cover.spanned(paths) & cover.open if paths else cover.open
            base = float(cover.level[span].min()) if span.any() else float(cover.level[cover.open].min())
            nxt = min(base + gap, top)
            if settled(nxt, offset, gap) and paths:
                break
            offset = nxt
        else:
            paths = self.paths(offset)
        if not paths:
            raise TmmError(f"drive plane at {offset:.4f} mm does not cut the mesh")
        return offset, paths, base


def _side_steps(reach: MeshReach, paths: List[CCPath], need: tuple[np.ndarray, np.ndarray], offset: float,
                m: np.ndarray, gap: float, limit: float) -> np.ndarray:
    """(n, 2) side steps of the CC points: the left one the gap guessed for the next pass, the right one the
    distance along LY back to the level its bins are finished to (a little beyond), at most `limit`; where
    that level is the mesh's own edge, at most the distance to where the CC point's section leaves the mesh
    (the top bound checks nothing beyond it, and would pass a posture that stops short of the edge)."""
    level, edge = need
    frm = np.concatenate([p.frames for p in paths])
    across = np.maximum(frm[:, 1] @ m, 0.2)                                 # LY's share of m
    right = np.clip(BACK_SHARE * (offset - level) / across + BACK_MORE, 1e-3, limit)
    k = np.flatnonzero(edge)
    if k.size:
        pts = np.concatenate([p.points for p in paths])
        right[k] = np.maximum(_on_mesh(reach, pts[k], frm[k], right[k]), 1e-3)
    return np.column_stack([np.full(len(right), min(gap, limit)), right])


def _on_mesh(reach: MeshReach, pts: np.ndarray, frm: np.ndarray, d: np.ndarray, samples: int = 8,
             rounds: int = 14) -> np.ndarray:
    """(n,) how far (<= d) along -LY each CC point's section stays on the mesh: the first of `samples` off it,
    then the edge's crossing bisected (to d / samples / 2^rounds; the last sample on the mesh left the top
    bound unchecked up to d / samples short of the edge, and slivers along a slanted edge)."""
    t = d[:, None] * np.arange(1, samples + 1) / samples
    radius = 3.0 * float(d.max()) + 1.0
    off = np.isnan(surface_heights(reach, pts, frm, -t, radius))
    first = np.where(off.any(axis=1), off.argmax(axis=1), samples)
    rows = np.arange(len(pts))
    lo = np.where(first > 0, t[rows, np.maximum(first - 1, 0)], 0.0)
    hi = t[rows, np.minimum(first, samples - 1)]
    k = np.flatnonzero(first < samples)
    for _ in range(rounds if k.size else 0):
        mid = 0.5 * (lo[k] + hi[k])
        on = ~np.isnan(surface_heights(reach, pts[k], frm[k], -mid[:, None], radius)[:, 0])
        lo[k] = np.where(on, mid, lo[k])
        hi[k] = np.where(on, hi[k], mid)
    return lo


def _give_up_lagging(plan: AdaptivePlan, cover: Coverage, paths: List[CCPath], base: float, gap: float) -> bool:
    """A plane about to come back to the last one's offset, pulled back by a few bins that passes left short
    (a path's end held by the slope or the mesh's edge): those bins (within half a gap of the least level,
    at most LAGGING of them) are listed for clean-up up to the least level of the plane's other bins, and the
    plane is placed again from there. True where some were."""
    span = cover.spanned(paths) & cover.open
    lag = span & (cover.level < base + 0.5 * gap)
    rest = span & ~lag
    if not lag.any() or lag.sum() > LAGGING or not rest.any():
        return False
    reached = float(cover.level[rest].min())
    for a, b in zip(*(np.flatnonzero(np.diff(np.r_[0, lag.astype(np.int8), 0]))[k::2] for k in (0, 1))):
        plan.unfinished.append((float(cover.f0 + cover.width * a), float(cover.f0 + cover.width * b),
                                float(cover.level[a:b].min()), reached))
    cover.level = np.where(lag, np.maximum(cover.level, reached), cover.level)
    return True


def adaptive_passes(mesh: TriMesh, cutter: Cutter, tolerance: float, direction: Sequence[float] = (1.0, 0.0),
                    machine: Optional[TarusMachine] = None, grid: Optional[PostureGrid] = None,
                    forward_step: float = 2.0, chord_tolerance: float = 0.01, ideal_weight: float = 0.1,
                    progress: Optional[Progress] = None, assembly: Optional[ToolAssembly] = None) -> AdaptivePlan:
    """Passes across the mesh, each placed so that the scallop with the previous one stays within
    `tolerance` (module doc), their postures chosen for the Tarus motion time. Where no pass can advance the
    finished level (no posture for any gap), those places are listed in `AdaptivePlan.unfinished` for
    clean-up and the passes go on beside them. `progress(fraction done)` after each pass, False cancels
    (Cancelled), as everywhere in the core. `assembly`: the cutter's ToolAssembly, whose shank and holder bound
    every C-space and every lift (the tool tilts away, or the place is left unfinished). TmmError for a
    tolerance that is not a positive number."""
    if not (isinstance(tolerance, (int, float)) and math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"tolerance must be a positive number of mm, got {tolerance!r}")
    require_plain(cutter)
    t0 = time.perf_counter()
    machine = TarusMachine() if machine is None else machine
    grid = PostureGrid.degrees() if grid is None else grid
    reach = MeshReach(mesh)
    m = plane_normal(direction)
    s = mesh.vertices @ m
    lo, hi = float(s.min()), float(s.max())
    plan = AdaptivePlan(extent=(lo, hi), overrun=cutter.radius)
    cover = Coverage(mesh, m, np.array([m[1], -m[0], 0.0]), forward_step, EDGE * cutter.radius, plan.overrun)
    planes = _Planes(mesh, direction, cover, forward_step, chord_tolerance, cutter.radius, machine, grid)
    gap = FIRST_GAP * cutter.radius                                         # eq. 3.22: the first plane
    ahead = FIRST_AHEAD * cutter.radius                                     # eq. 3.23: d = 0.25 D
    guess = lo + gap
    while cover.open.any():
        for tries in range(MAX_TRIES):
            offset, paths, base = planes.place(guess, gap)
            if plan.passes and offset < plan.passes[-1].offset + REPEAT * gap and \
                    _give_up_lagging(plan, cover, paths, base, gap):
                offset, paths, base = planes.place(guess, gap)
            plan.builds += 1
            need = cover.needed(paths)
            side = _side_steps(reach, paths, need, offset, m, ahead, 2 * cutter.radius)
            got = _plan_pass(reach, cutter, MARGIN * tolerance, paths, side, grid, machine, ideal_weight, m,
                             np.where(need[1], np.inf, offset - need[0]), assembly, split=tries >= SPLIT_AFTER)
            if got is not None:
                paths = got[4]
                level, short = cover.advanced(paths, got[2])
                if (level > cover.level + 1e-9)[cover.open].any():
                    break
            plan.shrunk += 1                                                # no posture, or nothing gained
            gap *= SHRINK
            ahead = min(ahead, gap)
            guess = base + gap
        else:
            # no pass advances the least finished bins: a strip a quarter diameter wide beyond them is left
            # (reported for clean-up) and the passes go on past it
            stuck = cover.open & (cover.level <= base + 1e-9)
            f = cover.f0 + cover.width * np.flatnonzero(stuck)
            skip = SKIP * cutter.radius
            plan.unfinished.append((float(f.min()), float(f.max() + cover.width), base, base + skip))
            cover.level[stuck] = base + skip
            gap = skip
            guess = base + 2 * skip
            continue
        postures, widths, ends, used, paths, dropped, edge = got
        left = np.where(np.isnan(ends[:, 0, 0]), hi, ends[:, 0] @ m)
        right = np.where(np.isnan(ends[:, 1, 0]), lo, ends[:, 1] @ m)
        runs = [between_positions(reach, cutter, *overrun_positions(reach, cutter, p, q, plan.overrun,
                                                                    assembly=assembly), assembly=assembly)
                for p, q in zip(paths, postures)]
        list_ends(plan.unfinished, cover, reach, cutter, paths, runs, widths, ends, tolerance)
        plan.passes.append(PlannedPass(offset, paths, postures, widths, (float(right.max()), float(left.min())),
                                       gap, runs))
        plan.partial += short > 0
        beyond_tilt(plan.unfinished, cover, level, planes.paths(offset, trim=False), paths, offset, dropped)
        list_slivers(plan.unfinished, cover, edge)
        # the next pass's right side step as this one's left one (eq. 3.21's d_step_{i+1,R} = d_step_{i,L}),
        # the postures being the widest: half the width this pass finished (left + right along m) at most CC
        # points, so that the next one splits it evenly
        total = (left - offset) + (offset - right)
        gap = float(np.clip(0.5 * np.quantile(total, GAP_QUANTILE), LEAST_GAP * cutter.radius,
                            MOST_GAP * cutter.radius))
        ahead = AHEAD_SHARE * gap
        guess = offset + 2 * gap
        if progress is not None and progress(1.0 - float(np.mean(cover.open))) is False:
            raise Cancelled("5-axis mesh step-over cancelled")   # never a partial plan passed on as whole
    plan.seconds = time.perf_counter() - t0
    return plan
