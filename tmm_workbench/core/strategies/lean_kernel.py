"""Lean passes fitted in the kernel: native.lean_profiles (native/src/algo/lean_profile.cpp).

The straight runs of the segments (raster_lean's: passes and zig-zag links, split where the XY direction
turns) go to the kernel with their samples; it rebuilds each run's exact CL profile by adaptive exact drops
(breakpoints located where the triangle holding the cutter changes), fits the fewest lines within +-tol of it
by min-link windows and checks them at the drop intervals' midpoints near the band's edge (see the header).
With `arcs`, in runs that lie in a principal vertical plane (XZ or YZ) the kernel then merges consecutive moves
into one arc (G2/G3) or one longer line where that holds the same band and checks (native/src/algo/lean_arcs.cpp).
The ends of a run, both ends of a vertical move and the moves beside air stay as sampled, as in the Python fit
(tests/core/lean_reference.py, the slow reference). The arcs ride in the segments (CutSegment.arcs).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.segments import ArcsAt, CutSegment
from tmm_workbench.core.strategies.raster_lean import Run, RunKey, plane_of, run_xy, straight_runs, with_runs_replaced
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
MIN_STEP_MM = 0.002  # breakpoints of the profile located to this


@dataclass(frozen=True)
class ExactDrop:
    """The exact CL height as the raster computes it: the drop of `tool` (the cutter grown by the stock to
    leave) at `drop_floor`, raised by `z_shift`, at least `clamp_floor`; air (off-model, skip) where the raised
    drop is at or below `air_below` (-inf: never)."""
    index: "native.MeshIndex"
    tool: Cutter
    drop_floor: float
    z_shift: float = 0.0
    clamp_floor: float = -math.inf
    air_below: float = -math.inf


def lean_segments_kernel(segments: list[CutSegment], exact: ExactDrop, tol: float, max_step: float = 0.05,
                         lower_bound: bool = False, progress: Optional[Progress] = None, threads: int = 0,
                         arcs: bool = False) -> tuple[list[CutSegment], dict]:
    """The segments with each straight run's points replaced by the kernel's lean vertices (with `arcs`, the
    moves that are arcs in CutSegment.arcs) and the counts (points_in, points_out, arcs, checked: the kernel's
    exact drops, breakpoints, refits, kept_dense, and with `lower_bound` the least lines any fit within +-tol can
    use on these runs)."""
    if not tol > 0:
        raise TmmError(f"chord tolerance must be > 0 mm for lean passes, got {tol:g}")
    parts, by_key = straight_runs(segments)
    keys, runs = list(by_key), list(by_key.values())
    stats = dict(points_in=sum(len(seg) for seg in segments), arcs=0, checked=0, breakpoints=0, refits=0,
                 kept_dense=0, lower_bound=0)
    if not runs:
        stats["points_out"] = stats["points_in"]
        return list(segments), stats
    planes = [plane_of(r.u) if arcs else None for r in runs]
    flags = [np.where(r.fixed, native.LEAN_FIXED, 0) | np.where(r.settled, native.LEAN_KEEP, 0) for r in runs]
    offsets = np.concatenate([[0], np.cumsum([len(r.s) for r in runs])]).astype(np.int64)
    try:
        off, s, z, info = native.lean_profiles(
            exact.index, exact.tool.native, np.array([r.origin for r in runs]), np.array([r.u for r in runs]),
            offsets, np.concatenate([r.s for r in runs]), np.concatenate([r.e for r in runs]),
            np.concatenate(flags).astype(np.uint8), tol=float(tol), max_step=float(max_step), min_step=MIN_STEP_MM,
            drop_floor=float(exact.drop_floor), z_shift=float(exact.z_shift), clamp_floor=float(exact.clamp_floor),
            air_below=float(exact.air_below), lower_bound=lower_bound,
            arcs=np.array([p is not None for p in planes], dtype=np.uint8) if arcs else None, threads=threads,
            progress=progress)
    except native.Cancelled as exc:
        raise Cancelled("tool path computation cancelled") from exc
    except ValueError as exc:  # named by the kernel; max_step is the op's sample step / 2
        raise TmmError(f"lean passes: {exc} (max_step {max_step:g} mm)") from exc
    verts = {key: np.column_stack([run_xy(r, s[off[n]:off[n + 1]]), z[off[n]:off[n + 1]]])
             for n, (key, r) in enumerate(zip(keys, runs))}
    out = with_runs_replaced(segments, parts, verts, verts.__getitem__,
                             _run_arcs(keys, runs, planes, verts, info.get("arc_s"), info.get("arc_z"), off))
    stats.update(points_out=sum(len(seg) for seg in out), checked=int(info["drops"]),
                 breakpoints=int(info["breakpoints"]), refits=int(info["refits"]),
                 kept_dense=int(info["kept_dense"]), lower_bound=int(info["lower_bound"]), arcs=int(info["arcs"]))
    return out, stats


def _run_arcs(keys: list[RunKey], runs: list[Run], planes: list[Optional[str]], verts: dict[RunKey, np.ndarray],
              centre_s: Optional[np.ndarray], centre_z: Optional[np.ndarray], off: np.ndarray
              ) -> dict[RunKey, ArcsAt]:
    """Per run with arcs, per vertex the arc of the move ending there (None: a line), from the kernel's centres
    (distance along the run and height at each vertex, NaN for a line; run n's vertices at off[n]:off[n + 1])."""
    out: dict[RunKey, ArcsAt] = {}
    for n, (key, r) in enumerate(zip(keys, runs)):
        if planes[n] is None:  # fitted with lines only
            continue
        cs, cz = centre_s[off[n]:off[n + 1]], centre_z[off[n]:off[n + 1]]
        found = np.flatnonzero(np.isfinite(cs))
        if not len(found):
            continue
        v = verts[key]
        at: list[Optional[Arc]] = [None] * len(v)
        for i in found:
            at[i] = Arc.through(v[i - 1], v[i], (*(r.origin + cs[i] * r.u), cz[i]), planes[n])
        out[key] = tuple(at)
    return out
