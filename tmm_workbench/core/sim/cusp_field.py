"""The simulated cusp of a 3-axis raster, measured the same way whatever placed its passes.

The path and a dense raster of the same tool (passes one cell apart: its own cusp, cell^2 / 8R for a ball, is
negligible against the tolerance) are cut into the stock simulation. The dense raster leaves the reachable
envelope E: the surface the tool can bring out at all. The cusp of a cell is (H - E) cos(slope), H the path's
simulated height, i.e. along the normal; it is measured where the slope is at most the slope limit (walls are
waterline's) and the envelope comes within the tolerance of the design along the normal (elsewhere the tool cannot
reach the model: a concave corner narrower than the tool; those cells are `unreachable`, not cusps).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.geometry.rect import Rect
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.sim.compare import slope_deg
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

SLOPE_LIMIT_DEG = 75.0
STOCK_ABOVE_MM = 5.0  # the box stock's top above the model: every cut starts in material
# The dense raster's envelope, made by its caller (the strategy: core.strategies.surface.measure.dense_raster):
# (grid, surface, stock top, progress) -> the (ny, nx) heights the raster leaves in a box stock at the stock top
DenseRaster = Callable[[Grid, DropSurface, float, Optional[Progress]], np.ndarray]


@dataclass
class CuspField:
    grid: Grid
    design: np.ndarray       # (ny, nx) the model's heights, NaN off the model
    envelope: np.ndarray     # (ny, nx) what the dense raster leaves
    cos: np.ndarray          # (ny, nx) cos of the envelope's slope (vertical -> along the normal)
    measured: np.ndarray     # (ny, nx) bool: cells where the cusp is measured
    unreachable: np.ndarray  # (ny, nx) bool: on the model, not steep, but out of the tool's reach
    steep: np.ndarray        # (ny, nx) bool: on the model, steeper than the slope limit
    stock_top: float
    tolerance: float
    normal_xy: np.ndarray    # (ny, nx, 2) the envelope's unit normal, its XY part (where a tool touches it from)

    def contact_offset(self, cutter: Cutter) -> np.ndarray:
        """(ny, nx, 2) from each cell (a contact point) to the tool tip touching there, in XY: a torus's (ball:
        R n_xy; flat: R along n_xy's direction; bull: both parts), so that cells are matched to the passes that
        cut them (on a 35 deg slope a ball D6 touches 1.7 mm uphill of its tip)."""
        rc = min(cutter.corner_radius, cutter.radius)
        norm = np.linalg.norm(self.normal_xy, axis=2, keepdims=True)
        unit = np.divide(self.normal_xy, norm, out=np.zeros_like(self.normal_xy), where=norm > 1e-12)
        return (cutter.radius - rc) * unit + rc * self.normal_xy

    def stock(self) -> np.ndarray:
        return box_heights(self.grid, self.stock_top)

    def cut(self, path: Toolpath, cutter: Cutter, heights: Optional[np.ndarray] = None) -> np.ndarray:
        """The stock (`heights`, default the box) after `path` is cut into it."""
        return simulate(path, cutter, self.grid, self.stock() if heights is None else heights).heights

    def cusp(self, heights: np.ndarray) -> np.ndarray:
        """(ny, nx) cusp along the normal of simulated `heights`, NaN where not measured."""
        return np.where(self.measured, (heights - self.envelope) * self.cos, np.nan)

    def ridge_cusp(self, heights: np.ndarray) -> np.ndarray:
        """cusp() with each cell that is a local maximum along X or Y raised to the crest between its neighbours:
        a cusp's ridge is where two tool surfaces cross, a V along any line across it (slopes +-k), which cells
        sample up to k x cell / 2 below its crest; through f-, f0, f+ with f0 the largest, the crest of the
        symmetric V is f0 + |f+ - f-| / 2 (the verification pass decides with it, so that a finer grid does not
        find more)."""
        c = self.cusp(heights)
        filled = np.nan_to_num(c, nan=-np.inf)
        out = c.copy()
        for axis in (0, 1):
            lo = np.roll(filled, 1, axis=axis)
            hi = np.roll(filled, -1, axis=axis)
            edge = [slice(None)] * 2
            for index in (0, -1):  # no neighbour across the grid's edges
                edge[axis] = index
                lo[tuple(edge)] = hi[tuple(edge)] = -np.inf
            peak = np.isfinite(lo) & np.isfinite(hi) & (filled >= lo) & (filled >= hi)
            with np.errstate(invalid="ignore"):  # -inf - -inf off the peaks, not used
                crest = np.where(peak, filled + 0.5 * np.abs(np.where(peak, hi - lo, 0.0)), -np.inf)
            out = np.where(np.isfinite(out), np.maximum(out, crest), out)
        return out

    def max_cusp(self, heights: np.ndarray) -> float:
        c = self.cusp(heights)
        return float(np.nanmax(c)) if self.measured.any() else 0.0

    @property
    def share(self) -> float:
        """The share of the grid's cells measured."""
        return float(self.measured.mean())


