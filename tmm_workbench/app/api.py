"""Headless API for macros and scripts: an STL (or a FreeCAD mesh / Part) to G-code in one call.

Run under FreeCAD (`freecadcmd script.py`, or the GUI's Python console), with the add-on installed:

    from tmm_workbench.app.api import run_surface
    r = run_surface("/path/part.stl", tool="ballend", diameter=6, stepover=0.5, sample_step=0.25,
                    post="linuxcnc", gcode_path="/tmp/part.ngc", fcstd_path="/tmp/part.FCStd")
    print(len(r.toolpath), "moves;", r.gcode.count("\\nG1"), "G1 lines")

The call builds a Path Job (the mesh gets a stand-in box, see model_proxy), a ToolBit and tool
controller, a 'TMM 3-axis Surface' op, recomputes, post-processes and optionally saves. Feeds are
given in mm/min here (FreeCAD stores mm/s). Heights default to the top of the model or of the Job's
stock, whichever is higher, + 5 mm (safe) and + 10 mm (clearance). A FreeCAD object input is machined
in its own document; an STL path opens a new document `doc_name`. On failure a TmmError with the op's message is raised (a document opened
by the call is closed first).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence, Union

import FreeCAD

from tmm_workbench.app import model_proxy, tools
from tmm_workbench.app import progress as progress_mod
from tmm_workbench.app.api_args import (FEED, LENGTH, CallbackProgress, by_core_name, numbers, option,
                                        plain_numbers)
from tmm_workbench.app.api_five import MultipointResult, run_mesh5, run_multipoint
from tmm_workbench.app.api_run import StockBox, SurfaceResult, run
from tmm_workbench.app.api_surface import run_surface
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, spec_of
from tmm_workbench.core.tools.cutter import Cutter

__all__ = ["run_surface", "run_roughing", "run_waterline", "run_mesh5", "run_multipoint", "run", "simulate",
           "minimum_stick_out", "set_holder", "compare_cutters", "SurfaceResult", "MultipointResult",
           "SimulationReport", "StockBox", "TmmError"]

TOOL_ALIASES = tools.SHAPE_ALIASES
PATTERN_NAMES = {"zigzag": "ZigZag", "oneway": "OneWay", "spiral": "Spiral"}
BOUNDARY_NAMES = {"model": "Model", "stock": "Stock"}
OFF_MODEL_NAMES = {"floor": "Floor", "skip": "Skip"}
STEPOVER_MODE_NAMES = {"stepover": "StepOver", "cusp": "Cusp", "adaptive": "Adaptive"}
FORWARD_STEP_NAMES = {"tolerance": "Tolerance", "sample": "SampleStep"}  # lean passes
STEPOVER_MODE_NAMES["offset3d"] = "Offset3D"  # 3D offset: loops from the region's edge inward


# --- z-level roughing and waterline ----------------------------------------------------------------


@plain_numbers
def run_roughing(model: Union[str, os.PathLike, Any, None] = None, *, tool: Union[str, Cutter] = "endmill",
                 diameter: float = 6.0, corner_radius: float = 0.0, step_down: float = 2.0,
                 stepover_percent: float = 40.0, stock_to_leave: float = 0.5,
                 stock_to_leave_axial: Optional[float] = None, layer_mode: str = "fixed",
                 remaining_height: Optional[float] = None, flat_layers: bool = True, pattern: str = "offset",
                 direction: str = "climb", entry: str = "helix", ramp_angle_deg: Optional[float] = None,
                 helix_diameter_percent: Optional[float] = None, keep_tool_down: bool = True,
                 final_z: Optional[float] = None, chord_tolerance: Optional[float] = None,
                 stock: Optional[StockBox] = None, stock_margin: float = 1.0, stock_above: float = 1.0,
                 job: Any = None, safe_height: Optional[float] = None, clearance_height: Optional[float] = None,
                 horiz_feed: float = 1000.0, vert_feed: float = 300.0, spindle_speed: float = 10000.0,
                 tool_controller: Any = None, label: Optional[str] = None, post: str = "linuxcnc",
                 gcode_path: Optional[Union[str, os.PathLike]] = None,
                 fcstd_path: Optional[Union[str, os.PathLike]] = None, doc_name: str = "TMM",
                 progress: Union[bool, Callable[[float], bool]] = True, holder: Optional[str] = None,
                 stick_out: Optional[float] = None, shank_clearance: Optional[float] = None,
                 holder_clearance: Optional[float] = None, holder_collision: Optional[str] = None) -> SurfaceResult:
    """Z-level roughing of a block down to `model` (STL path, Mesh::Feature or Part::Feature) + stock to leave,
    to G-code (a 'TMM Roughing' op in a new Job, or in `job`).

    tool: 'endmill' | 'bullnose' | 'ballend' (corner_radius for bullnose) or a core Cutter (as run_surface).
    The stock: the model's box grown by `stock_margin` on the sides and `stock_above` on top (mm; the Job's
    box stock, 1 mm below), or `stock` = (xmin, ymin, zmin, xmax, ymax, zmax) given; with `job` (a Job or a
    result of this API), the op is added to it with its own tool controller and cuts that Job's stock
    (`model`: None for the Job's model). layer_mode 'fixed' | 'tolerance' (remaining_height: seed 000
    eq. 3.11); pattern 'offset' | 'zigzag'; direction 'climb' | 'conventional'; entry 'helix' | 'ramp' |
    'plunge'. stock_to_leave_axial: None follows stock_to_leave. final_z: None roughs down to the model's
    lowest point. None for the other optional numbers keeps the op's defaults. Heights, feeds (mm/min),
    tool_controller, label, post, files and progress as run_surface; the result is a SurfaceResult (op: the
    roughing op).
    The whole tool (holder, stick_out, shank_clearance, holder_clearance, holder_collision) as run_surface.
    """
    whole_tool = dict(holder=holder, stick_out=stick_out, shank_clearance=shank_clearance,
                      holder_clearance=holder_clearance, holder_collision=holder_collision)
    from tmm_workbench.app import op_roughing, stages
    from tmm_workbench.core.strategies.zlevel_rough import RoughingParams

    numbers(**_specs(RoughingParams, step_down=step_down, stepover_percent=stepover_percent,
                      stock_to_leave=stock_to_leave, stock_to_leave_axial=stock_to_leave_axial,
                      remaining_height=remaining_height, ramp_angle_deg=ramp_angle_deg,
                      helix_diameter_percent=helix_diameter_percent),
             chord_tolerance=(chord_tolerance, spec_of(RoughingParams, "chord_tol")),
             final_z=(final_z, LENGTH))  # the tool, stock, heights and feeds: run's
    values: dict[str, Any] = {
        "StepDown": step_down, "StepOver": stepover_percent, "StockToLeave": stock_to_leave,
        "LayerMode": option("layer_mode", layer_mode, by_core_name(op_roughing.LAYER_MODES)),
        "FlatLayers": bool(flat_layers), "KeepToolDown": bool(keep_tool_down),
        "Pattern": option("pattern", pattern, by_core_name(op_roughing.PATTERNS)),
        "Direction": option("direction", direction, by_core_name(op_roughing.DIRECTIONS)),
        "Entry": option("entry", entry, by_core_name(op_roughing.ENTRIES))}
    for prop, value in (("AxialStockToLeave", stock_to_leave_axial), ("RemainingHeight", remaining_height),
                        ("RampAngle", ramp_angle_deg), ("HelixDiameter", helix_diameter_percent),
                        ("ChordTolerance", chord_tolerance)):
        if value is not None:
            values[prop] = value
    if final_z is not None:
        values.update(UseFinalZ=True, FinalZ=final_z)
    values.update(stages.api_values(op_roughing.TOOL_STAGES, RoughingParams, whole_tool, model))
    return run(op_roughing.OP_NAME, model, job=job, tool=tool, diameter=diameter, corner_radius=corner_radius, stock=stock,
               stock_margin=stock_margin, stock_above=stock_above, safe_height=safe_height,
               clearance_height=clearance_height, horiz_feed=horiz_feed, vert_feed=vert_feed,
               spindle_speed=spindle_speed, post=post, gcode_path=gcode_path, fcstd_path=fcstd_path,
               doc_name=doc_name, progress=progress, tool_controller=tool_controller, label=label, **values)


@plain_numbers
def run_waterline(model: Union[str, os.PathLike, Any, None] = None, *, tool: Union[str, Cutter] = "ballend",
                  diameter: float = 6.0, corner_radius: float = 0.0, step_down: float = 1.0,
                  stock_to_leave: float = 0.0, sample_step: Optional[float] = None,
                  chord_tolerance: Optional[float] = None, direction: str = "climb", boundary: str = "model",
                  margin: float = 0.0, top_z: Optional[float] = None, bottom_z: Optional[float] = None,
                  stock: Optional[StockBox] = None, stock_margin: float = 1.0, stock_above: float = 1.0,
                  job: Any = None, safe_height: Optional[float] = None, clearance_height: Optional[float] = None,
                  horiz_feed: float = 1000.0, vert_feed: float = 300.0, spindle_speed: float = 10000.0,
                  tool_controller: Any = None, label: Optional[str] = None, post: str = "linuxcnc",
                  gcode_path: Optional[Union[str, os.PathLike]] = None,
                  fcstd_path: Optional[Union[str, os.PathLike]] = None, doc_name: str = "TMM",
                  progress: Union[bool, Callable[[float], bool]] = True, holder: Optional[str] = None,
                  stick_out: Optional[float] = None, shank_clearance: Optional[float] = None,
                  holder_clearance: Optional[float] = None, holder_collision: Optional[str] = None,
                  rest: Optional[bool] = None, rest_from: Optional[str] = None, rest_reference: Any = None,
                  rest_tolerance: Optional[float] = None) -> SurfaceResult:
    """Waterline finishing of `model` (STL path, Mesh::Feature or Part::Feature): closed loops at constant
    heights `step_down` apart (a 'TMM Waterline' op in a new Job, or in `job`: e.g. after run_roughing, with
    its own tool controller; `model` None for the Job's model).

    boundary: 'model' (its XY box grown by the tool radius) | 'stock', grown by `margin`. top_z, bottom_z:
    the highest and lowest level (both or neither; default the model's top and lowest point). sample_step:
    None automatic. direction 'climb' | 'conventional'. The stock of a new Job as run_roughing's. Heights,
    feeds (mm/min), tool_controller, label, post, files and progress as run_surface; the result is a SurfaceResult (op:
    the waterline op).
    The whole tool (holder, stick_out, shank_clearance, holder_clearance, holder_collision) as run_surface.
    rest=True: the loops only where the `job`'s earlier ops (or rest_reference) left more than rest_tolerance that
    this tool reaches (rest_from, rest_reference, rest_tolerance as run_surface's region 'rest').
    """
    whole_tool = dict(holder=holder, stick_out=stick_out, shank_clearance=shank_clearance,
                      holder_clearance=holder_clearance, holder_collision=holder_collision, rest=rest,
                      rest_from=rest_from, rest_reference=rest_reference, rest_tolerance=rest_tolerance)
    from tmm_workbench.app import op_waterline, stages
    from tmm_workbench.core.strategies.waterline import WaterlineParams

    numbers(**_specs(WaterlineParams, step_down=step_down, stock_to_leave=stock_to_leave, sample_step=sample_step),
             chord_tolerance=(chord_tolerance, spec_of(WaterlineParams, "chord_tol")), margin=(margin, LENGTH),
             top_z=(top_z, LENGTH), bottom_z=(bottom_z, LENGTH))  # the tool, stock, heights and feeds: run's
    if (top_z is None) != (bottom_z is None):
        raise TmmError(f"top_z and bottom_z are given together or not at all, got top_z={top_z!r}, "
                       f"bottom_z={bottom_z!r}")
    values: dict[str, Any] = {
        "StepDown": step_down, "StockToLeave": stock_to_leave, "BoundaryMargin": margin,
        "BoundaryShape": option("boundary", boundary, BOUNDARY_NAMES),
        "Direction": option("direction", direction, by_core_name(op_waterline.DIRECTIONS))}
    if sample_step is not None:
        values["SampleStep"] = sample_step
    if chord_tolerance is not None:
        values["ChordTolerance"] = chord_tolerance
    if top_z is not None:
        values.update(UseZRange=True, TopZ=top_z, BottomZ=bottom_z)
    values.update(stages.api_values(op_waterline.TOOL_STAGES, WaterlineParams, whole_tool, model))
    return run(op_waterline.OP_NAME, model, job=job, tool=tool, diameter=diameter, corner_radius=corner_radius, stock=stock,
               stock_margin=stock_margin, stock_above=stock_above, safe_height=safe_height,
               clearance_height=clearance_height, horiz_feed=horiz_feed, vert_feed=vert_feed,
               spindle_speed=spindle_speed, post=post, gcode_path=gcode_path, fcstd_path=fcstd_path,
               doc_name=doc_name, progress=progress, tool_controller=tool_controller, label=label, **values)


def _specs(params_class: type, **values: Any) -> dict[str, tuple[Any, Spec]]:
    """API arguments named as the params fields, each with its field's spec."""
    return {name: (value, spec_of(params_class, name)) for name, value in values.items()}


@dataclass
class SimulationReport:
    max_left: float            # mm, the largest deviation above the design (scallop, material left)
    min_deviation: float       # mm, the smallest (negative: the deepest gouge)
    percentiles: dict          # {50, 90, 95, 99: deviation mm}
    removed_volume: float      # mm^3
    remaining_volume: float    # mm^3 above the design
    gouge_cells: int           # cells below the design by more than the tolerance
    gouged: bool
    collisions: list           # [(op label, move, depth mm)]: rapids through stock
    cycle_seconds: float       # all ops
    regions: dict              # the same numbers per slope band ("slope 0-20 deg") and per XY bucket (25 mm, or a quarter of the stock)
    ops: list                  # app.simulation.OpSimulation per op
    png: Optional[str]         # the heat map written, when asked
    cell: float
    tolerance: float
    simulation: Any            # app.simulation.JobSimulation (grids, heights, deviation)
    holder_collisions: list = field(default_factory=list)   # [(op label, HolderClearance)] where one came too close
    stock_collisions: list = field(default_factory=list)    # [(op label, StockCollisions)]: the same against the stock


@plain_numbers
def simulate(target: Any, *, cell: float = 0.1, tolerance: float = 0.01, max_step: Optional[float] = None,
             png_path: Optional[Union[str, os.PathLike]] = None, progress: Union[bool, Callable[[float], bool]] = True,
             fail_on_gouge: bool = False, holder: Optional[str] = None,
             stick_out: Optional[float] = None, png_band: Optional[float] = None,
             body_tolerance: float = 1e-3) -> SimulationReport:
    """Cuts the stock of a Job with its active ops in order (or with one op), compares it with the Job's model
    and reports: the deviation (vertical, + material left, - gouge) extremes and percentiles, removed and
    remaining volume, rapids through stock, cycle time. `target`: a Job, an op, or a SurfaceResult /
    MultipointResult of this API. png_path: writes the heat map. A gouge deeper than `tolerance` is printed
    as an error; with fail_on_gouge it raises TmmError. 5-axis moves are sub-stepped `max_step` mm apart
    (default: the step whose cusp between tool instances is a tenth of the tolerance, core.sim.simulate.sub_step).
    The shank and holder of each op (its Holder; or `holder`, a name of the holder library, with `stick_out` for
    every op: a job computed without one) are checked along its moves against the design: `holder_collisions`,
    and during the cut against the stock as each move finds it (uncut material too): `stock_collisions`, each
    printed as an error (with fail_on_gouge: raised); png_path's heat map marks the stock collisions, stock within
    `body_tolerance` mm of a body's clearance not counted (a finish leaves its cusps above the design the guards
    keep the clearance from). png_band:
    the heat map's colours span +-png_band mm, the cells beyond in its darkest ends, counted in its title (TMM
    Simulate's colour band; None: the whole range)."""
    from tmm_workbench.app import simulation
    from tmm_workbench.core.preview.deviation_png import render_deviation_png

    target = getattr(target, "job", None) or target
    numbers(cell=(cell, Spec(low=1e-4, high=100.0, unit="mm", label="cell")),
             tolerance=(tolerance, Spec(low=0.0, high=10.0, unit="mm", label="tolerance")),
             max_step=(max_step, Spec(low=1e-3, high=10.0, unit="mm", label="max_step", optional=True)))
    if stick_out is not None and holder is None:
        raise TmmError("stick_out is used with a holder only: give holder= (a name from the holder library) as well")
    numbers(stick_out=(stick_out, Spec(low=0.0, high=1000.0, unit="mm", label="stick_out", low_open=True)),
            png_band=(png_band, Spec(low=0.0, high=1000.0, unit="mm", label="png_band", low_open=True, optional=True)),
            body_tolerance=(body_tolerance, Spec(low=0.0, high=10.0, unit="mm", label="body_tolerance")))
    if png_band is not None and not png_path:
        raise TmmError("png_band colours the heat map: give png_path as well")
    label = str(getattr(target, "Label", "simulation"))
    factory = (lambda _: CallbackProgress(progress)) if callable(progress) else None
    with progress_mod.using(factory):
        with progress_mod.reporter(f"{label} simulation", bool(progress)) as cb:
            sim = simulation.simulate_job(target, cell, tolerance, max_step, cb,
                                          None if holder is None else (holder, stick_out), body_tolerance)
    o = sim.comparison.overall
    png = None
    if png_path:
        png = render_deviation_png(sim.comparison, sim.grid, str(png_path), f"{label}: simulated stock vs design",
                                   collisions=sim.result.stock_collisions, band=png_band)
    report = SimulationReport(o.max_left, o.min_deviation, dict(o.percentiles), sim.comparison.removed_volume,
                              o.remaining_volume, o.gouge_cells, sim.comparison.gouged, sim.collisions,
                              sim.cycle_seconds,
                              {k: v.as_dict() for k, v in sim.comparison.regions.items()}, sim.ops, png, cell,
                              tolerance, sim, [(o.label, o.holder) for o in sim.ops if o.holder is not None
                                               and not o.holder.ok], sim.stock_collisions)
    problems = [f"op '{op_label}': {check.summary()}" for op_label, check in report.holder_collisions]
    problems += [f"op '{op_label}': {found.summary()}" for op_label, found in report.stock_collisions]
    if report.gouged:
        problems.append(f"the simulated stock is gouged {-o.min_deviation:.4f} mm below the design in "
                        f"{o.gouge_cells} cells (tolerance {tolerance:g} mm)")
    if report.collisions:
        op_label, move, depth = report.collisions[0]
        problems.append(f"{len(report.collisions)} rapids cut stock (the first: op '{op_label}', move {move}, "
                        f"{depth:.3f} mm deep)")
    if problems:
        text = f"{label}: " + "; ".join(problems)
        FreeCAD.Console.PrintError(text + "\n")
        if fail_on_gouge:
            raise TmmError(text)
    return report


@plain_numbers
def minimum_stick_out(target: Any, *, holder: Optional[str] = None) -> dict:
    """The shortest stick-out per 3-axis op of a Job (or of one op, or an API result) with which the holder
    never lifts the tool (core.verify.holder_clearance.minimum_stick_out over the op's moves against the design):
    {op label: StickOut}. `holder`: a name of the holder library for every op; None: each op's own Holder (or its
    tool controller's; an op without one is left out). 5-axis ops are left out (their tool tilts)."""
    from tmm_workbench.app import stick_out

    return stick_out.per_op(getattr(target, "job", None) or getattr(target, "op", None) or target, holder)


def set_holder(tool_controller: Any, holder: Optional[str], stick_out: float = 0.0) -> None:
    """Clamps a tool controller's tool (or an API result's) in `holder` (a name of the holder library; None: no
    holder) at `stick_out` mm from the holder's face to the tip (0: the ToolBit's Length minus 3 shank diameters).
    Ops whose Holder is FromToolController (the default of a new op) then keep that holder clear of the model."""
    from tmm_workbench.app import tool_assembly

    op = getattr(tool_controller, "op", None)
    tc = op.ToolController if op is not None else tool_controller
    tool_assembly.set_tool_controller_holder(tc, holder, stick_out)


@plain_numbers
def compare_cutters(model: Any, candidates: Sequence[Any], *, stepover: float, sample_step: float,
                    cell: float = 0.1, tolerance: float = 0.01, angle_deg: float = 0.0, margin: float = 0.0,
                    horiz_feed: float = 1000.0, vert_feed: float = 300.0) -> Any:
    """Seed 003's optimal cutter (core.plan.optimal_cutter): the same 3-axis raster with each candidate, each
    simulated and compared with the model, ranked with the reason. `model`: an STL path, a Mesh/Part object
    or a Job (its model); `candidates`: ToolBits, tool controllers (their tool) or core Cutters. Feeds in
    mm/min, the same for all (the cycle times compare the paths)."""
    from tmm_workbench.app import geometry, simulation
    from tmm_workbench.core.plan.optimal_cutter import compare_cutters as core_compare
    from tmm_workbench.core.strategies.raster_drop import SurfaceParams

    numbers(stepover=(stepover, spec_of(SurfaceParams, "stepover")),
             sample_step=(sample_step, spec_of(SurfaceParams, "sample_step")),
             cell=(cell, Spec(low=1e-4, high=100.0, unit="mm", label="cell")),
             horiz_feed=(horiz_feed, FEED), vert_feed=(vert_feed, FEED))
    if isinstance(model, (str, os.PathLike)):
        mesh = geometry.mesh_from_stl(model)
    elif simulation.job_of(model) is model:
        mesh = geometry.combine([model_proxy.mesh_of_model(m, 0.001) for m in model.Model.Group])
    else:
        mesh = model_proxy.mesh_of_model(model, 0.001)
    cutters = []
    for c in candidates:
        if isinstance(c, Cutter):
            cutters.append((c.describe(), c))
        else:
            bit = getattr(c, "Tool", c)  # a tool controller carries its ToolBit
            cutters.append((tools.label_of(bit), tools.cutter_from_tool(bit)))
    return core_compare(mesh, cutters, stepover=stepover, sample_step=sample_step, cell=cell, tolerance=tolerance,
                        angle_deg=angle_deg, margin=margin, horiz_feed=horiz_feed / 60.0,
                        vert_feed=vert_feed / 60.0)
