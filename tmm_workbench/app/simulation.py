"""A Job's (or one op's) tool paths cut into its stock and compared with its model: the App side
of core.sim. The stock is the Job's stock solid as a height field (box, cylinder or any solid: its top on
each cell's vertical line), the design the Job's model objects tessellated finely; each active op in order
cuts the same z-map with its own tool (app.tools, the one ToolBit map) from its Path (G0/G1, 5-axis axes
in U/V/W: core.path5; the XY arcs of FreeCAD's own ops as chords within 1 um: core.arcs). Cycle time: 3-axis ops from the Path's feeds and the tool controller's rapid rates,
5-axis ops from the Tarus post's estimate (joint speeds, A and C planned)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.app import geometry, model_proxy, post_objects, tools
from tmm_workbench.core import path5
from tmm_workbench.core.arcs import arc_points
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import StockHeights, cell_tops
from tmm_workbench.core.sim import compare as compare_mod
from tmm_workbench.core.sim.cycle_time import three_axis_time
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import SimResult, simulate
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.sim.stock_collisions import combined
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter

DESIGN_DEFLECTION_MM = 0.001  # the model tessellated this close: well below the scallops compared
ARC_TOLERANCE_MM = 1e-4       # chords of G2/G3 arcs within this of the arc (lean passes: 0.1 of their band)
_PLANES = {"G17": "XY", "G18": "XZ", "G19": "YZ"}


@dataclass
class OpSimulation:
    label: str
    five_axis: bool
    moves: int
    cycle_seconds: float
    collisions: list            # [(move index, depth mm)]
    seconds: float              # simulation time
    holder: Any = None          # core.verify.holder_clearance.HolderClearance (None: no holder to check)
    stock: Any = None           # core.sim.stock_collisions.StockCollisions (None: no holder to check)


@dataclass
class JobSimulation:
    grid: Grid
    result: SimResult                   # the stock after the last op (initial: before the first)
    comparison: compare_mod.Comparison
    ops: list = field(default_factory=list)   # OpSimulation per op, in order
    design: Optional[np.ndarray] = None

    @property
    def cycle_seconds(self) -> float:
        return sum(o.cycle_seconds for o in self.ops)

    @property
    def collisions(self) -> list:
        return [(o.label, int(m), float(d)) for o in self.ops for m, d in o.collisions]

    @property
    def stock_collisions(self) -> list:
        """[(op label, StockCollisions)] of the ops whose neck, shank or holder came too close to the stock."""
        return [(o.label, o.stock) for o in self.ops if o.stock is not None and not o.stock.ok]


def job_of(obj: Any) -> Any:
    """The Job holding `obj` (or `obj` itself when it is a Job)."""
    if hasattr(obj, "Operations") and hasattr(obj, "Stock"):
        return obj
    for parent in getattr(obj, "InList", []) or []:
        found = job_of(parent)
        if found is not None:
            return found
    return None


def operations(job: Any) -> list:
    out = []

    def walk(objs: Any) -> None:
        for o in objs:
            if hasattr(o, "Group") and not hasattr(o, "Path"):
                walk(o.Group)
            elif hasattr(o, "Path") and getattr(o, "Active", True) and getattr(o, "ToolController", None):
                out.append(o)
    walk(job.Operations.Group)
    return out


def toolpath_and_feeds(op: Any) -> tuple[Toolpath, list]:
    commands = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
    moves = path5.decode_commands(commands)
    # the arc plane in force at each command (G17 XY, G18 XZ, G19 YZ: TMM's lean passes write G18/G19 arcs)
    planes, plane = [], "XY"
    for name, _ in commands:
        plane = _PLANES.get(name.upper(), plane)
        planes.append(plane)
    tp = Toolpath()
    feeds: list = []
    for m in moves:
        if any(math.isnan(c) for c in m.tip):
            if m.is_rapid and not len(tp):
                continue  # a Z-only rapid before the first XY: from wherever the tool is, up (never into stock)
            raise TmmError(f"op '{op.Label}', command {m.index} ({m.name}): X, Y or Z was never given")
        feed = None if m.is_rapid else (m.feed or float(op.ToolController.HorizFeed.Value))
        if m.name in ("G2", "G3"):  # FreeCAD's own ops: chords within 1 um, at the arc's feed
            if not len(tp):
                raise TmmError(f"op '{op.Label}', command {m.index} ({m.name}): an arc before any position")
            last = tp.moves[-1]
            try:
                pts = arc_points((last.x, last.y, last.z), m.tip, float(m.params.get("I", 0.0)),
                                 float(m.params.get("J", 0.0)), m.name == "G2", ARC_TOLERANCE_MM,
                                 plane=planes[m.index], k=float(m.params.get("K", 0.0)))
            except TmmError as exc:
                raise TmmError(f"op '{op.Label}', command {m.index} ({m.name}): {exc}") from None
            for p in pts:
                tp.add(MoveKind.FEED, *p, axis=m.axis)
                feeds.append(feed)
            continue
        tp.add(MoveKind.RAPID if m.is_rapid else MoveKind.FEED, *m.tip, axis=m.axis)
        feeds.append(feed)
    return tp, feeds


def _five_axis_shape(op: Any) -> str:
    params = getattr(getattr(op, "Proxy", None), "params_from", None)
    shape = getattr(params(op), "shape", None) if callable(params) else None
    return shape or "bull_nose"


def _tarus_cycle_time(op: Any) -> float:
    from tmm_workbench.core.post.tarus_writer import write_tarus

    program = post_objects.program_from_objects([op.ToolController, op])
    return float(write_tarus(program).cycle_time)


def op_cycle_seconds(op: Any, decoded: Optional[tuple[Toolpath, list]] = None) -> float:
    """The op's cycle time, s: 5-axis paths from the Tarus post (joint speeds, A and C planned), 3-axis from
    the Path's feeds and the tool controller's rapid rates (core.sim.cycle_time). `decoded`: the op's
    (toolpath, feeds) when the caller has read its Path already."""
    tp, feeds = decoded or toolpath_and_feeds(op)
    if len(tp) < 2:
        return 0.0
    if tp.is_five_axis():
        return _tarus_cycle_time(op)
    tc = op.ToolController
    return three_axis_time(tp.points(), feeds, tc.HorizRapid.Value, tc.VertRapid.Value).seconds


def stock_heights(job: Any, grid: Grid, progress: Optional[Callable[[float], bool]] = None) -> np.ndarray:
    stock = getattr(job, "Stock", None)
    if stock is None or stock.Shape.isNull():
        raise TmmError(f"Job '{job.Label}' has no stock to simulate")
    h = mesh_heights(geometry.mesh_from_shape(stock.Shape, 0.01, stock.Label), grid, progress=progress)
    return np.where(np.isfinite(h), h, float(stock.Shape.BoundBox.ZMin))  # outside the stock: none


def design_mesh(job: Any, ops: list) -> Any:
    """The design: the Job's models (TMM's stand-in boxes give the mesh or STL they stand for) and any model an op
    machines instead (its StlFile or Model), as one mesh."""
    meshes = [model_proxy.mesh_of_model(m, DESIGN_DEFLECTION_MM) for m in list(getattr(job.Model, "Group", []) or [])]
    for op in ops:
        if getattr(op, "StlFile", ""):
            meshes.append(geometry.mesh_from_stl(op.StlFile))
        elif getattr(op, "Model", None) is not None:
            meshes.append(model_proxy.mesh_of_model(op.Model, DESIGN_DEFLECTION_MM))
    if not meshes:
        raise TmmError(f"Job '{job.Label}' has no model to compare with")
    return geometry.combine(meshes)


def slope_regions(design: np.ndarray, cell: float) -> dict:
    """Masks of the design's cells by slope band (core.plan.optimal_cutter.SLOPE_BANDS): where seed 003
    found the cutters differ."""
    from tmm_workbench.core.plan.optimal_cutter import SLOPE_BANDS

    slope = compare_mod.slope_deg(design, cell)
    return {f"slope {lo:g}-{hi:g} deg": np.isfinite(design) & (slope >= lo) & (slope < hi) for lo, hi in SLOPE_BANDS}


BUCKET_MM = 25.0  # seed 003's buckets: square XY regions of the grid, reported one by one


def bucket_regions(grid: Grid, design: np.ndarray, size: float = BUCKET_MM) -> dict:
    """Masks of the design's cells by square XY bucket of `size` mm (seed 003, section 4.1: the regions whose
    scallop is compared), at most a quarter of the grid's longer side, named by their XY box."""
    size = min(size, max(grid.nx, grid.ny) * grid.cell / 4)
    nb = max(1, int(round(size / grid.cell)))
    out = {}
    for j0 in range(0, grid.ny, nb):
        for i0 in range(0, grid.nx, nb):
            mask = np.zeros(design.shape, dtype=bool)
            mask[j0:j0 + nb, i0:i0 + nb] = True
            mask &= np.isfinite(design)
            if mask.any():
                x0, y0 = grid.x0 + i0 * grid.cell, grid.y0 + j0 * grid.cell
                out[f"bucket x {x0:g}..{x0 + nb * grid.cell:g} y {y0:g}..{y0 + nb * grid.cell:g}"] = mask
    return out


