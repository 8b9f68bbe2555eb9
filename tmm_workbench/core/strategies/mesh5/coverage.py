"""How far across the surface the 5-axis passes have finished it, per bin of the feed coordinate (the
adaptive step-over's bookkeeping: stepover.adaptive_passes)."""
from __future__ import annotations

from typing import List

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath


def _edge_samples(mesh: TriMesh, feed: np.ndarray, spacing: float) -> np.ndarray:
    """Points along every edge of the mesh, at most `spacing` apart along the feed, so that every feed bin
    sees the mesh's extent across (its vertices alone may lie several bins apart)."""
    e = np.unique(np.sort(mesh.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    a, b = mesh.vertices[e[:, 0]], mesh.vertices[e[:, 1]]
    k = np.minimum(np.ceil(np.abs((b - a) @ feed) / spacing).astype(np.int64), 1000) + 2
    idx = np.repeat(np.arange(len(e)), k)
    frac = (np.arange(len(idx)) - np.repeat(np.cumsum(k) - k, k)) / np.repeat(k - 1, k)
    return a[idx] + frac[:, None] * (b[idx] - a[idx])


class Coverage:
    """How far across (along the plane normal m) the surface is finished, per bin of the feed coordinate:
    passes end where the mesh's boundary runs slanted across the planes, so one level for the whole width
    would take a pass's band for places its path never reaches."""

    def __init__(self, mesh: TriMesh, m: np.ndarray, feed: np.ndarray, width: float, edge: float,
                 overrun: float) -> None:
        self.m, self.feed, self.width, self.edge, self.overrun = m, feed, width, edge, overrun
        pts = _edge_samples(mesh, feed, 0.5 * width)
        f, s = pts @ feed, pts @ m
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

    def _segments(self, path: CCPath) -> tuple[np.ndarray, np.ndarray]:
        """Per segment of the path, its CC points' two indices and the bins it spans (lo, hi); the overrun
        adds a segment at each end from the end point to overrun mm beyond it, except where the path was cut
        short inside the mesh (beyond the machine's tilt: the overrun, lifted clear of the slope, cuts
        little there)."""
        b = self.bin(path.points @ self.feed)
        run = np.where(path.cut_short, 0.0, self.overrun)
        ext = self.bin(np.array([path.points[0] @ self.feed - run[0], path.points[-1] @ self.feed + run[1]]))
        n = len(b)
        ij = np.array([[0, 0]] + [[i, i + 1] for i in range(n - 1)] + [[n - 1, n - 1]])
        bins = np.column_stack([np.r_[ext[0], b[:-1], b[-1]], np.r_[b[0], b[1:], ext[1]]])
        return ij, np.sort(bins, axis=1)

    def spanned(self, paths: List[CCPath]) -> np.ndarray:
        """The bins the paths (with their overruns) run through."""
        span = np.zeros(len(self.lo), dtype=bool)
        for p in paths:
            _, bins = self._segments(p)
            span[int(bins.min()):int(bins.max()) + 1] = True
        return span

    def needed(self, paths: List[CCPath]) -> tuple[np.ndarray, np.ndarray]:
        """Per CC point, the least level of the bins of its two segments (how far back its right side must
        reach), and whether one of them is still at the mesh's own edge (no pass finished it yet)."""
        need, edge = [], []
        for p in paths:
            ij, bins = self._segments(p)
            low = np.array([self.level[a:b + 1].min() for a, b in bins])
            fresh = np.array([(self.level[a:b + 1] <= self.lo[a:b + 1]).any() for a, b in bins])
            n, e = np.full(len(p), np.inf), np.zeros(len(p), dtype=bool)
            for k in (0, 1):
                np.minimum.at(n, ij[:, k], low)
                np.logical_or.at(e, ij[:, k], fresh)
            need.append(n)
            edge.append(e)
        return np.concatenate(need), np.concatenate(edge)

    def advanced(self, paths: List[CCPath], ends: np.ndarray) -> tuple[np.ndarray, int]:
        """The level after a pass and how many of its CC points fall short of the level: a segment whose
        right boundaries reach the level of every bin it spans raises them to the lesser of its left
        boundaries (inf where the left side ran off the mesh); a bin that any short segment spans keeps its
        level, for the next pass."""
        left = np.where(np.isnan(ends[:, 0, 0]), np.inf, ends[:, 0] @ self.m)
        right = np.where(np.isnan(ends[:, 1, 0]), -np.inf, ends[:, 1] @ self.m)
        cand = np.full(len(self.level), np.inf)
        touched, failed = np.zeros(len(cand), dtype=bool), np.zeros(len(cand), dtype=bool)
        short, start = np.zeros(len(left), dtype=bool), 0
        for p in paths:
            ij, bins = self._segments(p)
            lp, rp = left[start:start + len(p)], right[start:start + len(p)]
            for (i, j), (a, b) in zip(ij, bins):
                touched[a:b + 1] = True
                if max(rp[i], rp[j]) <= self.level[a:b + 1].min() + 1e-9:
                    cand[a:b + 1] = np.minimum(cand[a:b + 1], min(lp[i], lp[j]))
                else:
                    failed[a:b + 1] = True
                    short[start + i] = short[start + j] = True
            start += len(p)
        return np.where(touched & ~failed, np.maximum(self.level, cand), self.level), int(short.sum())

