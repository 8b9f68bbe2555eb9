"""Adaptive 5-axis step-over from the tilted cutter's effective cutting profile (seed 000 section 3.5.3,
eq. 3.21-3.33, generalised from the flat end mill to the bull-nose).

Half-widths. At each CC point, the chosen posture's effective cutting profile (the tool swept along the feed
LX, seen in the LY-LZ plane: top_bound.lower_profile, lifted by delta along the axis) stands over the
surface's cross-section S(y) (the mesh's height along LZ at LX = 0, LY = y); the remaining height is their
difference. The left (+LY) half-width is the largest d with the remaining height <= the tolerance on all of
[0, d], the right one the same on [-d, 0]: the seed's eq. 3.29-3.32 solve the same for one rim point of the
flat end mill (alpha); here it is the whole profile, for any posture and the bull-nose too, at the posture
that will be cut (the seed estimates it by CM2 first, and takes 0.9 of the result, eq. 3.33). Where the mesh
ends first, that side is covered to the edge (inf) when the tool is there beyond the last section sample on
the mesh too; else it ends at that sample (the bin stays open: no sliver left along the edge silently).

Passes. The drive planes are placed one after another across the mesh (along their normal m); how far
across the surface is finished is kept per 2 mm bin of the feed coordinate (passes end where the mesh's
boundary runs slanted across the planes). The first plane lies 0.125 D inside the mesh (eq. 3.22). Each next
plane goes a gap beyond the least finished level of the open bins its own path runs through, and no higher
than the top of any open bin. Its C-space is built with, per CC point, the right side step reaching back to
the level of its bins and the left one a share of the gap; a CC point with no posture for its left step gets a
smaller one, a CC point with none for its right step moves the plane nearer (next to a path's end it is left
out instead, its bins for clean-up). In the C-space each CC point keeps the postures that finish the widest
strip (widest_cspace: the right side back to its bins' level, the left as far along the plane normal as the
pass can reach at nearly all its CC points; the seed measures the half-widths at its ideal posture), and among
them the postures are chosen for the motion time (optimal.smooth_postures); the next gap is half the width the
pass finished (eq. 3.21's d_step_{i+1,R} = d_step_{i,L}, split evenly). The real half-widths are measured; a
bin advances to the least left boundary of its CC points where their right boundaries reach its level, and
keeps its level (for the next pass) where they do not. A plane that would come back to the last one's offset,
pulled back by a few such bins, leaves them for clean-up instead. The passes are planned at MARGIN of the
tolerance. The tools go on an overrun of a radius beyond the ends of each path, each position lifted clear of
the mesh (tool_moves.overrun_positions), which the bins count (coverage.Coverage).
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
from tmm_workbench.core.strategies.mesh5.top_bound import lower_profile, surface_heights
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
WIDTH_SAMPLES = 97      # lateral samples per side out to 2 R (the section is linear between them)
SHRINK = 0.8            # gap factor when a pass must be rebuilt
MAX_TRIES = 12
# the passes are planned for this share of the tolerance: the profile is swept straight along LX with the
# posture of its CC point, while the path curves along the feed and the posture turns between CC points (the
# slow check on seed 000's convex surface found up to 1.26 tau where the full tolerance was planned)
MARGIN = 0.85
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
# a plane that would come back to less than REPEAT x the gap beyond the last one, pulled back by at most LAGGING
# bins, leaves those for clean-up instead (each such plane cut a sliver: 8 passes for 5 mm)
REPEAT = 0.3
LAGGING = 6
GAP_QUANTILE = 0.25     # of the pass's finished widths, whose half is the next gap
AHEAD_SHARE = 0.75      # the left side step the C-space asks, of the gap (the widest posture is chosen in it)


def half_widths(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, lam: np.ndarray,
                omg: np.ndarray, delta: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """For n CC points with their postures (lam, omg rad, delta mm, each (n,)): the half-widths (n, 2) (left
    +LY, right -LY; inf where the mesh ends first) within which the remaining height stays <= `tolerance`,
    and the world points of the section at those widths (n, 2, 3) (NaN where inf)."""
    require_plain(cutter)
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    lam, omg, delta = (np.asarray(v, dtype=float).reshape(-1) for v in (lam, omg, delta))
    n = len(pts)
    ys = np.linspace(0.0, 2.0 * cutter.radius, WIDTH_SAMPLES)
    lateral = np.concatenate([ys, -ys[1:]])
    S = surface_heights(reach, pts, frm, np.tile(lateral, (n, 1)), 3.0 * cutter.radius)
    py, pz = lower_profile(cutter, lam, omg, 2001)
    a = tool_rotation(lam, omg)[:, 2, 1:]                                   # lift direction (LY, LZ)
    py = py + delta[:, None] * a[:, :1]
    pz = pz + delta[:, None] * a[:, 1:]
    widths = np.zeros((n, 2))
    ends = np.full((n, 2, 3), np.nan)
    for i in range(n):
        z = np.interp(lateral, py[i], pz[i], left=np.inf, right=np.inf)
        h = z - S[i]
        for side, sl in ((0, slice(0, len(ys))), (1, np.r_[0, len(ys):len(lateral)])):
            y, hs = np.abs(lateral[sl]), h[sl]
            over = np.flatnonzero(~(hs <= tolerance))                       # NaN (mesh ended) counts too
            if over.size == 0:
                widths[i, side] = np.inf if np.isnan(hs).any() else y[-1]
                continue
            k = int(over[0])
            sgn = 1.0 if side == 0 else -1.0
            if np.isnan(hs[k]) and _past_edge(py[i], pz[i], y, S[i][sl], sgn, k, tolerance):
                widths[i, side] = np.inf
                continue
            d = 0.0 if k == 0 else y[k - 1] if np.isnan(hs[k]) else _crossing(py[i], pz[i], y, S[i][sl], sgn, y[k - 1], y[k], tolerance)
            widths[i, side] = d
            s_d = S[i][sl][k - 1] if np.isnan(hs[k]) else np.interp(d, y, S[i][sl])
            ends[i, side] = pts[i] + sgn * d * frm[i, 1] + s_d * frm[i, 2]
    return widths, ends


def _past_edge(py: np.ndarray, pz: np.ndarray, y: np.ndarray, s: np.ndarray, sgn: float, k: int,
               tolerance: float) -> bool:
    """Whether the profile covers the section beyond its last sample on the mesh (k - 1): at sample k (off
    the mesh, the section extrapolated from the two before) the tool is there within the tolerance. Else the
    side ends at that sample, short of the mesh's edge (a sliver the next pass or the clean-up takes)."""
    if k == 0:
        return True                                                         # the CC point itself: as before
    z = np.interp(sgn * y[k], py, pz, left=np.inf, right=np.inf)
    return bool(z - (s[0] if k == 1 else 2 * s[k - 1] - s[k - 2]) <= tolerance)