def measure_grid_size(boundary: Rect, cutter: Cutter, cell: float) -> tuple[int, int]:
    """measure_grid's cells across and along, before any is allocated."""
    r = cutter.radius
    return (max(1, math.ceil((boundary[2] - boundary[0] - 2 * r) / cell - 1e-9)),
            max(1, math.ceil((boundary[3] - boundary[1] - 2 * r) / cell - 1e-9)))


def measure_grid(boundary: Rect, cutter: Cutter, cell: float) -> Grid:
    """The cells measured for a raster over `boundary`: inside it, clear of its edges by the tool radius (the
    passes' ends and the outermost passes' far sides are not the spacing's)."""
    r = cutter.radius
    return Grid.covering(boundary[0] + r, boundary[1] + r, boundary[2] - r, boundary[3] - r, cell)


def cusp_field(mesh: TriMesh, cutter: Cutter, boundary: Rect, tolerance: float, cell: float,
               slope_limit_deg: float = SLOPE_LIMIT_DEG, stock_to_leave: float = 0.0,
               surface: Optional[DropSurface] = None, grid: Optional[Grid] = None,
               progress: Optional[Progress] = None, fast_envelope: bool = False,
               dense: Optional[DenseRaster] = None) -> CuspField:
    """The field for rasters over `boundary` (xmin, ymin, xmax, ymax) with `cutter`; `cell` is the simulation's
    cell and the dense raster's step-over. The envelope is `dense`'s (the strategy's dense raster, made by the
    caller: core.strategies.surface.measure.dense_raster) or, with `fast_envelope`, grid_envelope's (the dense
    raster as one batch drop on its grid of points, sampled `cell` apart, no chord thinning or refinement, cut by
    the kernel from arrays: several times faster). With `stock_to_leave` the dense raster leaves it too, and a
    cell is reachable when the envelope comes within tolerance + stock_to_leave of the design."""
    if not fast_envelope and dense is None:
        raise TmmError("the cusp field needs the dense raster's envelope (dense) or fast_envelope")
    grid = grid or measure_grid(boundary, cutter, cell)
    surface = surface or DropSurface(mesh)
    design = mesh_heights(mesh, grid, surface)
    top = float(mesh.bounds[1][2]) + stock_to_leave
    stock_top = top + STOCK_ABOVE_MM
    if fast_envelope:
        envelope = grid_envelope(mesh, cutter, boundary, grid, stock_to_leave, surface, stock_top, progress)
    else:
        envelope = dense(grid, surface, stock_top, progress)
    return field_of(grid, design, envelope, tolerance, stock_to_leave, slope_limit_deg, stock_top)


def field_of(grid: Grid, design: np.ndarray, envelope: np.ndarray, tolerance: float, stock_to_leave: float,
             slope_limit_deg: float, stock_top: float) -> CuspField:
    """The field from the design's and the envelope's heights on `grid`: slopes, normals and the masks."""
    slope = slope_deg(envelope, grid.cell)
    gy, gx = np.gradient(envelope, grid.cell)
    normal_xy = -np.stack([gx, gy], axis=2) / np.sqrt(1.0 + gx * gx + gy * gy)[:, :, None]
    cos = np.cos(np.radians(slope))
    on_model = np.isfinite(design)
    steep = on_model & (slope > slope_limit_deg)
    near = (envelope - np.where(on_model, design, -np.inf)) * cos <= tolerance + stock_to_leave
    measured = on_model & ~steep & near
    return CuspField(grid, design, envelope, cos, measured, on_model & ~steep & ~near, steep, stock_top, tolerance,
                     normal_xy)


