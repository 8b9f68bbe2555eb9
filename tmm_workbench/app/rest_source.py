"""Rest machining in the 3-axis Surface op (Region 'Rest'): what is left comes from the Job's earlier ops (the
simulation of their paths on the stock: RestFrom EarlierOps) or from a reference tool (RestReference: a tool
controller or ToolBit whose envelope over the model, below the stock's top, is what it would leave); the op's tool
machines only where it takes off more than RestTolerance of it (core.footprint.rest, core.strategies.rest_filter),
with the Surface's pattern, clipped to the rest region and its box. RestReport says the area and the volume left
before and after; RestRegions marks the rest cells for the 3D view.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Optional, Sequence

import FreeCAD
import numpy as np

from tmm_workbench.app import simulation, tools
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.rest import RestArea, RestStock, rest_area, tool_envelope
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.params import Spec
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.tools.cutter import Cutter

REST = "Rest"                     # the Region choice (app.region_source.REGIONS)
EARLIER_OPS, REFERENCE_TOOL = "EarlierOps", "ReferenceTool"
SOURCES = {EARLIER_OPS: EARLIER_OPS, REFERENCE_TOOL: REFERENCE_TOOL}
TOLERANCE = Spec("rest tolerance", "mm", low=0.0, high=10.0, low_open=True)
REPORT, MARKS = "RestReport", "RestRegions"
MAX_MARKS = 20_000                # rest cells marked on the view (every k-th of a larger area)


@dataclass
class Rest:
    area: RestArea
    stock: RestStock              # what the rest filter cuts against
    region: Any                   # the CL region clipped to the op's box


def reference_cutter(op: Any, cutter: Cutter) -> Cutter:
    """The cutter of RestReference, at least as large as the op's `cutter` (TmmError naming what is wrong)."""
    ref = getattr(op, "RestReference", None)
    if ref is None:
        raise TmmError("Region 'Rest' from ReferenceTool: no reference tool (RestReference is empty): choose the "
                       "tool controller of the larger tool that finished before")
    bit = getattr(ref, "Tool", ref)   # a tool controller carries its ToolBit
    reference = tools.cutter_from_tool(bit)
    if reference.diameter < cutter.diameter:
        raise TmmError(f"Region 'Rest': the reference tool {reference.describe()} is smaller than the rest tool "
                       f"{cutter.describe()}: it must be at least {cutter.diameter:g} mm (a larger tool that "
                       f"finished before)")
    return reference


def rest_of(op: Any, job: Any, mesh: TriMesh, cutter: Cutter, left: Any, box: tuple) -> Rest:
    """The op's rest (Region 'Rest'): `left` the Job's earlier ops' stock (app.simulation.material_left, None
    without one), `box` the op's boundary box (xmin, ymin, xmax, ymax). TmmError naming what is missing, or when
    nothing is left for the tool."""
    tolerance = float(op.RestTolerance.Value)
    if not (math.isfinite(tolerance) and TOLERANCE.low < tolerance <= TOLERANCE.high):
        raise TmmError(f"RestTolerance must be in (0, {TOLERANCE.high:g}] mm, got {tolerance:g}")
    if op.RestFrom == EARLIER_OPS:
        if left is None or not simulation.earlier_paths(op):
            raise TmmError("Region 'Rest' from EarlierOps: no earlier operation of the Job has a path to leave "
                           "material (or one waits for its recompute): put the rest op after the finishing op, or "
                           "take the rest from a reference tool (RestFrom ReferenceTool)")
        grid, heights = left.grid, np.array(left.heights)   # a copy: the linker cuts the material top as it links
    else:
        reference = reference_cutter(op, cutter)
        grid = simulation.simulation_grid(job, simulation.known_cell(job, cutter, simulation.REST_SHARE))
        heights = np.minimum(simulation.stock_heights(job, grid), tool_envelope(mesh, reference, grid))
    area = rest_area(heights, mesh_heights(mesh, grid), tool_envelope(mesh, cutter, grid), grid, tolerance,
                     cutter.radius)
    if area.empty:
        raise TmmError(f"Region 'Rest': {area.summary()} ({cutter.describe()})")
    region = polygons.intersection(area.region, [polygons.rectangle(*box)])
    if not region:
        raise TmmError(f"Region 'Rest': the rest area lies outside the op's boundary x {box[0]:g}..{box[2]:g}, "
                       f"y {box[1]:g}..{box[3]:g} mm")
    return Rest(area, area.stock(heights), region)