def _crossing(py: np.ndarray, pz: np.ndarray, y: np.ndarray, s: np.ndarray, sgn: float, a: float, b: float,
              tolerance: float) -> float:
    """The lateral distance in [a, b] where the remaining height (profile over the section, linear between
    the section's samples) reaches the tolerance, by bisection (the profile curves between samples)."""
    for _ in range(30):
        mid = 0.5 * (a + b)
        # beyond the profile's ends the tool is not there (its side wall): never within the tolerance
        if np.interp(sgn * mid, py, pz, left=np.inf, right=np.inf) - np.interp(mid, y, s) <= tolerance:
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


def reach_widths(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, cs: CSpace,
                 tolerance: float, m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, P) how far along the plane normal m each available posture of the C-space at its lift S2
    finishes on the left (+m) and back on the right (-m) (the half-widths as half_widths, to the section's
    samples, the crossing linear between two, and their section points' share of m; inf where the mesh ends
    first, NaN where the posture is not available): what each posture would finish, to choose from."""
    n = len(points)
    lam, omg = (g.ravel() for g in cs.grid.mesh())
    ys = np.linspace(0.0, 2.0 * cutter.radius, WIDTH_SAMPLES)
    lateral = np.concatenate([ys, -ys[1:]])
    S = surface_heights(reach, points, frames, np.tile(lateral, (n, 1)), 3.0 * cutter.radius)
    py, pz = lower_profile(cutter, lam, omg, 2001)
    h = 0.01 * cutter.radius
    g = np.arange(-3.0 * cutter.radius, 3.0 * cutter.radius + h, h)
    # the profile on a uniform grid (far above beyond its ends: the side wall is no cutting edge)
    Z = np.array([np.interp(g, py[p], pz[p], left=1e9, right=1e9) for p in range(len(lam))])
    a = tool_rotation(lam, omg)[:, 2, 1:]
    avail = cs.available.reshape(n, -1)
    lift = cs.lift.reshape(n, -1)
    out = np.full((2, n, len(lam)), np.nan)
    sides = (np.arange(len(ys)), np.r_[0, len(ys):len(lateral)])
    ly, lz = frames[:, 1] @ m, frames[:, 2] @ m
    for i in range(n):
        ps = np.flatnonzero(avail[i])
        if ps.size == 0:
            continue
        d = lift[i, ps][:, None]
        u = np.clip((lateral[None, :] - d * a[ps, :1] - g[0]) / h, 0.0, len(g) - 1.001)
        k = u.astype(np.int64)
        t = u - k
        z = Z[ps[:, None], k] * (1 - t) + Z[ps[:, None], k + 1] * t + d * a[ps, 1:]
        rem = z - S[i][None, :]
        for side, sl in enumerate(sides):
            r = rem[:, sl]
            over = ~(r <= tolerance)
            first = np.where(over.any(axis=1), over.argmax(axis=1), len(ys))
            rows = np.arange(len(ps))
            k1 = np.minimum(first, len(ys) - 1)
            k0 = np.maximum(first - 1, 0)
            r0, r1 = r[rows, k0], r[rows, k1]
            frac = np.clip((tolerance - r0) / np.where(r1 > r0, r1 - r0, np.inf), 0.0, 1.0)
            w = np.where(first == 0, 0.0, ys[k0] + frac * (ys[k1] - ys[k0]))
            w = np.where(first >= len(ys), ys[-1], w)
            # the mesh ended first: the whole side when the tool is there beyond the last sample on the mesh
            # too (the section there extrapolated), else only up to that sample (the edge left a sliver)
            k2 = np.maximum(first - 2, 0)
            s_sl = S[i][sl]
            ext = 2 * s_sl[k0] - s_sl[k2]
            zk = z[rows, sl[k1]]
            covered = (zk < 1e8) & (zk - ext <= tolerance)
            w = np.where((first < len(ys)) & np.isnan(r1), np.where(covered, np.inf, ys[k0]), w)
            s0, s1 = s_sl[k0], s_sl[k1]
            s_w = np.where(first >= len(ys), s_sl[-1], np.where(np.isnan(s1), s0, s0 + frac * (s1 - s0)))
            sgn = 1.0 if side == 0 else -1.0
            out[side, i, ps] = np.where(np.isinf(w), w, w * ly[i] + sgn * s_w * lz[i])
    return out[0], out[1]


def widest_cspace(reach: MeshReach, cutter: Cutter, tolerance: float, points: np.ndarray, frames: np.ndarray,
                  cs: CSpace, back: np.ndarray, m: np.ndarray) -> tuple[CSpace, np.ndarray]:
    """The C-space kept to the postures that finish the widest strip: at each CC point those whose right
    half-width reaches `back` (n,) along -m (the level of its bins; all that reach furthest where none does)
    and whose left one reaches, along the plane normal m, as far as the pass can uniformly
    (WIDE_QUANTILE of the CC points' widest) or its own widest where less. The seed measures the half-widths
    at the ideal posture; chosen for the motion time alone, the postures only just meet the side steps asked,
    and the passes are no wider than the guess. Also (n,): the CC points that fall short, their right side
    short of its step or their left reach below NARROW of the pass's."""
    left, rgt = reach_widths(reach, cutter, points, frames, cs, tolerance, m)
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
               assembly: Optional[ToolAssembly] = None):
    """The pass along `paths` with the side steps `side` (n, 2) (left, right) of its CC points (the left
    ones relaxed where no posture meets them), each CC point's postures kept to the widest (widest_cspace:
    `back` (n,) the reach along -m to its bins' level, inf at the mesh's own edge): (postures, widths, ends,
    side steps, paths), or None where some CC point still has no posture. CC points with no posture, or
    narrow, at a path's end are left out (_peel; next to an end cut short by the machine's tilt, all with no
    posture: the tool there reaches the slope)."""
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    cs, side = _cspace(reach, cutter, tolerance, pts, frm, side, grid, machine, assembly)
    if cs.empty.any():
        paths, keep = _peel(paths, cs.empty)
        if not paths or cs.empty[keep].any():
            return None
        pts, frm, side, back = pts[keep], frm[keep], side[keep], back[keep]
        cs = CSpace(cs.grid, cs.lift[keep], cs.top[keep])
    cs, narrow = widest_cspace(reach, cutter, tolerance, pts, frm, cs, back, m)
    narrow &= np.isfinite(back)                            # not for the mesh's own edge alone
    if narrow.any():
        paths, keep = _peel(paths, narrow, through_cut=False)
        if not paths:
            return None
        pts, frm, side = pts[keep], frm[keep], side[keep]
        cs = CSpace(cs.grid, cs.lift[keep], cs.top[keep])
    postures, start = [], 0
    for p in paths:
        part = slice(start, start + len(p))
        sub = CSpace(cs.grid, cs.lift[part], cs.top[part])
        try:
            postures.append(smooth_postures(sub, cutter, p.points, p.frames, machine, ideal_weight))
        except TmmError:
            return None                                                     # out of the machine's reach
        start += len(p)
    cat = lambda name: np.concatenate([getattr(q, name) for q in postures])  # noqa: E731
    widths, ends = half_widths(reach, cutter, pts, frm, cat("lam"), cat("omg"), cat("delta"), tolerance)
    return postures, widths, ends, side, paths


