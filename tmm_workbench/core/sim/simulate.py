"""What a tool path leaves in the stock: the kernel cuts the z-map along every move (3-axis: the APT cutter's
swept envelope, exact per cell; 5-axis: the torus sub-stepped along the move, tip straight and axis by slerp,
bound in the kernel's sweep5.hpp; a flat end mill is the bull-nose solid with corner radius 0, exactly).
Rapids cut too; one that removes material is a collision (a crash on the machine), reported with its move.
With a tool assembly, its neck, shank and holder are checked against the stock as it is at each move
(core.sim.stock_collisions)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock_collisions import CheckedBodies, StockCollisions
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
CUT, RAPID = 0, 1  # the kernel's MoveKind
SHAPES_5AXIS = ("round_insert", "bull_nose")


@dataclass
class SimResult:
    grid: Grid
    initial: np.ndarray       # (ny, nx) stock heights before cutting
    heights: np.ndarray       # (ny, nx) after
    collisions: np.ndarray    # (k, 2): [move index, depth mm] of rapids that removed material
    moves_cut: int
    cells_lowered: int
    seconds: float
    five_axis: bool
    stock_collisions: Optional[StockCollisions] = None  # with an assembly: its bodies against the stock

    @property
    def removed_volume(self) -> float:
        """mm^3 removed from the stock."""
        return float(np.sum(self.initial - self.heights) * self.grid.cell_area)


def move_kinds(toolpath: Toolpath) -> np.ndarray:
    """(n - 1,) kernel kinds: the move into point k + 1 is a rapid when point k + 1 is reached by G0."""
    return np.array([RAPID if m.kind is MoveKind.RAPID else CUT for m in toolpath.moves[1:]], dtype=np.uint8)


def solid_radii(tool: Cutter) -> tuple[float, float]:
    """(Ro, Ri) of the 5-axis simulated solid: the toroidal view, a flat end mill (R, 0) (the bull-nose solid
    with corner radius 0: flat bottom, rim, cylinder)."""
    return (tool.radius, 0.0) if tool.kind == "flat" else tool.torus_radii


def sub_step(tool: Cutter, tolerance: float, max_tilt: float = math.pi / 4) -> float:
    """The 5-axis sub-step whose error between instances is a tenth of `tolerance`, at most 0.5 mm: the cusp
    s^2 / (8 Ri) of the torus (the kernel's sweep5.hpp bound), sqrt(0.8 Ri tol); a flat end mill's tilted
    bottom leaves a sawtooth s tan(tilt) instead (its rim has no radius), so s = 0.1 tol / tan(`max_tilt`)."""
    _, Ri = solid_radii(tool)
    if Ri == 0.0:
        return min(0.5, 0.1 * tolerance / max(math.tan(min(max_tilt, 1.5)), 1e-3))
    return min(0.5, math.sqrt(0.8 * Ri * tolerance))


def max_tilt(toolpath: Toolpath) -> float:
    """The largest angle (rad) of a cutting move's tool axis from the vertical."""
    cut = move_kinds(toolpath) == CUT
    axes = toolpath.axes()[1:][cut]
    return float(np.arccos(np.clip(axes[:, 2], -1.0, 1.0)).max(initial=0.0))


def simulate(toolpath: Toolpath, tool: Cutter, grid: Grid, stock: np.ndarray, *, shape: str = "bull_nose",
             max_step: Optional[float] = None, tolerance: float = 0.01, collision_tol: float = 1e-3, threads: int = 0,
             progress: Optional[Progress] = None, assembly: Optional[ToolAssembly] = None,
             body_tolerance: float = 1e-3) -> SimResult:
    """Cuts `stock` ((ny, nx) heights on `grid`, copied) along `toolpath` with `tool`. A 5-axis path (any
    axis off vertical) needs a toroidal, ball or flat tool (`solid_radii`); `shape` is its solid
    ('bull_nose': a solid end mill; 'round_insert': the seed's insert cutter with its hollow); its moves are
    sub-stepped `max_step` mm apart (default: sub_step(tool, tolerance, the path's largest cutting tilt)). `assembly`: the tool's neck, shank and
    holder are checked against the stock as each move finds it (`stock_collisions`; deeper than `body_tolerance`
    mm into a clearance counts); its cutter is `tool`'s, so only what stands above the flutes is taken."""
    if len(toolpath) < 2:
        raise TmmError("the tool path to simulate has no moves")
    stock = np.asarray(stock, dtype=float)
    if stock.shape != (grid.ny, grid.nx):
        raise TmmError(f"stock heights have shape {stock.shape}, the grid {grid.ny} x {grid.nx}")
    if not np.isfinite(stock).all():
        raise TmmError("stock heights must be finite")
    tips = np.ascontiguousarray(toolpath.points())
    bad = np.flatnonzero(~np.isfinite(tips).all(axis=1))
    if len(bad):
        raise TmmError(f"tool path point {int(bad[0])} is not finite: {tips[bad[0]].tolist()}")
    kinds = move_kinds(toolpath)
    five = toolpath.is_five_axis()
    if five and shape not in SHAPES_5AXIS:
        raise TmmError(f"5-axis tool shape must be one of {', '.join(SHAPES_5AXIS)}, got {shape!r}")
    bodies = None if assembly is None else CheckedBodies.of(assembly)
    if not (isinstance(body_tolerance, (int, float)) and math.isfinite(body_tolerance) and body_tolerance >= 0):
        raise TmmError(f"body tolerance must be a finite length >= 0 mm, got {body_tolerance!r}")
    check = {} if bodies is None else {"bodies": bodies.rows, "body_tol": float(body_tolerance)}
    zmap = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
    zmap.heights[:] = stock
    t0 = time.perf_counter()
    try:
        if five:
            Ro, Ri = solid_radii(tool)
            max_step = sub_step(tool, tolerance, max_tilt(toolpath)) if max_step is None else max_step
            rep = native.cut_5axis(zmap, Ro, Ri, shape, tips, np.ascontiguousarray(toolpath.axes()), kinds,
                                   max_step, collision_tol, threads, progress, **check)
        else:
            if bodies is not None:
                check["flute_top"] = bodies.flute_top
            rep = native.cut_3axis(zmap, tool.native, tips, kinds, collision_tol, threads, progress, **check)
    except native.Cancelled as exc:
        raise Cancelled("simulation cancelled") from exc
    except ValueError as exc:
        raise TmmError(f"simulation: {exc}") from exc
    found = None if bodies is None else StockCollisions.from_kernel(rep["body_collisions"], bodies,
                                                                    int(rep["moves_cut"]))
    return SimResult(grid, stock.copy(), np.array(zmap.heights), np.asarray(rep["collisions"]).reshape(-1, 2),
                     int(rep["moves_cut"]), int(rep["cells_lowered"]), time.perf_counter() - t0, five, found)