def report(obj: Any, rest: Optional[Rest], notes: Sequence = ()) -> None:
    """RestReport (the area and volumes, and a clean-up's strips among the strategy's `notes`: how many, how long,
    the points that found no crease) and RestRegions (the rest cells at the height left, for the view); both
    emptied when the op is not a rest op."""
    for name, kind, tip in ((REPORT, "App::PropertyString", "The rest area of the last computation: its size "
                             "and the volume above the design before and after this tool"),
                            (MARKS, "App::PropertyVectorList", "The rest cells of the last computation (drawn "
                             "on the 3D view)")):
        if not hasattr(obj, name):
            obj.addProperty(kind, name, "Region", tip)
        obj.setEditorMode(name, 1)
    if rest is None:
        obj.RestReport, obj.RestRegions = "", []
        return
    mask = rest.area.mask
    pts = np.column_stack([rest.area.cells_xy(), rest.stock.heights[mask]])[:: max(1, -(-mask.sum() // MAX_MARKS))]
    from tmm_workbench.core.footprint.cleanup import CleanupReport
    from tmm_workbench.core.strategies.rest_steep import SteepReport

    obj.RestReport = "; ".join([rest.area.summary()] + [n.summary() for n in notes
                                                        if isinstance(n, (CleanupReport, SteepReport))])
    obj.RestRegions = [FreeCAD.Vector(*map(float, p)) for p in pts]
    FreeCAD.Console.PrintMessage(f"{obj.Label}: {obj.RestReport}\n")


def ignored(args: Args, asked: str = "region='rest'") -> Optional[str]:
    """The rest's settings mean nothing outside Region 'Rest' (the waterline: rest=True); a reference tool nothing
    when the rest comes from the earlier ops."""
    rest = str(args.get("region") or "").lower() == REST.lower() or args.get("rest") is True
    for name in ("rest_from", "rest_reference", "rest_tolerance"):
        if args.get(name) is not None and not rest:
            return f"{name} is used with {asked} only"
    source = str(args.get("rest_from") or "earlier_ops").lower()
    if args.get("rest_reference") is not None and source != "reference_tool":
        return "rest_reference is used with rest_from='reference_tool' only"
    if source == "reference_tool" and args.get("rest_reference") is None:
        return "rest_from='reference_tool' needs rest_reference= (a tool controller or ToolBit of the larger tool)"
    return None


STAGE = Stage("rest", (
    Field("RestFrom", "choice", "Region",
          "Region 'Rest': what is left comes from the Job's earlier operations (EarlierOps: their paths simulated "
          "on the stock) or from what RestReference would leave (ReferenceTool)", api="rest_from",
          choices=SOURCES, api_names={"earlier_ops": EARLIER_OPS, "reference_tool": REFERENCE_TOOL},
          default=EARLIER_OPS, widget="restFrom"),
    Field("RestReference", "link", "Region",
          "Region 'Rest' from ReferenceTool: the tool controller (or ToolBit) of the larger tool that finished "
          "before", api="rest_reference"),
    Field("RestTolerance", "length", "Region",
          "Region 'Rest': cut where more than this is left above what this tool reaches, mm",
          api="rest_tolerance", default=0.01, spec=TOLERANCE, widget="restTolerance"),
), ignored=ignored)


def is_rest(obj: Any) -> bool:
    """Whether the op machines only the rest (Region 'Rest', or the waterline's RestOnly)."""
    return getattr(obj, "Region", "") == REST or bool(getattr(obj, "RestOnly", False))


def material_left(obj: Any, cutter: Cutter) -> Any:
    """What the Job's earlier ops left (app.simulation.material_left), on a rest op's finer cells."""
    return simulation.material_left(obj, cutter, simulation.REST_SHARE if is_rest(obj) else 4.0)


def know_stock(obj: Any, params: Any, left: Any, mesh: TriMesh) -> None:
    """The stock the Job's earlier ops leave (`left`: material_left) given to the op's holder guard
    (core.sim.stock_bodies.give) when an earlier op has a path: its shank and holder keep their clearance from what
    those ops left standing off the design too. A Job's first op keeps it from the model only (finishing from the
    raw block, only the Job's simulation sees the shank in the block: fc_test_sim_holder)."""
    from tmm_workbench.core.sim import stock_bodies

    stock_bodies.give(params, left if left is not None and simulation.earlier_paths(obj) else None, mesh)


def rest_of_op(obj: Any, job: Any, mesh: TriMesh, cutter: Cutter, left: Any, box: tuple) -> Optional[Rest]:
    """The op's rest when it machines only the rest (Region 'Rest', or the waterline's RestOnly), else None."""
    if is_rest(obj):
        return rest_of(obj, job, mesh, cutter, left, box)
    return None


# the Waterline's: its loops only where they take off rest material (no region: the loops are levels)
WATERLINE_STAGE = Stage("rest", (
    Field("RestOnly", "bool", "Rest",
          "Cut only where the Job's earlier ops (or RestReference) left more than RestTolerance that this tool "
          "reaches: the steep walls of a rest", api="rest", default=False),
    *(replace(f, group="Rest", widget="") for f in STAGE.fields),
), ignored=lambda args: ignored(args, "rest=True"))