def _peel(paths: List[CCPath], drop: np.ndarray, through_cut: bool = True) -> tuple[List[CCPath], np.ndarray]:
    """The paths without the runs of CC points in `drop` (n,) at their ends: up to END_PEEL at any end (that
    end then cut short, its bins left for clean-up: _beyond_tilt), and with `through_cut` all of a run next
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
            if np.all(ok):
                out.append(p)
                continue
            edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
            out += [p.take(slice(a, b), cut_short=(bool(a > 0), bool(b < len(ok))))
                    for a, b in zip(edges[::2], edges[1::2]) if b - a >= 2]
        return out

    def paths(self, offset: float, trim: bool = True) -> List[CCPath]:
        """The plane's CC paths (within the machine's tilt: _reachable), their end points moved inside along
        the feed: on the mesh's boundary the sections' rays graze it, and a side that reads "off the mesh" is
        neither bounded by the C-space nor measured by the half-widths. The section (LX = 0) drifts along the
        feed by LY's and LZ's share of it as it goes out to the side, so the end points go in by that drift
        over a diameter across (at most a radius; the overrun covers it). `trim` False: not split."""
        out = []
        for p in self._reachable(offset, trim):
            pts = p.points.copy()
            if len(pts) > 1:
                most = min(self.radius, float(np.linalg.norm(pts[-1] - pts[0])) / 3)
                for k, sgn in ((0, 1.0), (-1, -1.0)):
                    f, feed = p.frames[k], self.cover.feed
                    drift = 2 * self.radius * abs(f[1] @ feed) + self.radius * abs(f[2] @ feed)
                    pts[k] += sgn * min(0.02 * self.radius + drift, most) * f[0]
            out.append(replace(p, points=pts))
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
            if abs(nxt - offset) < 1e-3 * gap and paths:
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
    right = np.clip(1.01 * (offset - level) / across + 1e-3, 1e-3, limit)
    k = np.flatnonzero(edge)
    if k.size:
        pts = np.concatenate([p.points for p in paths])
        right[k] = np.maximum(_on_mesh(reach, pts[k], frm[k], right[k]), 1e-3)
    return np.column_stack([np.full(len(right), min(gap, limit)), right])


def _on_mesh(reach: MeshReach, pts: np.ndarray, frm: np.ndarray, d: np.ndarray, samples: int = 8) -> np.ndarray:
    """(n,) how far (<= d) along -LY each CC point's section stays on the mesh, to d / samples^2."""
    lo, hi = np.zeros(len(pts)), d.copy()
    for _ in range(2):
        t = lo[:, None] + (hi - lo)[:, None] * np.arange(1, samples + 1) / samples
        S = surface_heights(reach, pts, frm, -t, 3.0 * float(d.max()) + 1.0)
        off = np.isnan(S)
        first = np.where(off.any(axis=1), off.argmax(axis=1), samples)
        rows = np.arange(len(pts))
        last_on = np.where(first > 0, t[rows, np.maximum(first - 1, 0)], lo)
        hi = np.where(first < samples, t[rows, np.minimum(first, samples - 1)], hi)
        lo = last_on
    return lo