def simulation_grid(target: Any, cell: float) -> Grid:
    """The grid a simulation of `target` (a Job or an op) would use at `cell` mm: TmmError, before anything is
    allocated, when the cell is not a length > 0 or the grid is above the work limits (the panel asks this
    as a cell size is entered)."""
    job = job_of(target)
    if job is None:
        raise TmmError(f"'{getattr(target, 'Label', target)}' is not in a Job")
    if getattr(job, "Stock", None) is None or job.Stock.Shape.isNull():
        raise TmmError(f"Job '{job.Label}' has no stock to simulate")
    bb = job.Stock.Shape.BoundBox
    grid = Grid.covering(bb.XMin, bb.YMin, bb.XMax, bb.YMax, cell)
    if min(grid.nx, grid.ny) < 2:  # one cell across compares nothing: no slope, no scallop between passes
        largest = min(bb.XLength, bb.YLength) / 2
        raise TmmError(f"simulation cell {cell:g} mm gives {grid.nx} x {grid.ny} cells over Job '{job.Label}''s "
                       f"stock ({bb.XLength:g} x {bb.YLength:g} mm): at most {largest:g} mm gives the 2 x 2 a "
                       f"comparison needs")
    return grid


def simulate_job(target: Any, cell: float = 0.1, tolerance: float = 0.01, max_step: Optional[float] = None,
                 progress: Optional[Callable[[float], bool]] = None,
                 holder: Optional[tuple[str, Optional[float]]] = None,
                 body_tolerance: float = 1e-3) -> JobSimulation:
    """Cuts the stock of `target`'s Job with its active ops (or only `target` when it is an op) and
    compares the result with the Job's model; each op's shank and holder checked along its moves against the
    model and, during the cut, against the stock as the earlier moves left it (its own Holder, or `holder` =
    (name, stick-out) for every op: a job computed without one), stock within `body_tolerance` mm of a body's
    clearance not counted."""
    job = job_of(target)
    if job is None:
        raise TmmError(f"'{getattr(target, 'Label', target)}' is not in a Job")
    ops = operations(job) if target is job else [target]
    if not ops:
        raise TmmError(f"Job '{job.Label}' has no active operation with a tool path")
    grid = simulation_grid(job, cell)

    def share(lo: float, hi: float) -> Optional[Callable[[float], bool]]:  # a phase's part of the whole
        return (lambda f: progress(lo + (hi - lo) * f)) if progress else None
    initial = stock_heights(job, grid, share(0.0, 0.05))
    model = design_mesh(job, ops)  # the design under each cell, highest where models overlap
    design = mesh_heights(model, grid, progress=share(0.05, 0.2))
    heights, done = initial, []
    result = None
    for k, op in enumerate(ops):
        tp, feeds = toolpath_and_feeds(op)
        if len(tp) < 2:
            raise TmmError(f"op '{op.Label}' has no tool path: recompute it first")
        cutter = tools.cutter_from_tool(op.ToolController.Tool)
        five = tp.is_five_axis()

        assembly = _assembly(op, holder)
        r = simulate(tp, cutter, grid, heights, shape=_five_axis_shape(op) if five else "bull_nose",
                     max_step=max_step, tolerance=tolerance,
                     progress=share(0.2 + 0.8 * k / len(ops), 0.2 + 0.8 * (k + 1) / len(ops)), assembly=assembly,
                     body_tolerance=body_tolerance)
        seconds = op_cycle_seconds(op, (tp, feeds))
        done.append(OpSimulation(str(op.Label), five, len(tp), seconds, r.collisions.tolist(), r.seconds,
                                 _holder_check(assembly, model, tp), r.stock_collisions))
        heights = r.heights
        result = r if result is None else SimResult(grid, result.initial, r.heights,
                                                    np.vstack([result.collisions, r.collisions]),
                                                    result.moves_cut + r.moves_cut,
                                                    result.cells_lowered + r.cells_lowered,
                                                    result.seconds + r.seconds, result.five_axis or five,
                                                    combined([result.stock_collisions, r.stock_collisions]))
    # cells compared: the design under them and stock there to begin with
    design_here = np.where(initial >= design - tolerance, design, np.nan)
    regions = {**slope_regions(design_here, grid.cell), **bucket_regions(grid, design_here)}
    comparison = compare_mod.compare(result, design_here, tolerance, regions)
    return JobSimulation(grid, result, comparison, done, design_here)


