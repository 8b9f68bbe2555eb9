"""The clean-up after a 5-axis mesh finish: what its passes leave above the tolerance, found by the 5-axis stock
simulation of its tool path, finished by a smaller 3-axis ball end mill (the rest machinery of the 3-axis
Surface op: core.footprint.rest, raster_drop with its rest filter, holder guard and steep loops), and what the
ball cannot reach either reported with its area.

What the finish leaves: the strips no posture finishes (the plan's `unfinished`, marked by finish.cleanup_points)
and what the passes' ends leave along a boundary that runs slanted across the drive planes (a sliver a cell or
two wide on seed 000's concave surface; its right side step stops at the last ray sample on the mesh), and
beside a path cut short where the surface falls beyond the machine's tilt. The simulation sees all of them; the
plan lists only the first. So the clean-up is told by the simulation, and its note says how much of what was
left lies outside the listed strips.

    segments, note = cleanup(mesh, flat, path5, Cutter.ball(4), tolerance=0.1, feed_angle_deg=0)
    path3 = link(segments, LinkPolicy(safe, clearance))     # the ball's own tool path (a tool change before it)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.rest import rest_area, tool_envelope, without_specks
from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core import polygons
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.report_text import within
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import CUT, max_tilt, move_kinds, simulate, sub_step
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.rest_steep import gradient
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.toolpath import Move, Toolpath
from tmm_workbench.core.tools.cutter import Cutter

MAX_CELL = 0.25          # mm: the simulation's cells, at most (a ball radius / 8 below it), as the rest op's
STOCK_ABOVE = 0.5        # mm of stock over the design the finish starts from (as after a roughing)
CUSP_SHARE = 0.5         # of the tolerance: the ball's cusp on a flat between its passes
_BYTES_PER_CELL = 64     # design, stock, left, envelope and the masks
# mm between the simulated instances of a flat end mill, at most: where its rim crosses a cell between two of
# them the cell reads high (seed 000's convex and concave finishes against instances 0.01 mm apart: up to
# 0.0099 mm at 0.2, 0.0098 at 0.1 mm, a tenth of their 0.1016 mm tolerance; 28 and 6 more cells above it at 0.2)
MAX_STEP = 0.1


@dataclass
class Left:
    """What a 5-axis path leaves more than the tolerance above the design, along its normal (the simulation's
    cells)."""
    grid: Grid
    design: np.ndarray             # (ny, nx) the design's heights (NaN off the model)
    heights: np.ndarray            # (ny, nx) the stock after the path
    above: np.ndarray              # (ny, nx) cells above the tolerance (patches of fewer than 3 dropped)
    outside: np.ndarray            # (ny, nx) of them outside the listed strips (grown by the finish tool's radius)
    tolerance: float
    cos: np.ndarray                # (ny, nx) cos(the design's slope): a height above it x cos is along the normal

    @property
    def area(self) -> float:
        return float(self.above.sum() * self.grid.cell_area)

    @property
    def outside_area(self) -> float:
        return float(self.outside.sum() * self.grid.cell_area)

    def points(self, mask: np.ndarray) -> np.ndarray:
        """(k, 3) the centres of the mask's cells on the design."""
        return np.column_stack([self.grid.centres()[mask.ravel()], self.design[mask]])

    def summary(self) -> str:
        if not self.above.any():
            return f"the simulated finish leaves nothing above {self.tolerance:g} mm ({self.grid.cell:g} mm cells)"
        text = (f"the simulated finish leaves {self.area:.1f} mm2 above {self.tolerance:g} mm "
                f"({self.grid.cell:g} mm cells)")
        if self.outside.any():
            text += (f", {self.outside_area:.1f} mm2 of it outside the strips, {within(self.points(self.outside))}: "
                     "marked for clean-up")
        return text


