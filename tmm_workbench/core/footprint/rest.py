"""Rest machining's region: where a smaller tool can take off more than the tolerance of what is left.

What is left is the stock as the Job's earlier ops leave it (the simulation's heights) or as a reference tool
would leave it (its envelope over the model, below the stock's top). What the rest tool can reach is its own
envelope: the lowest its surface comes over each cell when its tip is dropped at every cell centre (the
drop-cutter CL points of a raster as fine as the grid, swept by the kernel's z-map cut). Cells where what is left
stands more than the tolerance above that envelope are the rest; the tool centre goes where it cuts them, the
cells grown by the tool radius (Clipper's offset of the cells' union). Cells still above the tolerance after the
rest tool are reported as out of its reach: the smallest tool's limit, for a still smaller one.

Seed 000 (section 3.6) finishes with clean-up strips of the cells the finishing tool could not reach; seed 003
(section 4.5) with a pencil after a large radiused cutter. Both leave the region implicit; the reach test here is
the same criterion made explicit per cell, with the tolerance the simulation judges the finish by.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import native
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import CUT, RAPID
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
MIN_CELLS = 3          # a clean-up strip's patch of fewer cells is the grid's noise (core.footprint.cleanup)
LEAST_CUT = 0.2        # of the tolerance: a rest cell is one the tool lowers by at least this much
MAX_RUNS = 400_000     # row runs of rest cells turned into rectangles: a finer grid is refused above this


@dataclass
class RestStock:
    """What is left to machine: heights on a grid (-inf: nothing there), and how deep below them the tool must
    come to count as cutting it (core.strategies.rest_filter)."""
    grid: Grid
    heights: np.ndarray
    tolerance: float
    # the design's heights on the grid (NaN: none) and the rest tolerance they are judged by: the steep part of
    # the rest (core.strategies.rest_steep) is told by the design's slope; None: not split
    design: Optional[np.ndarray] = None
    within: float = 0.0
    envelope: Optional[np.ndarray] = None   # the rest tool's envelope (what it can reach)

    def __post_init__(self) -> None:
        if np.shape(self.heights) != (self.grid.ny, self.grid.nx):
            raise TmmError(f"rest heights have shape {np.shape(self.heights)}, the grid {self.grid.ny} x "
                           f"{self.grid.nx}")
        if not (math.isfinite(self.tolerance) and self.tolerance > 0):
            raise TmmError(f"rest tolerance must be a length > 0 mm, got {self.tolerance!r}")


@dataclass
class RestArea:
    grid: Grid
    mask: np.ndarray            # (ny, nx) cells above the tolerance that the rest tool lowers
    region: Shape               # where its CL points go: those cells grown by the tool radius
    tolerance: float
    area: float                 # mm^2 of rest cells
    volume_before: float        # mm^3 above the design before the rest tool
    volume_after: float         # and after it (what it cannot reach)
    out_of_reach: float         # mm^2 still above the tolerance after it
    design: Optional[np.ndarray] = None   # the design's heights (NaN: none)
    envelope: Optional[np.ndarray] = None   # the tool's envelope (tool_envelope)

    @property
    def empty(self) -> bool:
        return not self.mask.any()

    def summary(self) -> str:
        if self.empty:
            return (f"nothing left for this tool: no cell stands more than {self.tolerance:g} mm above what it "
                    f"can reach")
        text = (f"rest {self.area:.0f} mm2 in {len(polygons.regions(self.region))} region(s): "
                f"{self.volume_before:.1f} mm3 above the design before, {self.volume_after:.1f} mm3 after")
        if self.out_of_reach > 0:
            text += f"; {self.out_of_reach:.0f} mm2 stay more than {self.tolerance:g} mm above it (out of its reach)"
        return text

    def stock(self, left: np.ndarray) -> "RestStock":
        """What the rest filter cuts against: `left` on the rest cells only, a cut being LEAST_CUT of the
        tolerance."""
        return RestStock(self.grid, np.where(self.mask, left, -np.inf), LEAST_CUT * self.tolerance, self.design,
                         self.tolerance, self.envelope)

    def cells_xy(self) -> np.ndarray:
        """(n, 2) centres of the rest cells (what the view marks)."""
        return self.grid.centres()[self.mask.ravel()]


def tool_envelope(mesh: TriMesh, cutter: Cutter, grid: Grid, surface: Optional[DropSurface] = None,
                  progress: Optional[Progress] = None, tips: Optional[np.ndarray] = None) -> np.ndarray:
    """(ny, nx) the lowest the tool's surface comes over each cell centre when it is dropped onto the mesh at
    every cell centre (each CL point plunged into by the z-map cut); the mesh's floor where it touches nothing.
    Between the grid's positions a tool could go a cusp lower (cell^2 / 8 r for a ball of radius r): the
    envelope errs on the side of material left. `tips`: (ny, nx) tip heights to plunge to in place of the
    cutter's drop (the whole tool's: its shank or holder may hold it up)."""
    surface = surface or DropSurface(mesh)
    floor = float(mesh.vertices[:, 2].min())
    xs, ys = grid.xs(), grid.ys()
    X, Y = np.meshgrid(xs, ys)
    part = None if progress is None else (lambda f: progress(0.5 * f))
    if tips is None:
        z = surface.drop(cutter, np.column_stack([X.ravel(), Y.ravel()]), floor, part).reshape(grid.ny, grid.nx)
    else:
        z = np.asarray(tips, dtype=float).reshape(grid.ny, grid.nx)
    reach = float(cutter.native.height(np.array([cutter.native.max_radius]))[0])
    top = float(z.max()) + reach + 1.0   # above the tool everywhere
    # each CL point plunged into on its own, straight down from `top` and back up: a straight move between two
    # CL points would cut below both where the surface bends between them (0.1 mm at a wall's rim was measured)
    cl = np.column_stack([X.ravel(), Y.ravel(), z.ravel()])
    above = cl.copy()
    above[:, 2] = top
    tips = np.ascontiguousarray(np.stack([above, cl, above], axis=1).reshape(-1, 3))
    kinds = np.tile(np.array([CUT, RAPID, RAPID], dtype=np.uint8), len(cl))[:len(tips) - 1]
    zmap = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, top)
    zmap.heights[:] = top
    part = None if progress is None else (lambda f: progress(0.5 + 0.5 * f))
    try:
        native.cut_3axis(zmap, cutter.native, tips, kinds, 1e-3, 0, part)
    except native.Cancelled as exc:
        raise Cancelled("rest region cancelled") from exc
    return np.minimum(np.array(zmap.heights), top)


def rest_area(left: np.ndarray, design: np.ndarray, envelope: np.ndarray, grid: Grid, tolerance: float,
              radius: float) -> RestArea:
    """The rest of `left` ((ny, nx) heights on `grid`) for a tool whose envelope is `envelope`, over the design
    heights (NaN where there is no design: never rest): the cells more than the tolerance above the design that
    the tool lowers by LEAST_CUT of it or more. The region bounds the tool centre: the rest cells grown by
    `radius`."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"rest tolerance must be a length > 0 mm, got {tolerance!r}")
    for name, a in (("left", left), ("design", design), ("envelope", envelope)):
        if np.shape(a) != (grid.ny, grid.nx):
            raise TmmError(f"rest {name} heights have shape {np.shape(a)}, the grid {grid.ny} x {grid.nx}")
    has_design = np.isfinite(design)
    # above the tolerance, and the tool takes some of it off (to within the tolerance where it reaches)
    # every such cell, a single one too: a large tool's raster on a steep slope leaves its cusps above the
    # tolerance in cells one or two wide along its passes
    # (and every cell it brings within the tolerance, however little it takes off: a cell 0.0105 mm above the
    # design with the envelope at 0.009 is rest too)
    mask = has_design & (left - design > tolerance) & ((left - envelope > LEAST_CUT * tolerance)
                                                        | (envelope - design <= tolerance))
    after = np.minimum(left, envelope)
    above = np.where(has_design, np.clip(left - design, 0, None), 0.0)
    above_after = np.where(has_design, np.clip(after - design, 0, None), 0.0)
    a = grid.cell_area
    region = mask_region(mask, grid, radius) if mask.any() else []
    return RestArea(grid, mask, region, tolerance, float(mask.sum() * a), float(above.sum() * a),
                    float(above_after.sum() * a), float(np.sum(above_after > tolerance) * a), design,
                    envelope)


