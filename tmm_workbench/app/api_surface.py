"""`run_surface`: 3-axis raster finishing through the headless API (re-exported by app.api, whose name it is:
`from tmm_workbench.app.api import run_surface`); a module of its own so that app.api_five's companion clean-up
op can use it without importing app.api back."""
from __future__ import annotations

import os
from typing import Any, Callable, Optional, Union

from tmm_workbench.app.api_args import plain_numbers
from tmm_workbench.app.api_run import SurfaceResult, run
from tmm_workbench.core.tools.cutter import Cutter

DEFAULT_STEPOVER = 1.0  # mm, stepover_mode 'stepover' without a step-over given


@plain_numbers
def run_surface(model: Union[str, os.PathLike, Any, None] = None, *, job: Any = None,
                tool: Union[str, Cutter] = "ballend",
                diameter: float = 6.0, corner_radius: float = 0.0, stepover: Optional[float] = None,
                sample_step: float = 0.5,
                angle_deg: float = 0.0, pattern: str = "zigzag", stock_to_leave: float = 0.0,
                boundary: str = "model", margin: float = 0.0, off_model: str = "floor",
                chord_tolerance: Optional[float] = None, stepover_mode: str = "stepover",
                cusp: Optional[float] = None,
                region: Any = None, slope_range: Optional[tuple[float, float]] = None,
                spiral_direction: Optional[str] = None, region_tolerance: Optional[float] = None,
                safe_height: Optional[float] = None, clearance_height: Optional[float] = None,
                horiz_feed: float = 1000.0, vert_feed: float = 300.0, spindle_speed: float = 10000.0,
                tool_controller: Any = None, label: Optional[str] = None, forward_step: str = "tolerance",
                arcs: bool = False,
                verify_cusp: bool = False,
                post: str = "linuxcnc", gcode_path: Optional[Union[str, os.PathLike]] = None,
                fcstd_path: Optional[Union[str, os.PathLike]] = None, doc_name: str = "TMM",
                progress: Union[bool, Callable[[float], bool]] = True,
                stepover_percent: Optional[float] = None, final_depth: Optional[float] = None,
                finish_passes: Optional[int] = None, finish_step_down: Optional[float] = None,
                start_point: Optional[tuple[float, float]] = None,
                offset_from: Any = None, holder: Optional[str] = None, stick_out: Optional[float] = None,
                shank_clearance: Optional[float] = None, holder_clearance: Optional[float] = None,
                holder_collision: Optional[str] = None, rest_from: Optional[str] = None,
                rest_reference: Any = None, rest_tolerance: Optional[float] = None,
                pencil_source: Optional[str] = None, pencil_curve: Any = None,
                pencil_file: Optional[Union[str, os.PathLike]] = None, pencil_side: Optional[str] = None,
                pencil_passes: Optional[int] = None) -> SurfaceResult:
    """3-axis raster finishing of `model` (STL path, Mesh::Feature or Part::Feature) to G-code, in a new Job or
    added to `job` (a Job or an API result: its model when `model` is None, a further tool controller).

    tool: 'ballend' | 'endmill' | 'bullnose' (FreeCAD ToolBit shapes; corner_radius for bullnose), or a
    core.tools.Cutter (any APT cutter, e.g. Cutter(10, 2, 5, 3, 20): a ToolBit of TMM's tmm_apt shape when
    it has a cone or taper; diameter and corner_radius are then the cutter's own).
    pattern: 'zigzag' | 'oneway'; boundary: 'model' | 'stock' XY box grown by `margin` (mm).
    off_model: 'floor' (cut along the model's lowest point where no part of it is under the tool) | 'skip'
    (lift over such places, cut only over the model).
    chord_tolerance: how far above the CL points a longer straight move may pass where it replaces them
    (mm; default the op's, 0.001; 0 keeps every point off a straight line).
    An argument the chosen mode would ignore is refused by name (stepover with a cusp mode, cusp without one or
    verify_cusp, spiral_direction without pattern 'spiral', arcs with forward_step 'sample').
    stepover_mode: 'stepover' (passes `stepover` apart, default 1 mm) | 'cusp' (the step-over that keeps the cusp height
    `cusp` on the boundary's worst crossing, slope and curvature) | 'adaptive' (each pass placed from the previous one's tool
    positions so the cusp between them is `cusp`); cusp: mm, default the op's (0.01).
    stepover_mode 'offset3d': closed loops from the region's boundary inward, spaced so the cusp between
    neighbours is `cusp` across the local slope (3D offset / constant scallop; pattern 'zigzag' links them,
    'oneway' lifts before each). offset_from: None (from the region's boundary) or a sketch / an object with
    edges, open or closed, of the model's document (the op's OffsetStart Curve): the passes are offset from it,
    seen from above, to both sides across the region.
    region (where the tool centre may go; app.region_source): None (the boundary box), a sketch or any
    object with closed edges (inner loops are holes), or faces of the model seen from above: face names
    ("Face3" or a list) of a Part model, or (object, names) pairs; region_tolerance: its discretisation, mm.
    region 'rest' (app.rest_source): only where more than rest_tolerance (mm, default 0.01) is left that this
    tool reaches; rest_from 'earlier_ops' (default: the stock the `job`'s earlier ops leave, simulated) |
    'reference_tool' (what rest_reference, a tool controller or ToolBit of the larger tool, would leave).
    pattern 'pencil' (app.pencil_source): along concave creases (pencil_source 'creases', default: where the tool
    touches the model on two sides, CL valleys deeper than `cusp`), an outline (pencil_source 'outline':
    pencil_curve, a sketch or edges of the model's document, offset by the tool radius to pencil_side 'outside' |
    'inside' | 'both'), a footprint file (pencil_source 'file': pencil_file, x y lift per line) or seed 000's
    clean-up strips (pencil_source 'cleanup', with region 'rest': where the finishing tool's contact normals jump
    more than its corner and rest_tolerance allow, joined with the rest cells, each point slid to the crease by the
    drop along a vector; the finishing tool is rest_reference, or the job's last earlier op with a ball or bull
    nose); pencil_passes: 1 (pencil) or more (multi-pencil, outward, `stepover` apart or the cusp's spacing); 0 with
    region 'rest': as many as cover the rest (clean-up: up each flank to the strip's edge).
    pattern 'spiral': from the region's centre, spiral_direction 'outward' | 'inward'. slope_range: (min,
    max) deg, cut only where the surface slope lies in it (default all).
    forward_step: 'tolerance' (default: the fewest moves within +-chord_tolerance of the exact tool path, lean
    passes fitted in the kernel) | 'sample' (a point every sample_step, thinned above only; before 2026-12); arcs:
    G2/G3 in the pass's plane (XZ/YZ, rasters at 0/90 deg) with 'tolerance', where the post writes K (not
    linuxcnc: lines there, with a warning).
    verify_cusp: cut the passes in the stock simulation and add partial passes where the simulated cusp exceeds
    `cusp` (the op's VerifyCusp), any stepover_mode (offset3d: the extra passes are level sets
    of its field between two loops), zigzag or oneway over the box.
    Feeds in mm/min. tool_controller (with `job`): one of the Job's tool controllers to cut with instead of a new
    one (several ops, one tool: one controller, no tool change between them); its tool and feeds must be the
    ones the call names (checked, not dropped). label: the op's label (in the Job and in its G-code; None: the
    op's own). progress: True (progress bar / text lines), False (quiet), or a callable
    `f(fraction) -> bool` returning False to cancel.
    Depths (app.surface_passes, as the op's panel): stepover_percent (of the tool diameter, in (0, 100], instead
    of `stepover`); final_depth (mm, no tool tip below it); finish_passes (1-50: the first ones leave
    stock_to_leave + k x finish_step_down, the last stock_to_leave); start_point (x, y): each pass set begins at
    the raster's end nearest it.
    The whole tool (app.tool_assembly, docs/holders.md): holder (a name from TMM's holder library, or
    'tool_controller': the holder set on the job's tool controller (set_holder); None: the tool controller's when
    `job` is given and its tool controller carries one, else the cutter alone), stick_out (mm from the holder's face to the tip; None: the ToolBit's Length minus 3 shank diameters),
    shank_clearance and holder_clearance (mm, default 1), holder_collision 'lift' (the tool rises where the shank
    or holder would come closer, material is left there: the op's HolderReport) | 'leave_out' (not cut there).
    """
    args = dict(locals())  # the call's arguments by name, as the op's stages declare them
    from tmm_workbench.app import op_surface, stages
    from tmm_workbench.core.strategies.surface.params import SurfaceParams

    if stepover is None and str(stepover_mode).lower() == "stepover" and stepover_percent is None:
        args["stepover"] = DEFAULT_STEPOVER
    values = stages.api_values(op_surface.STAGES, SurfaceParams, args, model)
    return run("TMM_Surface", model, job=job, tool=tool, diameter=diameter, corner_radius=corner_radius,
               safe_height=safe_height, clearance_height=clearance_height, horiz_feed=horiz_feed, vert_feed=vert_feed,
               spindle_speed=spindle_speed, post=post, gcode_path=gcode_path, fcstd_path=fcstd_path,
               doc_name=doc_name, progress=progress, tool_controller=tool_controller, label=label, **values)