@dataclass
class CleanupNote:
    """What the 5-axis finish left above the tolerance, and what the clean-up ball leaves (mm^2, simulated)."""
    tool: str
    tolerance: float
    cell: float
    left: float                    # area above the tolerance after the 5-axis finish
    outside_strips: float          # of it outside the plan's listed strips (grown by the finish tool's radius)
    after: float                   # area still above it after the clean-up (out of the ball's reach)
    after_points: np.ndarray       # (k, 3) centres of those cells on the design
    moves: int                     # the clean-up's cut positions

    def summary(self) -> str:
        if self.left <= 0:
            return (f"clean-up: nothing left above {self.tolerance:g} mm after the 5-axis passes (simulated, "
                    f"{self.cell:g} mm cells)")
        text = (f"clean-up with the {self.tool}: {self.left:.1f} mm2 left above {self.tolerance:g} mm by the 5-axis "
                f"passes (simulated, {self.cell:g} mm cells; {self.outside_strips:.1f} mm2 of it outside the listed "
                f"strips), {self.moves} positions")
        if self.after > 0:
            return text + (f"; {self.after:.1f} mm2 stay above it (out of the ball's reach too), "
                           f"{within(self.after_points)}")
        return text + "; nothing stays above it"


def check_tool(tool: Cutter) -> None:
    if not isinstance(tool, Cutter) or tool.kind != "ball":
        what = tool.describe() if isinstance(tool, Cutter) else type(tool).__name__
        raise TmmError(f"clean-up tool must be a ball end mill, got {what}")


def ball_stepover(radius: float, tolerance: float) -> float:
    """The ball's passes apart for a cusp of CUSP_SHARE of the tolerance on a flat (mm)."""
    cusp = min(CUSP_SHARE * tolerance, radius)
    return 2.0 * math.sqrt(2.0 * radius * cusp - cusp * cusp)


def cleanup_grid(mesh: TriMesh, cell: float = MAX_CELL) -> Grid:
    """The simulation's grid over the mesh's box (refused above the limits)."""
    c = float(cell)
    if not (math.isfinite(c) and c > 0):
        raise TmmError(f"clean-up cell must be a length > 0 mm, got {cell!r}")
    lo, hi = mesh.bounds
    grid = Grid.covering(float(lo[0]) - 1.0, float(lo[1]) - 1.0, float(hi[0]) + 1.0, float(hi[1]) + 1.0, c)
    check_work("clean-up simulation cells", grid.nx * grid.ny, _BYTES_PER_CELL, f"cells of {c:g} mm over the model")
    return grid


def lead_rates(path: Toolpath, radius: float) -> np.ndarray:
    """(n - 1,) per move, how fast a flat bottom of `radius` changes its height at a fixed (x, y) per mm
    travelled: |axis . direction| / axis_z (the larger of the move's two ends), and where the axis turns, its
    rim rising and falling by radius x the turn. A flat bottom sliding in its own plane (no lead tilt, no turn)
    changes nothing; the sawtooth between two simulated instances s apart is at most s x this rate."""
    pts, axes = path.points(), path.axes()
    d = np.diff(pts, axis=0)
    length = np.linalg.norm(d, axis=1)
    u = d / np.maximum(length, 1e-12)[:, None]
    a0, a1 = axes[:-1], axes[1:]
    z = np.maximum(np.minimum(a0[:, 2], a1[:, 2]), 0.05)
    lead = np.maximum(np.abs(np.einsum("ij,ij->i", a0, u)), np.abs(np.einsum("ij,ij->i", a1, u)))
    turn = np.arccos(np.clip(np.einsum("ij,ij->i", a0, a1), -1.0, 1.0))
    return np.where(length > 1e-12, (lead + radius * turn / np.maximum(length, 1e-12)) / z, 0.0)


def sim_path(path: Toolpath, radius: float, tolerance: float) -> Toolpath:
    """The path of a flat end mill of `radius` to simulate with instances at most MAX_STEP apart: each cutting
    move split into pieces short enough that its own sawtooth (lead_rates) is a tenth of `tolerance`. One
    sub-step for the whole path would be the steepest move's: a tool going down its own axis (the entries and
    exits) asks a hundredth of a mm of every move."""
    rate = lead_rates(path, radius)
    pts, axes = path.points(), path.axes()
    length = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    n = np.maximum(np.where(move_kinds(path) == CUT, np.ceil(rate * length / (0.1 * tolerance)), 1), 1)
    if (n == 1).all():
        return path
    k, tips, turned = _pieces(pts, axes, n.astype(np.int64))
    kinds = [m.kind for m in path.moves[1:]]
    return Toolpath([path.moves[0]] + [Move(kinds[j], *map(float, t), axis=tuple(map(float, v)))
                                       for j, t, v in zip(k.tolist(), tips, turned)])