def without_specks(mask: np.ndarray) -> np.ndarray:
    """The mask without 8-connected patches of fewer than MIN_CELLS cells."""
    from scipy import ndimage

    labels, n = ndimage.label(mask, structure=np.ones((3, 3), dtype=bool))
    if not n:
        return mask
    sizes = np.bincount(labels.ravel())
    keep = sizes >= MIN_CELLS
    keep[0] = False
    return keep[labels]


def mask_region(mask: np.ndarray, grid: Grid, grow: float) -> Shape:
    """The union of the mask's cells (as squares, a row's run of cells one rectangle) grown by `grow` mm."""
    padded = np.pad(mask.astype(np.int8), ((0, 0), (1, 1)))
    edges = np.diff(padded, axis=1)
    rows, starts = np.nonzero(edges == 1)
    _, ends = np.nonzero(edges == -1)   # row-major order pairs each start with its end
    if len(starts) > MAX_RUNS:
        raise TmmError(f"the rest area is in {len(starts)} pieces of rows, more than {MAX_RUNS}: make the "
                       f"simulation's cells larger or the tolerance larger")
    c, x0, y0 = grid.cell, grid.x0, grid.y0
    rects = [polygons.rectangle(x0 + s * c, y0 + j * c, x0 + e * c, y0 + (j + 1) * c)
             for j, s, e in zip(rows, starts, ends)]
    shape = polygons.union(rects)
    return polygons.offset(shape, grow) if grow > 0 else shape
