"""Exact waterline: at a tip height z, the closed loops of tool positions where the cutter touches the mesh
without gouging (the boundary of the region where the drop-cutter height exceeds z), by the kernel.

    loops = waterline_loops(DropSurface(mesh), Cutter.ball(6), [5.0, 4.0], (0, 0, 100, 80))
    for level in loops:            # one list per z, in the order given
        for loop in level:         # loop.xy (n, 2), loop.contact (n,), loop.island, loop.area

Method and limits: docs/waterline.md (a feature narrower than the sample step can be missed between grid
lines, as with any sampled method; `min_step` samples again, down to that step, the cells where a feature
could hide between the nodes: the adaptive grid).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.tools.cutter import Cutter

_DEFAULT_GRID_NODES = 4_000_000  # the default sample step keeps the shared drop grid below this
_BYTES_PER_NODE = 24             # the grid's xy and heights
_BYTES_PER_POINT = 64            # a loop point: kernel, numpy and segment copies
_REFINE_FACTOR = 4.0             # loop points per grid crossing, at most on average (chord refinement)


@dataclass
class WaterlineLoop:
    xy: np.ndarray        # (n, 2) tool-tip XY, closed implicitly (the first point is not repeated at the end)
    z: float              # the tip height of the level
    contact: np.ndarray   # (n,) bool: True where the point is an exact contact (False: on the bounds' edge)

    @property
    def island(self) -> bool:
        """True: counter-clockwise around blocked material (an outside loop); False: a pocket/hole."""
        return self.area > 0

    @property
    def area(self) -> float:
        """Signed area (shoelace), > 0 for islands."""
        x, y = self.xy[:, 0], self.xy[:, 1]
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))

    def __len__(self) -> int:
        return len(self.xy)


def default_sample_step(cutter: Cutter, bounds: tuple[float, float, float, float]) -> float:
    """A quarter of the cutter radius, coarser only where the grid would pass _DEFAULT_GRID_NODES."""
    w, h = bounds[2] - bounds[0], bounds[3] - bounds[1]
    return max(cutter.radius / 4.0, math.sqrt(max(w * h, 0.0) / _DEFAULT_GRID_NODES))


def estimate_work(bounds: tuple[float, float, float, float], levels: int, sample_step: float,
                  levels_from: str = "") -> float:
    """Drops of the shared grid plus loop points over all levels (crossings of the grid lines, a few per
    line, refined), refused above core.limits before anything is allocated; `levels_from` names what sets the
    level count (the strategy's step-down and range)."""
    w, h = bounds[2] - bounds[0], bounds[3] - bounds[1]
    nx, ny = math.ceil(w / sample_step) + 3, math.ceil(h / sample_step) + 3
    nodes = float(nx) * float(ny)
    points = levels * 4.0 * (nx + ny) * _REFINE_FACTOR
    cause = (f"sample step {sample_step:g} mm over a {w:.6g} x {h:.6g} mm boundary and {levels:.6g} waterline "
             f"level{'s' if levels != 1 else ''}{f' ({levels_from})' if levels_from else ''}")
    memory = _BYTES_PER_NODE * nodes + _BYTES_PER_POINT * points
    check_work("waterline drops and points", nodes + points, memory / (nodes + points), cause)
    if nodes > native.WATERLINE_MAX_GRID_NODES:
        raise TmmError(f"{cause} gives a drop grid of {nodes:.3g} nodes, more than the kernel's limit of "
                       f"{native.WATERLINE_MAX_GRID_NODES:.3g}; use a larger sample step or a smaller boundary")
    return nodes + points


def _finite(name: str, value: object) -> float:
    if not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool) \
            or not math.isfinite(float(value)):
        raise TmmError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def waterline_loops(surface: DropSurface, cutter: Cutter, zs: Sequence[float],
                    bounds: tuple[float, float, float, float], *, sample_step: float | None = None,
                    chord_tol: float = 0.01, threads: int = 0, progress: Progress | None = None,
                    min_step: float | None = None) -> list[list[WaterlineLoop]]:
    """For each z in zs (any order; returned in the same order), the closed loops of tip positions at height z
    where `cutter` touches the mesh of `surface` without gouging, within bounds (xmin, ymin, xmax, ymax) of the
    tip. Cancels with core.errors.Cancelled; bad input TmmError by name.

    The blocked region (where the tool would cut the mesh) lies on the left of every loop: islands run
    counter-clockwise, pockets clockwise. Every contact point is free (its drop height is at most z) and
    within 1e-7 mm of a point that is blocked; chords between neighbours stay within `chord_tol` of the exact
    loop. Points where the blocked region runs past the bounds lie on the bounds and have contact False.
    Stock to leave s: pass `cutter.offset(s)` and the levels z - s, then add s to the loops' z (exact: the grown
    cutter's surface lies s below this one's, Cutter.offset).

    min_step (mm, None: off): the adaptive grid. Per level, cells of the sample_step grid where a feature could
    hide between the nodes (saddles; a free corner whose drop height is within the cutter's lift over a cell
    of z, where triangles can hold the tool above z) are sampled again at sample_step / 2^m <= min_step, so a
    coarse sample_step finds loops and spikes down to about min_step (docs/waterline.md, "Adaptive grid")."""
    if len(bounds) != 4:
        raise TmmError(f"waterline bounds must be four numbers xmin, ymin, xmax, ymax, got {bounds!r}")
    b = tuple(_finite(f"waterline bounds {k}", v) for k, v in zip(("xmin", "ymin", "xmax", "ymax"), bounds))
    if not (b[2] > b[0] and b[3] > b[1]):
        raise TmmError(f"waterline bounds are empty: x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g}")
    levels = [_finite("waterline level z", z) for z in zs]
    step = default_sample_step(cutter, b) if sample_step is None else _finite("sample step", sample_step)
    if not step > 0:
        raise TmmError(f"sample step must be a positive length, got {step:g} mm")
    tol = _finite("chord tolerance", chord_tol)
    if not 0 < tol <= 1.0:
        raise TmmError(f"chord tolerance must be in (0, 1] mm, got {tol:g}")
    if not isinstance(threads, int) or isinstance(threads, bool) or threads < 0:
        raise TmmError(f"threads must be a whole number >= 0 (0: all cores), got {threads!r}")
    fine = 0.0
    if min_step is not None:
        fine = _finite("minimum step", min_step)
        if not step / 256.0 <= fine <= step:
            raise TmmError(f"minimum step must be in [sample step / 256, sample step] = [{step / 256.0:g}, {step:g}] "
                           f"mm, got {fine:g} mm")
    if not levels:
        return []
    estimate_work(b, len(levels), step)

    o = native.WaterlineOptions()
    o.xmin, o.ymin, o.xmax, o.ymax = b
    o.sample_step = step
    o.chord_tol = tol
    o.bracket = min(1e-7, tol / 4)
    o.min_step = fine
    try:
        out, _ = native.waterline(surface.index, cutter.native, levels, o, threads=threads, progress=progress)
    except native.Cancelled as exc:
        raise Cancelled("waterline computation cancelled") from exc
    except ValueError as exc:
        raise TmmError(str(exc)) from exc
    return [[WaterlineLoop(xy, z, contact) for xy, contact in level] for z, level in zip(levels, out)]