def _beyond_tilt(plan: AdaptivePlan, cover: Coverage, level: np.ndarray, whole: List[CCPath],
                 paths: List[CCPath], offset: float) -> None:
    """Takes the pass's new `level`; the open bins the plane's whole paths run through but its paths within
    the machine's tilt do not (_Planes._reachable) are left for clean-up up to the least level the pass
    reached elsewhere (added to plan.unfinished), so that the next passes go on beside them instead of
    coming back for them (or being held back by them)."""
    gained = level > cover.level + 1e-9
    reached = float(level[gained].min()) if gained.any() else offset
    hole = cover.spanned(whole) & ~cover.spanned(paths) & cover.open & ~gained & (cover.level < reached)
    if hole.any():
        for a, b in zip(*(np.flatnonzero(np.diff(np.r_[0, hole.astype(np.int8), 0]))[k::2] for k in (0, 1))):
            f0 = cover.f0 + cover.width * a
            plan.unfinished.append((float(f0), float(cover.f0 + cover.width * b), float(cover.level[a:b].min()),
                                    reached))
        level = np.where(hole, np.maximum(level, reached), level)
    cover.level = level


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
    cover = Coverage(mesh, m, np.array([m[1], -m[0], 0.0]), forward_step, 1e-3 * cutter.radius, plan.overrun)
    planes = _Planes(mesh, direction, cover, forward_step, chord_tolerance, cutter.radius, machine, grid)
    gap = 0.125 * cutter.diameter                                           # eq. 3.22: the first plane
    ahead = 0.25 * cutter.diameter                                          # eq. 3.23: d = 0.25 D
    guess = lo + gap
    while cover.open.any():
        for _ in range(MAX_TRIES):
            offset, paths, base = planes.place(guess, gap)
            if plan.passes and offset < plan.passes[-1].offset + REPEAT * gap and \
                    _give_up_lagging(plan, cover, paths, base, gap):
                offset, paths, base = planes.place(guess, gap)
            plan.builds += 1
            need = cover.needed(paths)
            side = _side_steps(reach, paths, need, offset, m, ahead, 2 * cutter.radius)
            got = _plan_pass(reach, cutter, MARGIN * tolerance, paths, side, grid, machine, ideal_weight, m,
                             np.where(need[1], np.inf, offset - need[0]), assembly)
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
            skip = 0.25 * cutter.diameter
            plan.unfinished.append((float(f.min()), float(f.max() + cover.width), base, base + skip))
            cover.level[stuck] = base + skip
            gap = skip
            guess = base + 2 * skip
            continue
        postures, widths, ends, used, paths = got
        left = np.where(np.isnan(ends[:, 0, 0]), hi, ends[:, 0] @ m)
        right = np.where(np.isnan(ends[:, 1, 0]), lo, ends[:, 1] @ m)
        runs = [between_positions(reach, cutter, *overrun_positions(reach, cutter, p, q, plan.overrun,
                                                                    assembly=assembly), assembly=assembly)
                for p, q in zip(paths, postures)]
        plan.passes.append(PlannedPass(offset, paths, postures, widths, (float(right.max()), float(left.min())),
                                       gap, runs))
        plan.partial += short > 0
        _beyond_tilt(plan, cover, level, planes.paths(offset, trim=False), paths, offset)
        # the next pass's right side step as this one's left one (eq. 3.21's d_step_{i+1,R} = d_step_{i,L}),
        # the postures being the widest: half the width this pass finished (left + right along m) at most CC
        # points, so that the next one splits it evenly
        total = (left - offset) + (offset - right)
        gap = float(np.clip(0.5 * np.quantile(total, GAP_QUANTILE), 0.05 * cutter.radius, 2 * cutter.radius))
        ahead = AHEAD_SHARE * gap
        guess = offset + 2 * gap
        if progress is not None and progress(1.0 - float(np.mean(cover.open))) is False:
            raise Cancelled("5-axis mesh step-over cancelled")   # never a partial plan passed on as whole
    plan.seconds = time.perf_counter() - t0
    return plan
