"""Adaptive 5-axis step-over from the tilted cutter's effective cutting profile (seed 000 section 3.5.3,
eq. 3.21-3.33, generalised from the flat end mill to the bull-nose).

Half-widths. At each CC point, the chosen posture's effective cutting profile (the tool swept along the feed
LX, seen in the LY-LZ plane: top_bound.lower_profile, lifted by delta along the axis) stands over the
surface's cross-section S(y) (the mesh's height along LZ at LX = 0, LY = y); the remaining height is their
difference. The left (+LY) half-width is the largest d with the remaining height <= the tolerance on all of
[0, d], the right one the same on [-d, 0]: the seed's eq. 3.29-3.32 solve the same for one rim point of the
flat end mill (alpha); here it is the whole profile, for any posture and the bull-nose too, at the posture
that will be cut (the seed estimates it by CM2 first, and takes 0.9 of the result, eq. 3.33). Where the mesh
ends first, that side is covered to the edge (inf).

Passes. The drive planes are placed one after another across the mesh (along their normal m). A pass covers,
on the plane-normal axis, the band between its left and right boundaries: the section points at the
half-widths, the least of its CC points on the left (the seed's maximum remaining material height point,
eq. 3.23) and the greatest on the right. The first plane lies 0.125 D inside the mesh (eq. 3.22). Each next
plane is put a guessed gap beyond the band covered so far (the previous pass's own left width: eq. 3.21's
d_step_{i+1,R} = d_step_{i,L} guess) and its C-space is built with that side step on both sides, so that
every posture it may choose reaches back over the gap within the tolerance (and as far ahead); the postures
are chosen for the motion time (optimal.smooth_postures) and the real half-widths measured. Where a CC point
has no posture for that side step, or the real right boundary does not reach the band (the frames of the
new pass differ from the guess), the gap is shrunk and the pass rebuilt. Between two passes the scallop is
then at most the tolerance at every CC point's section (each pass's own profile leaves at most the
tolerance up to its boundary), and about equal to it where the binding CC points meet.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, List, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath, cc_paths, plane_normal
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.optimal import PassPostures, smooth_postures
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, require_plain, tool_rotation
from tmm_workbench.core.strategies.mesh5.top_bound import lower_profile, surface_heights
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
WIDTH_SAMPLES = 97      # lateral samples per side out to 2 R (the section is linear between them)
SHRINK = 0.8            # gap factor when a pass must be rebuilt
MAX_TRIES = 12
# points checked inside each side step by the C-space's top bound: where the section curves up between the
# CC point and the side step, the ends alone pass postures that leave more there
INTERIOR = 3


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
            if np.isnan(hs[k]):
                widths[i, side] = np.inf
                continue
            sgn = 1.0 if side == 0 else -1.0
            d = 0.0 if k == 0 else _crossing(py[i], pz[i], y, S[i][sl], sgn, y[k - 1], y[k], tolerance)
            widths[i, side] = d
            s_d = np.interp(d, y, S[i][sl])
            ends[i, side] = pts[i] + sgn * d * frm[i, 1] + s_d * frm[i, 2]
    return widths, ends


def _crossing(py: np.ndarray, pz: np.ndarray, y: np.ndarray, s: np.ndarray, sgn: float, a: float, b: float,
              tolerance: float) -> float:
    """The lateral distance in [a, b] where the remaining height (profile over the section, linear between
    the section's samples) reaches the tolerance, by bisection (the profile curves between samples)."""
    for _ in range(30):
        mid = 0.5 * (a + b)
        if np.interp(sgn * mid, py, pz) - np.interp(mid, y, s) <= tolerance:
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


@dataclass(frozen=True)
class PlannedPass:
    """One drive plane's pass: its CC paths with their chosen postures, the half-widths (n, 2) of its CC
    points (all paths in order) and the band it covers on the plane-normal axis (right, left), mm."""
    offset: float
    paths: List[CCPath]
    postures: List[PassPostures]
    widths: np.ndarray
    band: tuple[float, float]
    side_step: float


@dataclass
class AdaptivePlan:
    passes: List[PlannedPass] = field(default_factory=list)
    builds: int = 0                 # C-spaces built (passes + rebuilds)
    short: int = 0                  # rebuilt nearer: the right side fell short of the band covered
    shrunk: int = 0                 # rebuilt with a smaller gap: no posture, or nothing gained
    # (feed from, feed to, across from, across to) of the strips no pass could finish: for clean-up
    unfinished: List[tuple[float, float, float, float]] = field(default_factory=list)
    seconds: float = 0.0
    extent: tuple[float, float] = (0.0, 0.0)   # the mesh along the plane normal

    def report(self) -> str:
        return (f"{len(self.passes)} passes over {self.extent[1] - self.extent[0]:.1f} mm, "
                f"{self.builds} C-spaces built ({self.short} moved nearer, {self.shrunk} with a smaller gap), "
                f"{self.seconds:.1f} s" + ("; left unfinished (feed from, to, across from, to; mm): " + ", ".join(
                    f"({a:.1f}, {b:.1f}, {c:.2f}, {d:.2f})" for a, b, c, d in self.unfinished) if self.unfinished else ""))


class _Coverage:
    """How far across (along the plane normal m) the surface is finished, per bin of the feed coordinate:
    passes end where the mesh's boundary runs slanted across the planes, so one level for the whole width
    would take a pass's band for places its path never reaches."""

    def __init__(self, mesh: TriMesh, m: np.ndarray, feed: np.ndarray, width: float, edge: float) -> None:
        self.m, self.feed, self.width, self.edge = m, feed, width, edge
        f, s = mesh.vertices @ feed, mesh.vertices @ m
        self.f0 = float(f.min())
        nb = int((float(f.max()) - self.f0) // width) + 1
        self.lo, self.hi = np.full(nb, np.inf), np.full(nb, -np.inf)
        b = self.bin(f)
        np.minimum.at(self.lo, b, s)
        np.maximum.at(self.hi, b, s)
        self.level = self.lo.copy()                                         # finished up to here

    def bin(self, f: np.ndarray) -> np.ndarray:
        return np.clip(((f - self.f0) // self.width).astype(np.int64), 0, len(self.lo) - 1)

    @property
    def open(self) -> np.ndarray:
        return self.level < self.hi - self.edge

    @property
    def covered(self) -> float:
        """The least level over the bins not finished (inf when all are)."""
        return float(self.level[self.open].min(initial=np.inf))

    def shortfall(self, points: np.ndarray, ends: np.ndarray) -> float:
        """How far (m) the right boundaries of a pass's CC points stay short of the level at their bins."""
        right = np.where(np.isnan(ends[:, 1, 0]), -np.inf, ends[:, 1] @ self.m)
        return float(np.max(right - self.level[self.bin(points @ self.feed)], initial=0.0))

    def advanced(self, paths: List[CCPath], ends: np.ndarray) -> np.ndarray:
        """The level after a pass (its right side meeting the level): per bin its paths span, the least left
        boundary of the CC points in or next to the bin (inf where the left side ran off the mesh)."""
        left = np.where(np.isnan(ends[:, 0, 0]), np.inf, ends[:, 0] @ self.m)
        level, start = self.level.copy(), 0
        for p in paths:
            lp, fp = left[start:start + len(p)], p.points @ self.feed
            start += len(p)
            b = self.bin(fp)
            new = np.full(len(level), np.inf)
            np.minimum.at(new, b, lp)
            # the bins between two CC points: the lesser of the two
            for i in range(len(b) - 1):
                lo, hi = sorted((int(b[i]), int(b[i + 1])))
                new[lo:hi + 1] = np.minimum(new[lo:hi + 1], min(lp[i], lp[i + 1]))
            span = np.zeros(len(level), dtype=bool)
            span[int(b.min()):int(b.max()) + 1] = True
            level = np.where(span, np.maximum(level, new), level)
        return level


def _plan_pass(mesh: TriMesh, reach: MeshReach, cutter: Cutter, tolerance: float, direction, offset: float,
               side: tuple[float, float], grid: PostureGrid, machine: TarusMachine, forward_step: float,
               chord_tolerance: float, ideal_weight: float):
    """The pass on the plane at `offset` with the side steps `side` (left, right), or None where some CC
    point has no posture for them."""
    paths = cc_paths(mesh, direction, np.array([offset]), forward_step, chord_tolerance)
    if not paths:
        raise TmmError(f"drive plane at {offset:.4f} mm does not cut the mesh")
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    steps = np.tile(np.minimum(side, 2 * cutter.radius), (len(pts), 1))
    cs = build_cspace(reach, cutter, pts, frm, grid, tolerance, steps, interior=INTERIOR)
    if cs.empty.any():
        return None
    postures, start = [], 0
    for p in paths:
        part = slice(start, start + len(p))
        sub = type(cs)(cs.grid, cs.lift[part], cs.top[part])
        try:
            postures.append(smooth_postures(sub, cutter, p.points, p.frames, machine, ideal_weight))
        except TmmError:
            return None                                                     # out of the machine's reach
        start += len(p)
    cat = lambda name: np.concatenate([getattr(q, name) for q in postures])  # noqa: E731
    widths, ends = half_widths(reach, cutter, pts, frm, cat("lam"), cat("omg"), cat("delta"), tolerance)
    return paths, postures, widths, ends


def adaptive_passes(mesh: TriMesh, cutter: Cutter, tolerance: float, direction: Sequence[float] = (1.0, 0.0),
                    machine: Optional[TarusMachine] = None, grid: Optional[PostureGrid] = None,
                    forward_step: float = 2.0, chord_tolerance: float = 0.01, ideal_weight: float = 0.1,
                    progress: Optional[Progress] = None) -> AdaptivePlan:
    """Passes across the mesh, each placed so that the scallop with the previous one stays within
    `tolerance` (module doc), their postures chosen for the Tarus motion time. Where no pass can advance the
    finished level (no posture for any gap), those places are listed in `AdaptivePlan.unfinished` for
    clean-up and the passes go on beside them. TmmError for a tolerance that is not a positive number."""
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
    plan = AdaptivePlan(extent=(lo, hi))
    edge = 1e-3 * cutter.radius
    cover = _Coverage(mesh, m, np.array([m[1], -m[0], 0.0]), forward_step, edge)
    gap = 0.25 * cutter.diameter                                            # eq. 3.22: the seed's d = 0.25 D
    offset = lo + 0.125 * cutter.diameter
    while cover.open.any():
        covered = cover.covered
        for _ in range(MAX_TRIES):
            offset = min(offset, hi - edge)
            plan.builds += 1
            got = _plan_pass(mesh, reach, cutter, tolerance, direction, offset, (gap, gap), grid, machine,
                             forward_step, chord_tolerance, ideal_weight)
            if got is not None:
                pts = np.concatenate([p.points for p in got[0]])
                short = cover.shortfall(pts, got[3])
                level = cover.advanced(got[0], got[3])
                if short <= 1e-9 and (level > cover.level + 1e-9)[cover.open].any():
                    break
                if short > 1e-9 and offset - 1.05 * short > covered + 0.25 * gap:
                    plan.short += 1
                    offset -= 1.05 * short + 1e-6                           # the right side falls short
                    continue
            plan.shrunk += 1                                                # no posture, or nothing gained
            gap *= SHRINK
            offset = covered + gap if plan.passes else offset
        else:
            # no pass advances the least finished bins: a strip a quarter diameter wide beyond them is left
            # (reported for clean-up) and the passes go on past it
            stuck = cover.open & (cover.level <= covered + 1e-9)
            f = cover.f0 + cover.width * np.flatnonzero(stuck)
            skip = 0.25 * cutter.diameter
            plan.unfinished.append((float(f.min()), float(f.max() + cover.width), covered, covered + skip))
            cover.level[stuck] = covered + skip
            gap, offset = skip, cover.covered + skip
            continue
        paths, postures, widths, ends = got
        left = np.where(np.isnan(ends[:, 0, 0]), hi, ends[:, 0] @ m)
        right = np.where(np.isnan(ends[:, 1, 0]), lo, ends[:, 1] @ m)
        band = (float(right.max()), float(left.min()))
        plan.passes.append(PlannedPass(offset, paths, postures, widths, band, gap))
        cover.level = level
        gap = max(band[1] - offset, 1e-3)                                   # the next right side: this left one
        offset = min(cover.covered, hi) + gap
        if progress is not None and progress(min(1.0, (min(cover.covered, hi) - lo) / (hi - lo))):
            break
    plan.seconds = time.perf_counter() - t0
    return plan
