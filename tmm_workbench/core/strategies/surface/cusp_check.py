"""What a cusp mode left: its pass set measured as the verification pass measures it, no passes added.

The cusp modes (constant cusp, adaptive, 3D offset) place their passes by rules that sample the surface (sections,
a field's first-order marching, secants); where the sampling misses detail a few cells stay above the cusp height.
The check cuts the pass set into the stock simulation on the verification's cells (core.strategies.surface.measure:
an eighth of the planar step, the dense raster sampled a cell apart) and reports how many measured cells exceed the
cusp (with the crest between cells, CuspField.ridge_cusp, as the verification decides), the largest, and where:
the bounding box and up to PLACES places (the worst cell of each group of exceeding cells within a tool diameter of
each other), so that the op can say it and suggest VerifyCusp. With VerifyCusp on, the verification's own final
measurement gives the same report (no second measurement). CheckCusp Auto measures every region at a bounded cost:
one with more than AUTO_CELLS of the verification's cells on coarser cells (check_cell), saying how far a crest
may read low there (reads_low).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from tmm_workbench.core import cancel, polygons
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.report_text import within
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.compare import slope_deg
from tmm_workbench.core.sim.cusp_field import (STOCK_ABOVE_MM, CuspField, field_of, grid_envelope, measure_grid,
                                               measure_grid_size)
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies.surface.measure import estimate_work, measure_cell
from tmm_workbench.core.strategies.surface.params import STEPOVER
from tmm_workbench.core.tools.cutter import Cutter

PLACES = 5
AUTO_CELLS = 250_000   # CheckCusp Auto measures at most this many cells (30 x 30 mm of the verification's cells for a
                       # ball D6 at 0.01 mm: a few seconds); a larger region on coarser cells (check_cell)


@dataclass
class CuspCheck:
    tolerance: float
    cell: float
    measured: int = 0                 # cells measured
    exceeding: int = 0                # of them, with a cusp (crests included) above the tolerance
    max_cusp: float = 0.0             # mm, the largest (crests included)
    box: Optional[tuple] = None       # (xmin, ymin, xmax, ymax) of the exceeding cells
    places: list = field(default_factory=list)   # [(x, y, cusp mm, cells)] the worst of each group, worst first
    unreachable: int = 0
    steep: int = 0
    seconds: float = 0.0
    verified: bool = False            # measured after the verification's partial passes
    skipped: str = ""                 # why it did not run (its work above the limits)
    reads_low: float = 0.0            # mm a cusp may read under its crest on level ground (reads_low), on cells
                                      # coarser than the verification's (0 on those)

    @property
    def within(self) -> bool:
        return self.exceeding == 0 and not self.skipped

    def summary(self) -> str:
        if self.skipped:
            return f"cusp check {self.tolerance:g} mm not run: {self.skipped}"
        coarse = (f"; CheckCusp Auto on this large region: a crest may read up to {self.reads_low:.4f} mm low "
                  "(level ground; / cos^2 of a slope)" if self.reads_low else "")
        if self.within:
            return (f"cusp check {self.tolerance:g} mm: held on all {self.measured} measured cells "
                    f"(largest {self.max_cusp:.4f} mm, {self.cell:.3g} mm cells{coarse})")
        where = "; ".join(f"({x:.1f}, {y:.1f}) {c:.4f} mm" for x, y, c, _ in self.places)
        return (f"cusp check {self.tolerance:g} mm: {self.exceeding} of {self.measured} measured {self.cell:.3g} mm "
                f"cells above it, up to {self.max_cusp:.4f} mm, {within(np.reshape(self.box, (2, 2)))}; "
                f"worst at {where}" + (" (after VerifyCusp's rounds)" if self.verified else
                                       f". VerifyCusp adds partial passes there{coarse}"))

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def from_field(fld: CuspField, cusp: np.ndarray, join: float, seconds: float = 0.0) -> CuspCheck:
    """The check of the measured `cusp` (ridge_cusp of a cut) in `fld` (the verification's); exceeding cells closer
    than `join` mm are one place."""
    out = _report(fld.grid, cusp, fld.measured, fld.unreachable, fld.steep, fld.tolerance, join, seconds)
    out.verified = True
    return out


def _places(xy: np.ndarray, v: np.ndarray, join: float) -> list:
    """The worst cell of each group (cells closer than `join` joined), the worst groups first, PLACES at most."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(xy).query_pairs(join, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(xy), len(xy)))
    _, label = connected_components(graph, directed=False)
    order = np.argsort(-v)
    first = np.unique(label[order], return_index=True)[1]   # each group's worst, by its rank in `order`
    worst = order[np.sort(first)][:PLACES]
    counts = np.bincount(label)
    return [(float(xy[i, 0]), float(xy[i, 1]), float(v[i]), int(counts[label[i]])) for i in worst]


_SCREEN = 0.9      # cells whose crest over the design is above this share of the tolerance get the envelope
_AROUND = 2        # cells around those (a crest reads its neighbours' cusps, and their slopes theirs)


def check_segments(mesh: TriMesh, cutter: Cutter, segments: list[CutSegment], params: Any,
                   surface: Optional[DropSurface] = None, progress: Optional[Progress] = None) -> CuspCheck:
    """raster_drop's pass set (`params`: its SurfaceParams) measured against params.cusp (see the module).

    The verification's measure, without its envelope everywhere: the envelope E lies between the design D (the
    tool never enters it) and the path's heights H, within the dense raster's own cusp of D where the tool reaches
    (cell^2 / 8R: 1.5 % of the tolerance for a ball); so the cusp (H - E) cos(slope) is at most H - D, and the
    crest read on H - D (CuspField.ridge_cusp's rule) screens the cells: E is computed (cusp_field.grid_envelope)
    only for those above _SCREEN x the tolerance and the _AROUND cells around them (their slopes and crests read
    their neighbours), and the cusp read on the screened cells; the rest hold."""
    from scipy.ndimage import binary_dilation

    t0 = time.perf_counter()
    surface = surface or DropSurface(mesh)
    tol, s = params.cusp, params.stock_to_leave
    grid = measure_grid(params.boundary, cutter, check_cell(params, cutter))
    design = mesh_heights(mesh, grid, surface)
    stock_top = float(mesh.bounds[1][2]) + s + STOCK_ABOVE_MM
    cancel.poll()
    path = link(segments, LinkPolicy(stock_top + 1.0, stock_top + 5.0))
    heights = simulate(path, cutter, grid, box_heights(grid, stock_top), progress=cancel.asker()).heights
    cancel.poll()
    on_model = np.isfinite(design) & _in_region(params, grid, cutter.radius)
    over = CuspField(grid, design, design + s, np.ones(design.shape), on_model, on_model & False, on_model & False,
                     stock_top, tol, np.zeros(design.shape + (2,))).ridge_cusp(heights)
    screen = np.nan_to_num(over, nan=0.0) > _SCREEN * tol
    wanted = binary_dilation(screen, iterations=_AROUND) if screen.any() else screen
    cusp = np.full(design.shape, np.nan)
    flat = slope_deg(design, grid.cell)
    measured, steep = on_model & (flat <= params.max_slope_deg), on_model & (flat > params.max_slope_deg)
    unreachable = np.zeros(design.shape, dtype=bool)
    if screen.any():
        env = grid_envelope(mesh, cutter, params.boundary, grid, s, surface, stock_top, cells=wanted)
        fld = field_of(grid, design, np.where(wanted, env, heights), tol, s, params.max_slope_deg, stock_top)
        cusp[screen] = fld.ridge_cusp(heights)[screen]
        for mine, theirs in ((measured, fld.measured), (steep, fld.steep), (unreachable, fld.unreachable)):
            mine[screen] = theirs[screen]
    out = _report(grid, cusp, measured, unreachable, steep, tol, cutter.diameter, time.perf_counter() - t0)
    if grid.cell > measure_cell(cutter, tol) * (1 + 1e-9):   # CheckCusp Auto's coarser cells: say what they miss
        out.reads_low = reads_low(cutter, grid.cell)
    return out


def _in_region(params: Any, grid: Grid, reach: float) -> np.ndarray:
    """The cells the passes are for: in the region, clear of its edge by the tool radius (as the box's cells are
    clear of the box's edges: measure_grid); everywhere for the box."""
    if params.region is None:
        return np.ones((grid.ny, grid.nx), dtype=bool)
    inner = polygons.offset(params.region, -reach)
    if not inner:
        return np.zeros((grid.ny, grid.nx), dtype=bool)
    return polygons.grid_inside(inner, grid.xs(), grid.ys())


def _report(grid: Grid, cusp: np.ndarray, measured: np.ndarray, unreachable: np.ndarray, steep: np.ndarray,
            tol: float, join: float, seconds: float) -> CuspCheck:
    values = np.nan_to_num(cusp, nan=-np.inf)
    bad = values > tol
    out = CuspCheck(tol, grid.cell, int(measured.sum()), int(bad.sum()), max(0.0, float(values.max())),
                    unreachable=int(unreachable.sum()), steep=int(steep.sum()), seconds=seconds)
    if bad.any():
        xy = grid.centres()[bad.ravel()]
        out.box = (float(xy[:, 0].min()), float(xy[:, 1].min()), float(xy[:, 0].max()), float(xy[:, 1].max()))
        out.places = _places(xy, values.ravel()[bad.ravel()], join)
    return out


def cost_points(boundary: Any, cutter: Cutter, cusp: float, cell: Optional[float] = None) -> float:
    """The check's CL points at most on `cell` mm cells (the verification's by default; measure.estimate_work:
    the dense raster everywhere and the design), refused above the limits (WorkLimitError)."""
    return estimate_work(boundary, cutter, cusp, cell or measure_cell(cutter, cusp), "cusp check")


def applies(params: Any) -> bool:
    """raster_drop's params: a cusp mode with the check not off (STEPOVER asks for no cusp height)."""
    return params.cusp_check != "off" and params.stepover_mode != STEPOVER


def cells(boundary: Any, cutter: Cutter, cusp: float, cell: Optional[float] = None) -> int:
    """The cells measured over `boundary` on `cell` mm cells (the verification's by default), before any is
    allocated."""
    nx, ny = measure_grid_size(boundary, cutter, cell or measure_cell(cutter, cusp))
    return nx * ny


def check_cell(params: Any, cutter: Cutter) -> float:
    """The check's cell: the verification's (measure.measure_cell); with CheckCusp Auto, on a region of more
    than AUTO_CELLS of them, one about sqrt(their count / AUTO_CELLS) times coarser, with at most AUTO_CELLS (the
    check's work then about that of a 30 x 30 mm region at the verification's cells, whatever the region's size:
    the cells, the path's cut into them and the dense raster's points all scale with their count)."""
    cell = measure_cell(cutter, params.cusp)
    if params.cusp_check == "on":
        return cell
    scale = math.sqrt(max(1.0, cells(params.boundary, cutter, params.cusp) / AUTO_CELLS))
    while cells(params.boundary, cutter, params.cusp, cell * scale) > AUTO_CELLS:
        scale *= 1.01
    return cell * scale


def reads_low(cutter: Cutter, cell: float) -> float:
    """How far under its crest a cusp may read on level ground on `cell` mm cells: a crest between two tool surfaces
    of curvature 1 / rho across it (rho the ball's or the corner's radius; the radius for a flat end) read as the V
    through three cells (CuspField.ridge_cusp) is at most 3 c^2 / (8 rho) low, and the dense raster a cell apart
    stands up to c^2 / (8 rho) above the envelope it stands for: c^2 / (2 rho) in all. On a slope t across the
    crest the tool's surface bends 1 / cos^3 t more and the cusp is read along the normal: / cos^2 t."""
    rho = cutter.corner_radius or cutter.radius
    return cell * cell / (2 * rho)


def report_params(mesh: TriMesh, cutter: Cutter, params: Any, segments: list[CutSegment],
                  surface: Optional[DropSurface], diagnostics: dict) -> Optional[CuspCheck]:
    """raster_drop's call: the check in diagnostics["cusp_check"], and appended to params.verify_notes when given
    (the op reports it); None when the verification ran (its final measurement is the report: variable_step)."""
    from tmm_workbench.core.errors import WorkLimitError

    if "cusp_check" in diagnostics:
        return None
    cell = check_cell(params, cutter)
    try:
        cost_points(params.boundary, cutter, params.cusp, cell)
        check = check_segments(mesh, cutter, segments, params, surface)
    except WorkLimitError as exc:   # the path stands; only the check is left out, and said
        check = CuspCheck(params.cusp, cell, skipped=str(exc))
    diagnostics["cusp_check"] = check.as_dict()
    if params.verify_notes is not None:
        params.verify_notes.append(check)
    return check
