"""What the 5-axis passes leave for clean-up, listed as strips (feed from, to, across from, to; mm) in the
plan's `unfinished` (stepover.adaptive_passes): bins beyond the machine's tilt, the slivers the tools leave
along a side run to the mesh's edge, and the stretch between a path's moved-in end and the edge."""
from __future__ import annotations

from typing import List

import numpy as np

from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath
from tmm_workbench.core.strategies.mesh5.coverage import Coverage
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.widths import end_by_tools
from tmm_workbench.core.tools.cutter import Cutter

Strips = List[tuple[float, float, float, float]]   # (feed from, to, across from, to; mm)


def beyond_tilt(listed: Strips, cover: Coverage, level: np.ndarray, whole: List[CCPath],
                paths: List[CCPath], offset: float, dropped: np.ndarray) -> None:
    """Takes the pass's new `level`; the open bins the plane's whole paths run through but its paths within
    the machine's tilt do not (_Planes._reachable) are left for clean-up up to the least level the pass
    reached elsewhere (added to `listed`, the plan's unfinished), so that the next passes go on beside them
    instead of coming back for them (or being held back by them); so are the bins of the CC points `dropped` (k, 3)
    inside a path (no posture there: stepover._plan_pass), whether their neighbours advanced them or not."""
    gained = level > cover.level + 1e-9
    reached = float(level[gained].min()) if gained.any() else offset
    inner = np.zeros(len(level), dtype=bool)
    inner[cover.bin(dropped @ cover.feed)] = True
    hole = (cover.spanned(whole) & ~cover.spanned(paths) & ~gained | inner) & cover.open & (cover.level < reached)
    if hole.any():
        for a, b in zip(*(np.flatnonzero(np.diff(np.r_[0, hole.astype(np.int8), 0]))[k::2] for k in (0, 1))):
            f0 = cover.f0 + cover.width * a
            listed.append((float(f0), float(cover.f0 + cover.width * b), float(cover.level[a:b].min()), reached))
        level = np.where(hole, np.maximum(level, reached), level)
    cover.level = level


def list_slivers(listed: Strips, cover: Coverage, edges: tuple[np.ndarray, np.ndarray], run: int = 4) -> None:
    """The slivers a pass's tools left along the mesh's edge (`edges`: where they stop on the left and on the
    right, (k, 3) each, stepover._plan_pass) listed in `listed`: per run of up to `run` adjacent bins, from
    where they stop to the bins' top (left) or from the bins' bottom (right)."""
    for side, edge in enumerate(edges):
        if len(edge) == 0:
            continue
        sgn = 1.0 if side == 0 else -1.0
        lo = cover.bin(edge @ cover.feed - 0.5 * cover.width)
        hi = cover.bin(edge @ cover.feed + 0.5 * cover.width)
        across = np.full(len(cover.lo), np.inf)
        for a, b, s in zip(lo, hi, sgn * (edge @ cover.m)):
            across[a:b + 1] = np.minimum(across[a:b + 1], s)
        bins = np.flatnonzero(np.isfinite(across))
        for part in np.split(bins, np.flatnonzero(np.diff(bins) > 1) + 1):
            for k in range(0, len(part), run):
                q = part[k:k + run]
                f0, f1 = float(cover.f0 + cover.width * q[0]), float(cover.f0 + cover.width * (q[-1] + 1))
                listed.append((f0, f1, float(across[q].min()), float(cover.hi[q].max())) if side == 0 else
                              (f0, f1, float(cover.lo[q].min()), float(-across[q].min())))


def list_ends(listed: Strips, cover: Coverage, reach: MeshReach, cutter: Cutter, paths: List[CCPath],
              runs: List[tuple[np.ndarray, np.ndarray]], widths: np.ndarray, ends: np.ndarray,
              tolerance: float) -> None:
    """What a pass's tools leave above `tolerance` between each path's end CC point and the mesh's edge it was
    moved in from (widths.end_by_tools) listed in listed, per end and side: along the feed from the
    first section short of the end's half-width to the edge, across from where the tools stop to the level
    the end CC point claims (`ends`; at the mesh's edge, the bins' top or bottom)."""
    start = 0
    for p, (tips, axes) in zip(paths, runs):
        first, last = start, start + len(p) - 1
        start += len(p)
        found = end_by_tools(reach, cutter, p, tips, axes, widths[[first, last]], tolerance)
        for e, (i, k, sgn) in enumerate(((first, 0, -1.0), (last, -1, 1.0))):
            edge = (p.points[k] + sgn * p.inset[k] * p.frames[k, 0]) @ cover.feed
            for side in (0, 1):
                at = [(q, c) for en, sd, q, c in found if (en, sd) == (e, side)]
                if not at:
                    continue
                f = np.array([q @ cover.feed for q, _ in at] + [edge])
                bins = np.arange(cover.bin(f.min()).item(), cover.bin(f.max()).item() + 1)
                stop = np.array([c @ cover.m for _, c in at])
                f0, f1 = float(cover.f0 + cover.width * bins[0]), float(cover.f0 + cover.width * (bins[-1] + 1))
                if side == 0:
                    claim = float(cover.hi[bins].max()) if np.isnan(ends[i, 0, 0]) else float(ends[i, 0] @ cover.m)
                    listed.append((f0, f1, float(stop.min()), max(claim, float(stop.max()))))
                else:
                    claim = float(cover.lo[bins].min()) if np.isnan(ends[i, 1, 0]) else float(ends[i, 1] @ cover.m)
                    listed.append((f0, f1, min(claim, float(stop.min())), float(stop.max())))