def _assembly(op: Any, holder: Optional[tuple[str, Optional[float]]]) -> Any:
    """The op's tool assembly to check: `holder` (name, stick-out) given for the check, else the op's own Holder;
    None without either."""
    from tmm_workbench.app import tool_assembly

    if holder is not None:
        name, stick_out = holder
        return tools.assembly_from_tool(op.ToolController.Tool, name, stick_out)
    return tool_assembly.assembly_of(op) if hasattr(op, "Holder") else None


def _holder_check(assembly: Any, model: Any, tp: Toolpath) -> Any:
    """The shank and holder along the moves against the design (core.verify.holder_clearance); None without an
    assembly. Kept beside the stock check of the simulation: what hits the design hits the stock over it, but
    the design check is exact against the triangles (the stock check sees the z-map's cells), and it measures
    how far the tool would have to rise."""
    from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

    return None if assembly is None else check_holder_clearance(model, assembly, tp)


KNOWN_CELL_MM = 0.25  # the stock heights the entries are placed over (a quarter of the tool radius if finer)
KNOWN_CELLS = 1e6     # at most (a larger stock gets larger cells: the entries then stay a little higher)
# a rest op's cells: an eighth of the tool radius. A rest cell is judged at its centre: on a quarter (0.25 mm for
# a ball D2) the cleaned groove's ends of tests/core/crease_case.py kept cells of up to 0.017 mm on the
# simulation's 0.1 mm ones, on an eighth none above 0.01 mm
REST_SHARE = 8.0