def grid_envelope(mesh: TriMesh, cutter: Cutter, boundary: Rect, grid: Grid, stock_to_leave: float,
                  surface: DropSurface, stock_top: float, progress: Optional[Progress] = None,
                  cells: Optional[np.ndarray] = None) -> np.ndarray:
    """The dense raster's envelope without the strategy: its passes (along X, a cell apart over `boundary` grown
    by the tool radius across, as the strategy's dense_params) dropped in one batch on points a cell apart, on the
    model's floor at least, and cut in serpentine order from arrays. The straight moves between points a cell apart
    pass below the exact CL path by its sag on convex ground (cell^2 / 8 rho: about a micrometre): the envelope is,
    if anything, lower, and the cusp over it larger. `cells` ((ny, nx) bool): only these cells' envelope is wanted;
    only the points within the tool's reach of them are dropped and cut (runs of a pass, the tool lifted above
    the stock between runs); elsewhere the result is the stock top."""
    from tmm_workbench.core.kernel import native

    r, cell, s = cutter.radius, grid.cell, stock_to_leave
    xs = np.linspace(boundary[0], boundary[2], max(2, math.ceil((boundary[2] - boundary[0]) / cell - 1e-9) + 1))
    ys = np.linspace(boundary[1] - r, boundary[3] + r,
                     max(2, math.ceil((boundary[3] - boundary[1] + 2 * r) / cell - 1e-9) + 1))
    gx = np.tile(xs, (len(ys), 1))
    gx[1::2] = gx[1::2, ::-1]                                # serpentine: every other pass backwards
    gy = np.repeat(ys, len(xs)).reshape(len(ys), len(xs))
    xy = np.column_stack([gx.ravel(), gy.ravel()])
    zmap = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
    zmap.heights[:] = box_heights(grid, stock_top)
    keep = np.arange(len(xy)) if cells is None else np.flatnonzero(_within_reach(grid, cells, xy, cutter))
    if len(keep) == 0:
        return np.array(zmap.heights)
    floor = float(mesh.bounds[0][2])
    z = np.maximum(surface.drop(cutter.offset(s), xy[keep], floor - s, progress) + s, floor)
    tips = np.column_stack([xy[keep], z])
    starts = np.flatnonzero(np.diff(keep, prepend=-2) != 1)   # runs of consecutive points in the serpentine
    ends = np.append(starts[1:], len(keep)) - 1
    lifts = np.vstack([tips[ends], tips[starts]])
    lifts[:, 2] = stock_top + 1.0                              # above the stock between runs: cuts nothing
    tips = np.ascontiguousarray(np.insert(tips, np.concatenate([ends + 1, starts]), lifts, axis=0))
    kinds = np.zeros(len(tips) - 1, dtype=np.uint8)          # every move cuts (CUT)
    cancel.native_call(native.cut_3axis, zmap, cutter.native, tips, kinds, 1e-3, 0)
    return np.array(zmap.heights)


def _within_reach(grid: Grid, cells: np.ndarray, xy: np.ndarray, cutter: Cutter) -> np.ndarray:
    """(n,) bool: the points within the tool's reach (and a cell) of a wanted cell. Each point is read at its
    nearest grid cell (projecting onto the grid's box brings no point farther from a cell) in the wanted cells
    grown by that reach."""
    from scipy.ndimage import distance_transform_edt

    grown = distance_transform_edt(~cells) <= cutter.native.max_radius / grid.cell + 1.5
    i = np.clip(np.floor((xy[:, 0] - grid.x0) / grid.cell).astype(int), 0, grid.nx - 1)
    j = np.clip(np.floor((xy[:, 1] - grid.y0) / grid.cell).astype(int), 0, grid.ny - 1)
    return grown[j, i]


def measure(field: CuspField, path: Toolpath, cutter: Cutter) -> tuple[float, float]:
    """The largest cusp of `path` and the share of cells measured."""
    return field.max_cusp(field.cut(path, cutter)), field.share
