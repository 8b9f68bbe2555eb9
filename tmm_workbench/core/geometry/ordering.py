"""Greedy nearest-neighbour order of open pieces (passes, strips, curves), each entered at its nearer end.

The next piece is the free one with an end nearest the last piece's exit; it is turned to start at that end. A
KD-tree over the ends answers each step in about log n (the plain scan is quadratic: 90,000 clean-up strips took
minutes). Ties go to the lowest piece index, then to its head, as a plain scan's argmin would.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np


def nearest_first(pieces: Sequence[np.ndarray], start: Optional[np.ndarray] = None) -> list[np.ndarray]:
    """`pieces` (each (m, >=2) points, XY first) in greedy nearest-first order. Without `start` the first piece
    comes first as it is; with it (XY), the walk starts there."""
    n = len(pieces)
    if n == 0:
        return []
    ends = np.empty((2 * n, 2))                       # row 2i: piece i's head, 2i + 1: its tail
    ends[0::2] = [p[0][:2] for p in pieces]
    ends[1::2] = [p[-1][:2] for p in pieces]
    walk = _EndWalk(ends)
    out: list[np.ndarray] = []
    if start is None:
        k, turn, at = 0, False, None
    else:
        at = np.asarray(start, float)[:2]
        k, turn = walk.nearest(at)
    while True:
        walk.take(k)
        p = pieces[k][::-1] if turn else pieces[k]
        out.append(p)
        if len(out) == n:
            return out
        at = np.asarray(p[-1], float)[:2]
        k, turn = walk.nearest(at)


class _EndWalk:
    """The ends of the pieces not yet taken, for nearest queries; the tree is rebuilt when half of it is taken."""

    def __init__(self, ends: np.ndarray):
        self.ends = ends
        self.free = np.ones(len(ends) // 2, dtype=bool)
        self._build()

    def _build(self) -> None:
        from scipy.spatial import cKDTree

        self.rows = np.flatnonzero(np.repeat(self.free, 2))
        self.tree = cKDTree(self.ends[self.rows])
        self.taken_since = 0

    def take(self, piece: int) -> None:
        self.free[piece] = False
        self.taken_since += 1
        if 2 * self.taken_since >= len(self.rows) // 2 and self.free.any():
            self._build()

    def nearest(self, at: np.ndarray) -> tuple[int, bool]:
        """(piece, turned): the free end nearest `at` by the plain scan's distance and tie order."""
        size = len(self.rows)
        k = min(8, size)
        while True:
            dist, idx = self.tree.query(at, k=k)
            dist, idx = np.atleast_1d(dist), np.atleast_1d(idx)
            rows = self.rows[idx[idx < size]]
            rows = rows[self.free[rows // 2]]
            if len(rows):
                d = np.hypot(*(self.ends[rows] - at).T)    # the plain scan's own distance, for its ties
                best = d.min()
                # every end as near as the best must be among those asked: stop when the farthest asked is farther
                if k == size or dist[-1] > best * (1 + 1e-12) + 1e-300:
                    row = int(rows[d <= best].min())
                    return row // 2, bool(row % 2)
            if k == size:
                raise ValueError("nearest_first: no free piece left")   # the caller counts the pieces
            k = min(2 * k, size)