def _pieces(pts: np.ndarray, axes: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each move k split into n[k] equal pieces as the simulation moves the tool (the tip straight, the axis by
    slerp): the move of each piece's end, its tip and its axis."""
    k = np.repeat(np.arange(len(n)), n)
    f = ((np.arange(len(k)) - np.repeat(np.cumsum(n) - n, n) + 1) / np.repeat(n, n))[:, None]
    return k, pts[k] + f * (pts[k + 1] - pts[k]), slerp(axes[k], axes[k + 1], f)


def material_left(mesh: TriMesh, cutter: Cutter, path: Toolpath, grid: Grid, tolerance: float,
                  stock_above: float = STOCK_ABOVE) -> tuple[np.ndarray, np.ndarray]:
    """(design, left): the design's heights on the grid (NaN off the model) and the stock `stock_above` over it
    after `path` of `cutter` (the 5-axis simulation, its error within a tenth of `tolerance`: a flat end mill's
    instances as far apart as each move's lead tilt allows, sim_path)."""
    design = mesh_heights(mesh, grid)
    floor = float(mesh.bounds[0][2]) - 1.0
    stock = np.where(np.isnan(design), floor, design + stock_above)
    if not path.is_five_axis():
        return design, simulate(path, cutter, grid, stock).heights
    if cutter.kind == "flat":
        dense = sim_path(path, cutter.radius, tolerance)
        return design, simulate(dense, cutter, grid, stock, max_step=MAX_STEP).heights
    return design, simulate(path, cutter, grid, stock, max_step=sub_step(cutter, tolerance, max_tilt(path))).heights


def in_strips(grid: Grid, strips: Sequence[np.ndarray], grow: float) -> np.ndarray:
    """(ny, nx) cells whose centre lies in one of the strips' XY corners ((4, 2) each) grown by `grow`."""
    if not len(strips):
        return np.zeros((grid.ny, grid.nx), dtype=bool)
    shape = polygons.offset(polygons.union([np.asarray(c, dtype=float) for c in strips]), grow)
    return polygons.grid_inside(shape, grid.xs(), grid.ys()) if shape else np.zeros((grid.ny, grid.nx), dtype=bool)


def left_above(mesh: TriMesh, cutter: Cutter, path: Toolpath, tolerance: float, *, strips: Sequence[np.ndarray] = (),
               stock_above: float = STOCK_ABOVE, cell: float = MAX_CELL) -> Left:
    """What the 5-axis `path` of `cutter` leaves more than `tolerance` above the mesh (along its normal: the
    vertical height x cos(slope)), from `stock_above` over it (at least 3 times the tolerance, so that an uncut
    cell counts; the simulation on cells of `cell` mm), and which of it lies outside the plan's `strips`
    (finish.strip_corners) grown by the cutter's radius."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"clean-up tolerance must be a length > 0 mm, got {tolerance!r}")
    grid = cleanup_grid(mesh, cell)
    stock = max(stock_above, 3.0 * tolerance)        # an uncut cell stands above the tolerance (up to 70 deg)
    design, left = material_left(mesh, cutter, path, grid, tolerance, stock)
    gy, gx = gradient(design, grid.cell)             # the tolerance is along the normal, as the plan's
    cos = 1.0 / np.sqrt(1.0 + gx * gx + gy * gy)
    above = without_specks(np.isfinite(design) & ((left - design) * cos > tolerance))
    return Left(grid, design, left, above, above & ~in_strips(grid, strips, cutter.radius), tolerance, cos)


def cleanup(mesh: TriMesh, cutter: Cutter, path: Toolpath, tool: Cutter, tolerance: float, *,
            feed_angle_deg: float = 0.0, strips: Sequence[np.ndarray] = (), stock_above: float = STOCK_ABOVE,
            cell: Optional[float] = None, assembly: Any = None, holder_notes: Optional[list] = None
            ) -> tuple[list[CutSegment], CleanupNote]:
    """The ball `tool`'s 3-axis clean-up of what the 5-axis `path` of `cutter` leaves more than `tolerance` above
    the mesh (module doc): its cut segments (tips, vertical axis; passes along the feed angle) and the note.
    `strips`: the plan's strip corners (finish.strip_corners), to say how much was left outside them.
    `assembly`: the ball's whole tool (the holder guard keeps its shank and holder clear). Cells of a ball radius
    / 8, at most MAX_CELL."""
    check_tool(tool)
    c = min(MAX_CELL, tool.radius / 8.0) if cell is None else cell
    found = left_above(mesh, cutter, path, tolerance, strips=strips, stock_above=stock_above, cell=c)
    if not found.above.any():
        return [], CleanupNote(tool.describe(), tolerance, c, 0.0, 0.0, 0.0, np.zeros((0, 3)), 0)
    grid, design, left = found.grid, found.design, found.heights
    # the rest judged vertically (as the rest machinery does: more than along the normal), and the cells beside
    # it: a sliver along an edge thinner than a cell is read above the tolerance in some cells only (on the
    # benchmark's 0.2 mm cells the ball left 105 cells of it, judged along the normal alone)
    vertical = without_specks(np.isfinite(design) & (left - design > tolerance))
    above = _grown(found.above | vertical) & np.isfinite(design)
    area = rest_area(np.where(above | ~np.isfinite(design), left, design), design,
                     _envelope(mesh, tool, grid, above, left), grid, tolerance, tool.radius)
    segments: list[CutSegment] = []
    if not area.empty:
        params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, angle_deg=feed_angle_deg,
                               stepover=ball_stepover(tool.radius, tolerance), sample_step=min(0.5, tool.radius / 4.0),
                               cusp_check="off")
        params.rest, params.assembly, params.holder_notes = area.stock(left), assembly, holder_notes
        segments = raster_drop.compute(mesh, tool, params).segments
    after = _after(grid, left, tool, segments)
    still = np.isfinite(design) & ((after - design) * found.cos > tolerance) & above
    pts = np.column_stack([grid.centres()[still.ravel()], design[still]]) if still.any() else np.zeros((0, 3))
    return segments, CleanupNote(tool.describe(), tolerance, c, found.area, found.outside_area,
                                 float(still.sum() * grid.cell_area), pts, int(sum(len(s) for s in segments)))


def _grown(mask: np.ndarray) -> np.ndarray:
    from scipy import ndimage

    return ndimage.binary_dilation(mask, structure=np.ones((3, 3), dtype=bool))


def _envelope(mesh: TriMesh, tool: Cutter, grid: Grid, mask: np.ndarray, left: np.ndarray) -> np.ndarray:
    """The ball's envelope (core.footprint.rest.tool_envelope) on the boxes around the mask's patches (grown by
    its radius and two cells), `left` elsewhere (nothing reached): the finish's leftovers lie scattered along the
    boundaries, and the envelope over the whole model costs a drop per cell."""
    from scipy import ndimage

    out = left.copy()
    n = int(math.ceil(tool.radius / grid.cell)) + 2
    near = ndimage.binary_dilation(mask, structure=np.ones((3, 3), dtype=bool), iterations=n)
    labels, _ = ndimage.label(near)
    for rows, cols in ndimage.find_objects(labels):
        sub = Grid(grid.x0 + cols.start * grid.cell, grid.y0 + rows.start * grid.cell, grid.cell,
                   cols.stop - cols.start, rows.stop - rows.start)
        out[rows, cols] = tool_envelope(mesh, tool, sub)
    return out


def _after(grid: Grid, left: np.ndarray, tool: Cutter, segments: list[CutSegment]) -> np.ndarray:
    """What is left after the clean-up's segments (linked straight up and down, simulated on `left`)."""
    if not segments:
        return left
    top = float(np.nanmax(left)) + tool.diameter + 1.0
    return simulate(link(segments, LinkPolicy(top, top)), tool, grid, left.copy()).heights
