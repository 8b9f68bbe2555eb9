"""Joins between the pieces of a rest's passes and waterline loops (core.strategies.rest_steep): the next piece
reached with the tool down, by a fed move, instead of a lift, a hop and a plunge at the plunge feed.

A large tool's rest on a slope is a scatter of short loop pieces (mount_rush: 1,467 pieces, median 0.4 mm, each
entered by a hop and a 1.6 mm plunge at the plunge feed: a third of the rest's time). The move from one piece's
end a to the next one's start b, at most longest_join apart (JOIN_DIAMETERS tool diameters, at least JOIN_MM) and a
level up or down, is the
straight line a -> b lifted where the surface stands above it: sampled SAMPLE_MM apart along it, each sample at
the higher of the line and the tool's drop there (plus the stock to leave), midpoints inserted where a steep wall
rises between two, then thinned by chords that pass no lower than any sample (surface.segments.reduce_chords). It stays on or above the surface: it cuts the rest
material it crosses, never the model. One longer than longest_join so lifted (over a letter between two pieces at its
feet) is not made: the hop is quicker. Before it is kept, its cut is checked: the moves against the model
(core.verify.linear_moves, DEEPEST_MM) and, with a tool assembly and a join longer than the tool radius (a
shorter one stays within the pieces' own reach), the neck, shank and holder against it along every sample
(core.query.drop_assembly, the holder guard's clearance). A join that fails is not made: the linker enters the
piece as before.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import CutSegment, SegmentKind
from tmm_workbench.core.strategies.surface.segments import reduce_chords
from tmm_workbench.core.tools.cutter import Cutter

JOIN_DIAMETERS = 2.0   # the longest join (XY and rise; its length lifted onto the surface too), in tool diameters:
#                        a 2 mm plunge at 300 mm/min and the hop take as long as about 6 mm at 1000 mm/min
JOIN_MM = 4.0          # and at least this long: the hop and its plunge of the clearance (1 mm at a third of the feed,
#                        the rapids) do not shrink with the tool (a D1's 2 mm left the sign's clean-up 600 entries)
SAMPLE_MM = 0.05       # the join's samples along the line (linear_moves' step)
HOP_SAMPLE_MM = 0.25   # a low hop's, for the shank and holder only (each wider than a millimetre: a wall they meet
#                        stands under several samples)
CHORD_MM = 0.002       # a thinned join passes at most this far above its samples
DEEPEST_MM = 1e-3      # a join whose moves come this far below the model's drop between samples is not made
REFINE_ROUNDS = 8      # halvings of a move between samples where the midpoint's drop stands above it
MIN_GAP_MM = 1e-3      # down to this far apart


def join_pieces(mesh: TriMesh, cutter: Cutter, params: Any, segments: list[CutSegment],
                surface: DropSurface) -> tuple[list[CutSegment], int]:
    """`segments` (the rest's pieces of passes and loops, in cutting order) with each piece that is not joined
    reached from the one before by a join where one passes the checks (see the module): a LINK segment of its
    interior points, joined, before it, and the piece marked joined (in place); the segments and the number of
    joins made."""
    s = max(float(getattr(params, "stock_to_leave", 0.0)), 0.0)
    grown = cutter.offset(s)
    longest = longest_join(cutter)
    candidates = [k for k in range(1, len(segments)) if not segments[k].joined
                  and _near(segments[k - 1].tips[-1], segments[k].tips[0], longest)]
    if not candidates:
        return segments, 0
    joins = {k: lifted(segments[k - 1].tips[-1], segments[k].tips[0], surface, grown, s) for k in candidates}
    # no longer than the hop's time (a join lifted over a letter between two pieces beside it is not)
    joins = {k: p for k, p in joins.items() if _length(p) <= longest and _clear_of_model(p, surface, grown, s)}
    assembly = getattr(params, "assembly", None)
    if assembly is not None:
        from tmm_workbench.core.sim.stock_bodies import bodies_drop

        bodies = bodies_drop(mesh, assembly, surface, getattr(params, "stock", None))
        joins = {k: p for k, p in joins.items() if _length(p) <= cutter.radius or _clear_of_bodies(bodies, p)}
    out: list[CutSegment] = []
    for k, seg in enumerate(segments):
        path = joins.get(k)
        if path is not None:
            if len(path) > 2:
                out.append(CutSegment(path[1:-1], SegmentKind.LINK, joined=True, pass_index=seg.pass_index))
            seg.joined = True
        out.append(seg)
    return out, len(joins)


def longest_join(cutter: Cutter) -> float:
    """The longest join for `cutter`, mm (see JOIN_DIAMETERS, JOIN_MM)."""
    return max(JOIN_DIAMETERS * cutter.diameter, JOIN_MM)


def _near(a: np.ndarray, b: np.ndarray, longest: float) -> bool:
    return float(np.hypot(*(b[:2] - a[:2]))) <= longest and abs(float(b[2] - a[2])) <= longest


def _length(p: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def lifted(a: np.ndarray, b: np.ndarray, surface: DropSurface, grown: Cutter, s: float) -> np.ndarray:
    """(k, 3) the join a -> b: the line lifted onto the surface where it stands above it, thinned."""
    n = max(1, int(math.ceil(float(np.hypot(*(b[:2] - a[:2]))) / SAMPLE_MM)))
    f = np.linspace(0.0, 1.0, n + 1)[:, None]
    pts = a + f * (b - a)
    floor = float(min(a[2], b[2])) - s - 1e3

    def lift(p: np.ndarray) -> None:
        p[:, 2] = np.maximum(p[:, 2], surface.drop(grown, p[:, :2], floor) + s)

    if n > 1:
        lift(pts[1:-1])
    for _ in range(REFINE_ROUNDS):   # a steep wall rises between two samples: its midpoints lifted too
        mid = 0.5 * (pts[1:] + pts[:-1])
        z = mid[:, 2].copy()
        lift(mid)
        low = (mid[:, 2] - z > DEEPEST_MM / 10) & (np.hypot(*np.diff(pts[:, :2], axis=0).T) > MIN_GAP_MM)
        if not low.any():
            break
        pts = np.insert(pts, np.flatnonzero(low) + 1, mid[low], axis=0)
    return reduce_chords(pts, CHORD_MM)


def _clear_of_model(path: np.ndarray, surface: DropSurface, grown: Cutter, s: float) -> bool:
    from tmm_workbench.core.verify.linear_moves import deepest_cut

    moves = path - np.array([0.0, 0.0, s])   # the grown cutter's tips lie s lower
    return deepest_cut(surface, grown, moves, np.ones(len(moves), dtype=bool), SAMPLE_MM / 2)[0] <= DEEPEST_MM


def _clear_of_bodies(bodies: Any, path: np.ndarray, step: float = SAMPLE_MM) -> bool:
    """Whether the neck, shank and holder (an AssemblyDrop) keep their clearance along the join's samples."""
    from tmm_workbench.core.strategies.holder_guard import BODIES, TOLERANCE_MM
    from tmm_workbench.core.strategies.segment_split import move_samples

    pts, _ = move_samples(CutSegment(path), step)
    zb, owner = bodies.heights_of(BODIES, pts[:, :2])
    return not bool(np.any((zb - pts[:, 2] > TOLERANCE_MM) & (owner >= 0)))


def bodies_clear(mesh: TriMesh, assembly: Any, surface: Optional[DropSurface] = None, stock: Any = None
                 ) -> Callable[[np.ndarray], bool]:
    """Whether a straight move ((k, 3) tips, sampled HOP_SAMPLE_MM apart) keeps the neck, shank and holder of
    `assembly` their clearance from `mesh` and from `stock` (the in-process stock the op starts from:
    core.sim.stock_bodies; None: the model only), the holder guard's: the linker's check of its low hops
    (LinkPolicy.hop_clear). The bodies' drop (and, without `surface`, the mesh's index) is built at the first
    move asked: an op sets the check up before it computes, and most ops hop seldom or never; built there, it
    indexed the mesh a second time outside the op's progress and cancel."""
    from tmm_workbench.core.sim.stock_bodies import bodies_drop

    bodies: list = []

    def clear(path: np.ndarray) -> bool:
        if not bodies:
            bodies.append(bodies_drop(mesh, assembly, surface or DropSurface(mesh), stock))
        return _clear_of_bodies(bodies[0], np.asarray(path, dtype=float), HOP_SAMPLE_MM)
    return clear
