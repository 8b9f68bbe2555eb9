"""Pass pieces clipped to a machining region, put in cutting order as chains.

A chain is cut with the tool down: its pieces one after the other, joined by links the strategy drops on
the surface (gouge-free like any dropped point). A link is the straight move between two pieces where it
stays inside the region, else the walk along the region's boundary between them (both ends of a clipped
piece lie on it; a walk round a hole's edge keeps the tool centre on the region's boundary), whichever
is possible and at most `max_link` long. Anywhere else the chain ends and the next starts with a "jump"
(seed 003's lift flag: the linker lifts to the safe height, crosses and plunges, core.linking).

Zig-zag: from the end of the current piece the nearest piece of the next pass that can be linked; when
there is none, the chain ends and the next one starts from the first pass that still has a piece (so a
region with a hole is cut side by side, one jump per side instead of one per pass). One-way: every piece
its own chain, pass after pass, each in the pass direction. Along a curve (spiral): pieces in curve
order, linked where they can be.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.footprint.raster import sample_segment
from tmm_workbench.core.footprint.region import edges_of, segment_inside
from tmm_workbench.core.polygons import Shape

# (link, piece) pairs in cutting order: the link ((k, 2) XY polyline from the previous piece's end to this
# piece's start) is None for the chain's first piece
Chain = list[tuple[Optional[np.ndarray], np.ndarray]]
_ON_BOUNDARY_MM = 1e-6


def _locate(ring: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """(distance from p to the closed polyline `ring`, arc-length position of the nearest point on it)."""
    a, b = ring, np.roll(ring, -1, axis=0)
    ab = b - a
    ll = np.maximum((ab * ab).sum(axis=1), 1e-300)
    t = np.clip(((p - a) * ab).sum(axis=1) / ll, 0.0, 1.0)
    d = np.hypot(*(a + t[:, None] * ab - p).T)
    i = int(np.argmin(d))
    cum = np.concatenate([[0.0], np.cumsum(np.sqrt(ll))])
    return float(d[i]), float(cum[i] + t[i] * np.sqrt(ll[i]))


def boundary_walk(a: np.ndarray, b: np.ndarray, shape: Shape, max_len: float) -> Optional[np.ndarray]:
    """The shorter way from a to b along the region boundary loop both lie on, as a polyline, if at most
    `max_len` long; None otherwise."""
    for ring in shape:
        ring = np.asarray(ring, dtype=float)
        da, sa = _locate(ring, a)
        db, sb = _locate(ring, b)
        if da > _ON_BOUNDARY_MM or db > _ON_BOUNDARY_MM:
            continue
        lengths = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
        cum = np.concatenate([[0.0], np.cumsum(lengths)])
        per = float(cum[-1])
        ahead = (sb - sa) % per
        if min(ahead, per - ahead) > max_len:
            return None
        if ahead <= per - ahead:   # forward along the ring: the vertices passed from sa to sa + ahead
            s = cum[:-1]
            passed = ((s - sa) % per > 1e-12) & ((s - sa) % per < ahead - 1e-12)
            order = np.argsort((s[passed] - sa) % per)
        else:                      # backward
            s = cum[:-1]
            passed = ((sa - s) % per > 1e-12) & ((sa - s) % per < per - ahead - 1e-12)
            order = np.argsort((sa - s[passed]) % per)
        return np.vstack([a, ring[passed][order], b])
    return None


def _link(a: np.ndarray, b: np.ndarray, shape: Shape, edges, max_link: float) -> Optional[np.ndarray]:
    """The link from a to b (see the module doc), or None: a jump."""
    if float(np.hypot(*(b - a))) <= max_link and segment_inside(a, b, shape, edges):
        return np.array([a, b])
    return boundary_walk(a, b, shape, max_link)


def _length(p: np.ndarray) -> float:
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


def zigzag_chains(pieces: Sequence[Sequence[np.ndarray]], shape: Shape, max_link: float) -> list[Chain]:
    """Chains through the pieces of each pass (pieces[i]: pass i's pieces, each (2, 2) in the pass
    direction) by the zig-zag rule above."""
    edges = edges_of(shape)
    left = [list(range(len(p))) for p in pieces]
    chains: list[Chain] = []
    first = 0  # the first pass with a piece left: a chain takes pieces only after it, so it only grows
    while True:
        while first < len(left) and not left[first]:
            first += 1
        if first == len(left):
            return chains
        j = left[first].pop(0)
        piece = pieces[first][j]
        if chains:  # start at the end nearer the previous chain's end: a shorter jump
            end = chains[-1][-1][1][-1]
            if np.hypot(*(piece[-1] - end)) < np.hypot(*(piece[0] - end)):
                piece = piece[::-1]
        elif first % 2:
            piece = piece[::-1]
        chain: Chain = [(None, piece)]
        i = first
        while i + 1 < len(pieces) and left[i + 1]:
            end = chain[-1][1][-1]
            best = None
            cands = [(float(np.hypot(*(c[0] - end))), j, c) for j in left[i + 1]
                     for c in (pieces[i + 1][j], pieces[i + 1][j][::-1])]
            for _, j, cand in sorted(cands, key=lambda t: t[0]):
                link = _link(end, cand[0], shape, edges, max_link)
                if link is not None and (best is None or _length(link) < best[0]):
                    best = (_length(link), j, cand, link)
            if best is None:
                break
            left[i + 1].remove(best[1])
            chain.append((best[3], best[2]))
            i += 1
        chains.append(chain)


def oneway_chains(pieces: Sequence[Sequence[np.ndarray]]) -> list[Chain]:
    """Every piece alone, pass after pass, in the pass direction."""
    return [[(None, p)] for row in pieces for p in row]


def curve_chains(pieces: Sequence[np.ndarray], shape: Shape, max_link: float) -> list[Chain]:
    """Pieces of one curve in curve order, linked where they can be."""
    edges = edges_of(shape)
    chains: list[Chain] = []
    for p in pieces:
        link = _link(chains[-1][-1][1][-1], p[0], shape, edges, max_link) if chains else None
        if link is not None:
            chains[-1].append((link, p))
        else:
            chains.append([(None, p)])
    return chains


Run = tuple[bool, np.ndarray]  # (is_link, xy): raster_drop's runs of XY points to drop


def _sample_polyline(p: np.ndarray, step: float) -> np.ndarray:
    """Points along the polyline no more than `step` apart, its vertices kept."""
    parts = [sample_segment(a, b, step)[:-1] for a, b in zip(p[:-1], p[1:]) if np.hypot(*(b - a)) > 0]
    return np.vstack(parts + [p[-1:]]) if parts else p[-1:]


def chain_runs(chains: Sequence[Chain], sample_step: float) -> list[list[Run]]:
    """Each chain as raster_drop's runs: its pieces sampled at most `sample_step` apart (a curve's pieces
    are sampled already) and, between two, the link's interior points (at least one, so the move across
    is dropped and checked like any other)."""
    out = []
    for chain in chains:
        runs: list[Run] = []
        for link, piece in chain:
            if link is not None:
                length = _length(link)
                step = min(sample_step, length / 2) if length > 1e-9 else sample_step
                runs.append((True, _sample_polyline(link, step)[1:-1]))
            runs.append((False, piece if len(piece) > 2 else sample_segment(piece[0], piece[-1], sample_step)))
        out.append(runs)
    return out