def earlier_ops(obj: Any) -> Optional[list]:
    """The active ops before `obj` in its Job; None without a stock or while one of them waits for its
    recompute (its Path may be stale: what it will leave is not known)."""
    job = job_of(obj)
    if job is None or getattr(job, "Stock", None) is None or job.Stock.Shape.isNull():
        return None
    earlier = []
    for op in operations(job):
        if op.Name == obj.Name:
            break
        earlier.append(op)
    if any("Touched" in op.State or "Invalid" in op.State for op in earlier):
        return None
    return earlier


def earlier_paths(obj: Any) -> bool:
    """Whether an active op before `obj` in its Job has a path to cut the stock with (False while one waits for
    its recompute)."""
    earlier = earlier_ops(obj)
    return bool(earlier) and any(len(toolpath_and_feeds(op)[0]) >= 2 for op in earlier)


def known_cell(job: Any, cutter: Cutter, share: float = 4.0) -> float:
    """The cell of the stock heights an op works over: KNOWN_CELL_MM (the tool radius over `share`, a quarter,
    if finer; a rest op's REST_SHARE), larger on a stock so big that it would hold more than KNOWN_CELLS."""
    bb = job.Stock.Shape.BoundBox
    return max(min(KNOWN_CELL_MM, cutter.radius / share), math.sqrt(bb.XLength * bb.YLength / KNOWN_CELLS))


def rest_stock(obj: Any, cutter: Cutter) -> Optional[tuple[Grid, np.ndarray]]:
    """What the Job's earlier ops left, as (grid, heights) for a roughing to cut only where material lies, each
    cell the highest of its neighbours (a height is the stock's at a cell's centre only; a wall between two
    centres rises to the higher). None when no earlier op has a path (the stock solid itself is then exact) or
    one waits for its recompute."""
    if not earlier_paths(obj):
        return None
    left = material_left(obj, cutter)
    if left is None:
        return None
    return left.grid, cell_tops(left.heights)


def material_left(obj: Any, cutter: Cutter, share: float = 4.0) -> Optional[StockHeights]:
    """What the active ops before `obj` in its Job left of the stock, as heights (the stock solid
    cut by their Paths; the linker keeps them up to date as the loops cut, so each loop is entered by a rapid to
    just above the level over it). The simulation, not a bound from the ops' stock to leave: a roughing's stair
    steps on a slope stand higher than its stock to leave, and only the simulation sees them. None (every loop
    entered from the safe height) without a stock, or while an earlier op waits for its recompute (its Path may
    be stale: what it will leave is not known)."""
    job = job_of(obj)
    earlier = earlier_ops(obj)
    if earlier is None:
        return None
    grid = simulation_grid(job, known_cell(job, cutter, share))
    heights = stock_heights(job, grid)
    for op in earlier:
        tp, _ = toolpath_and_feeds(op)
        if len(tp) >= 2:
            shape = _five_axis_shape(op) if tp.is_five_axis() else "bull_nose"
            heights = simulate(tp, tools.cutter_from_tool(op.ToolController.Tool), grid, heights,
                               shape=shape).heights
    return StockHeights(grid, heights, cutter)
