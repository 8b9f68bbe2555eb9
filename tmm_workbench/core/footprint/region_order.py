"""Pass pieces clipped to a machining region, put in cutting order as chains.

A chain is cut with the tool down: its pieces one after the other, joined by straight links the strategy
drops on the surface (gouge-free like any dropped point). A link is made only where the straight move
between two pieces stays inside the region and is at most `max_link` long; anywhere else the chain ends
and the next starts with a "jump" (seed 003's lift flag: the linker lifts to the safe height, crosses and
plunges, core.linking).

Zig-zag: from the end of the current piece the nearest piece of the next pass that can be linked; when
there is none, the chain ends and the next one starts from the first pass that still has a piece (so a
region with a hole is cut side by side, one jump per side instead of one per pass). One-way: every piece
its own chain, pass after pass, each in the pass direction. Along a curve (spiral): pieces in curve
order, linked where they can be.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from tmm_workbench.core.footprint.raster import sample_segment
from tmm_workbench.core.footprint.region import edges_of, segment_inside
from tmm_workbench.core.polygons import Shape

Chain = list[np.ndarray]  # pieces ((k, 2) XY polylines) in cutting order


def _linkable(a: np.ndarray, b: np.ndarray, shape: Shape, edges, max_link: float) -> bool:
    return float(np.hypot(*(b - a))) <= max_link and segment_inside(a, b, shape, edges)


def zigzag_chains(pieces: Sequence[Sequence[np.ndarray]], shape: Shape, max_link: float) -> list[Chain]:
    """Chains through the pieces of each pass (pieces[i]: pass i's pieces, each (2, 2) in the pass
    direction) by the zig-zag rule above."""
    edges = edges_of(shape)
    left = [list(range(len(p))) for p in pieces]
    chains: list[Chain] = []
    while True:
        first = next((i for i, rest in enumerate(left) if rest), None)
        if first is None:
            return chains
        j = left[first].pop(0)
        piece = pieces[first][j]
        if chains:  # start at the end nearer the previous chain's end: a shorter jump
            end = chains[-1][-1][-1]
            if np.hypot(*(piece[-1] - end)) < np.hypot(*(piece[0] - end)):
                piece = piece[::-1]
        elif first % 2:
            piece = piece[::-1]
        chain = [piece]
        i = first
        while i + 1 < len(pieces) and left[i + 1]:
            end = chain[-1][-1]
            best = None
            for j in left[i + 1]:
                for cand in (pieces[i + 1][j], pieces[i + 1][j][::-1]):
                    gap = float(np.hypot(*(cand[0] - end)))
                    if (best is None or gap < best[0]) and _linkable(end, cand[0], shape, edges, max_link):
                        best = (gap, j, cand)
            if best is None:
                break
            left[i + 1].remove(best[1])
            chain.append(best[2])
            i += 1
        chains.append(chain)


def oneway_chains(pieces: Sequence[Sequence[np.ndarray]]) -> list[Chain]:
    """Every piece alone, pass after pass, in the pass direction."""
    return [[p] for row in pieces for p in row]


def curve_chains(pieces: Sequence[np.ndarray], shape: Shape, max_link: float) -> list[Chain]:
    """Pieces of one curve in curve order, linked where they can be."""
    edges = edges_of(shape)
    chains: list[Chain] = []
    for p in pieces:
        if chains and _linkable(chains[-1][-1][-1], p[0], shape, edges, max_link):
            chains[-1].append(p)
        else:
            chains.append([p])
    return chains


Run = tuple[bool, np.ndarray]  # (is_link, xy): raster_drop's runs of XY points to drop


def chain_runs(chains: Sequence[Chain], sample_step: float) -> list[list[Run]]:
    """Each chain as raster_drop's runs: its pieces sampled at most `sample_step` apart (a curve's pieces
    are sampled already) and, between two, the link's interior points (at least its midpoint, so the move
    across is dropped and checked like any other)."""
    out = []
    for chain in chains:
        runs: list[Run] = []
        for k, piece in enumerate(chain):
            if k:
                a, b = chain[k - 1][-1], piece[0]
                length = float(np.hypot(*(b - a)))
                link = sample_segment(a, b, min(sample_step, length / 2))[1:-1] if length > 1e-9 else piece[:0]
                runs.append((True, link))
            runs.append((False, piece if len(piece) > 2 else sample_segment(piece[0], piece[-1], sample_step)))
        out.append(runs)
    return out
