"""Headless API, 5-axis: the mesh op (`run_mesh5`) and the multipoint op on a face (`run_multipoint`). Imported by
`app.api`, whose names they are (`from tmm_workbench.app.api import run_mesh5`)."""
from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable, Optional, Sequence, Union

import FreeCAD

from tmm_workbench.app.api_args import LENGTH, NON_NEGATIVE, POSITIVE, by_core_name, numbers, option, plain_numbers
from tmm_workbench.app.api_run import StockBox, SurfaceResult, run
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import spec_of
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter


@plain_numbers
def run_mesh5(model: Union[str, os.PathLike, Any, None] = None, *, tool: Union[str, Cutter] = "endmill",
              diameter: float = 6.0, corner_radius: float = 0.0, tolerance: Optional[float] = None,
              feed_angle_deg: float = 0.0, forward_step: Optional[float] = None,
              chord_tolerance: Optional[float] = None, least_tilt_deg: Optional[float] = None,
              tilt_limit_deg: Optional[float] = None, yaw_limit_deg: Optional[float] = None,
              grid_step_deg: Optional[float] = None, zigzag: bool = True, axis_retract: float = 5.0,
              stock: Optional[StockBox] = None, stock_margin: float = 1.0, stock_above: float = 1.0,
              job: Any = None, safe_height: Optional[float] = None, clearance_height: Optional[float] = None,
              horiz_feed: float = 1000.0, vert_feed: float = 300.0, spindle_speed: float = 10000.0,
              tool_controller: Any = None, label: Optional[str] = None, post: Optional[str] = "tarus",
              gcode_path: Optional[Union[str, os.PathLike]] = None,
              fcstd_path: Optional[Union[str, os.PathLike]] = None, doc_name: str = "TMM",
              progress: Union[bool, Callable[[float], bool]] = True, holder: Optional[str] = None,
              stick_out: Optional[float] = None, shank_clearance: Optional[float] = None,
              holder_clearance: Optional[float] = None, simulate_left: bool = True,
              cleanup_diameter: Optional[float] = None) -> SurfaceResult:
    """5-axis finishing of `model` (STL path, Mesh::Feature or Part::Feature) by seed 000's 3D C-space (a 'TMM
    5-axis Mesh' op in a new Job, or in `job`): adaptive passes within `tolerance` (the scallop, mm), the
    posture at every CC point chosen for the Tarus motion time (docs/mesh5.md).

    tool: 'endmill' | 'bullnose' (corner_radius) or a core flat / bull-nose Cutter; a ball or a V-bit is
    refused. feed_angle_deg: the passes' direction seen from above, from +X. least_tilt_deg, tilt_limit_deg:
    the tool axis's inclination from the surface normal, both within the machine's C range; yaw_limit_deg,
    grid_step_deg: the posture grid; None keeps the op's defaults (the seed's 0..45 deg, +-45 deg, 3 deg).
    post 'tarus' | 'apt_cl' | None (a 3-axis post would drop the tool axes: refused). The stock of a new Job
    as run_roughing's (the simulation cuts it). Heights, feeds (mm/min), tool_controller, label, files and
    progress as run_surface; the result is a SurfaceResult (op: the 5-axis mesh op; what was left for clean-up: its
    Mesh5Summary and CleanupRegions).
    The whole tool (holder, stick_out, shank_clearance, holder_clearance) as run_surface: the shank and holder
    bound every C-space, so the tool tilts away where they would come closer, or the place is left for
    clean-up (the op's HolderReport says which).
    simulate_left: the op's SimulateLeft (what the simulated finish leaves above the tolerance outside the strips
    is marked for clean-up too). cleanup_diameter (mm, None: no clean-up): a companion 3-axis ball end mill op of
    that diameter after the 5-axis one in the Job (a TMM Surface, Region 'Rest' from the Job's earlier ops, rest
    tolerance the 5-axis tolerance, passes along the feed angle for a cusp of half of it: it finishes what the
    5-axis op left where the ball reaches, and its RestReport says what stays); it is `result.cleanup`, and the
    G-code holds both ops (a tool change between).
    """
    from tmm_workbench.app import op_mesh5, stages
    from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params

    # (argument, value, Mesh5Params field, op property); a None keeps the op's default
    settings = (("tolerance", tolerance, "tolerance", "Tolerance"),
                ("feed_angle_deg", feed_angle_deg, "feed_angle_deg", "FeedAngle"),
                ("forward_step", forward_step, "forward_step", "ForwardStep"),
                ("chord_tolerance", chord_tolerance, "chord_tol", "ChordTolerance"),
                ("least_tilt_deg", least_tilt_deg, "tilt_min_deg", "LeastTilt"),
                ("tilt_limit_deg", tilt_limit_deg, "tilt_max_deg", "TiltLimit"),
                ("yaw_limit_deg", yaw_limit_deg, "yaw_limit_deg", "YawLimit"),
                ("grid_step_deg", grid_step_deg, "grid_step_deg", "GridStep"))
    numbers(**{arg: (value, spec_of(Mesh5Params, field)) for arg, value, field, _ in settings},
            axis_retract=(axis_retract, NON_NEGATIVE),
            cleanup_diameter=(cleanup_diameter, POSITIVE))  # the tool, stock, heights and feeds: run's
    given = [(field, prop, value) for _, value, field, prop in settings if value is not None]
    Mesh5Params(**{field: value for field, _, value in given}).grid()  # the tilts within the machine's range
    values: dict[str, Any] = {"FeedAngle": feed_angle_deg, "ZigZag": bool(zigzag), "AxisRetract": axis_retract,
                              "SimulateLeft": bool(simulate_left)}
    values.update({prop: value for _, prop, value in given})
    values.update(stages.api_values(op_mesh5.TOOL_STAGES, Mesh5Params, dict(
        holder=holder, stick_out=stick_out, shank_clearance=shank_clearance, holder_clearance=holder_clearance), model))
    later = cleanup_diameter is not None   # the posting and saving wait for the clean-up op
    r = run(op_mesh5.OP_NAME, model, job=job, tool=tool, diameter=diameter, corner_radius=corner_radius, stock=stock,
            stock_margin=stock_margin, stock_above=stock_above, safe_height=safe_height,
            clearance_height=clearance_height, horiz_feed=horiz_feed, vert_feed=vert_feed,
            spindle_speed=spindle_speed, post=None if later else post, gcode_path=None if later else gcode_path,
            fcstd_path=None if later else fcstd_path, doc_name=doc_name, progress=progress,
            tool_controller=tool_controller, label=label, **values)
    if not later:
        return r
    try:
        return _with_cleanup(r, float(cleanup_diameter), feed_angle_deg, horiz_feed, vert_feed, spindle_speed, post,
                             gcode_path, fcstd_path, progress)
    except BaseException:
        if job is None and isinstance(model, (str, os.PathLike)):   # the document run_mesh5 opened
            FreeCAD.closeDocument(r.doc.Name)
        raise


def _with_cleanup(r: SurfaceResult, diameter: float, angle: float, horiz_feed: float, vert_feed: float,
                  spindle_speed: float, post: Optional[str], gcode_path: Any, fcstd_path: Any,
                  progress: Any) -> SurfaceResult:
    """The 5-axis result `r` with its companion ball clean-up op (run_mesh5's cleanup_diameter) after it in the
    Job, both posted together and the document saved."""
    from tmm_workbench.app import posts
    from tmm_workbench.app.api_surface import run_surface
    from tmm_workbench.core.strategies.mesh5.cleanup import ball_stepover

    tol = float(r.op.Tolerance.Value)
    c = run_surface(None, job=r.job, tool="ballend", diameter=diameter, stepover=ball_stepover(0.5 * diameter, tol),
                    angle_deg=angle, region="rest", rest_tolerance=tol, horiz_feed=horiz_feed, vert_feed=vert_feed,
                    spindle_speed=spindle_speed, post=None, progress=progress)
    gcode = posts.export(post, [r.op.ToolController, r.op, c.op.ToolController, c.op], gcode_path) if post else ""
    if fcstd_path:
        Path(fcstd_path).parent.mkdir(parents=True, exist_ok=True)
        r.doc.saveAs(str(fcstd_path))
    return replace(r, gcode=gcode, cleanup=c.op)




# --- 5-axis multipoint ---------------------------------------------------------------------------
POST_SUFFIXES = {"tarus": ".tarus.ngc", "apt_cl": ".apt"}


@dataclass
class MultipointResult:
    doc: Any                  # App.Document holding everything
    job: Any                  # the Path Job
    op: Any                   # the TMM_Multipoint operation
    face: tuple[Any, str]     # (object, "FaceN") the op machines (the Job's model clone)
    toolpath: Toolpath        # the op's linked tool path (what its Path encodes)
    segments: list            # the strategy's cut segments the tool path links (core.segments.CutSegment)
    results: Any              # core.multipoint.MultipointResults (per footprint point)
    gcode: dict               # post name -> text
    files: dict               # post name -> written file (when out_dir is given), "fcstd" -> document


@plain_numbers
def run_multipoint(face_source: Any, *, Ro: float = 6.7, Ri: float = 6.0, method: str = "vcrf",
                   side_step: float = 18.0, pass_spacing: Optional[str] = None, forward_step: float = 2.0,
                   feed_angle_deg: float = 90.0, margin: float = 0.0, zigzag: bool = True,
                   scallop: Optional[float] = None,
                   tilt_limit_deg: Optional[float] = None,
                   tolerance: Optional[float] = None, tool_shape: str = "round_insert", axis_retract: float = 5.0,
                   surface_extension: float = 0.0, footprint_anchor: str = "axis",
                   gouge_tolerance: Optional[float] = None,
                   safe_height: Optional[float] = None, clearance_height: Optional[float] = None,
                   horiz_feed: float = 1000.0, vert_feed: float = 300.0, spindle_speed: float = 10000.0,
                   posts: Sequence[str] = ("tarus", "apt_cl"), out_dir: Optional[Union[str, os.PathLike]] = None,
                   name: str = "multipoint", fcstd_path: Optional[Union[str, os.PathLike]] = None,
                   doc_name: str = "TMM5", progress: Union[bool, Callable[[float], bool]] = True,
                   holder: Optional[str] = None, stick_out: Optional[float] = None,
                   shank_clearance: Optional[float] = None, holder_clearance: Optional[float] = None,
                   holder_collision: Optional[str] = None) -> MultipointResult:
    """5-axis multipoint finishing (seed 001) of one Bézier/B-spline face, to G-code for each post.

    face_source: a Bézier control net (array (m+1, n+1, 3), mm), a Part.BezierSurface / BSplineSurface
    (both machined in a new document `doc_name`), or an (object, "FaceN") pair (machined in the object's
    document). Tool: Ro, Ri of the torus (Ro = 0: ball end mill D = 2 Ri; the ToolBit is a bull-nose
    D = 2 (Ro + Ri), corner Ri). method 'vcrf' | 'drd'; tool_shape 'round_insert' (the seed's
    torus, hollow centre) | 'bull_nose' (plus its flat bottom).
    pass_spacing 'scallop' (each pass at the largest side step whose simulated scallop with the pass before
    is at most `scallop` mm; side_step is the first guess) | 'even' (passes spread evenly, at most side_step
    apart) | 'fixed' (side_step apart from the start edge, a last pass on the far edge: the seed's footprint).
    None: 'scallop', as a new op in the GUI (`scallop` None: the op's default height). Where the scallop
    cannot be held (the tool does not reach the face) the op machines what it reaches and warns: the areas
    are `result.op.Proxy.placement.unreached` (core LeftArea), its ContactSummary says how many.
    tilt_limit_deg, tolerance: None keeps the core's defaults (45 deg, 1e-3 mm). gouge_tolerance: the deepest
    cut allowed between consecutive positions, positions inserted where a move cuts deeper (None: 0.005 mm;
    0: not checked).
    surface_extension (mm, 0: off): position against the face continued past its edges (checked against
    the real face); footprint_anchor 'axis' (seed 001: the pre-tilt axis on the footprint point) | 'tip'
    (the tilted tip on it).
    Heights default to the face's or the Job stock's top, whichever is higher, + 5 mm (safe, for the tool's
    lowest point) and + 10 mm (clearance).
    The whole tool (app.tool_assembly, docs/holders.md): holder (a name from TMM's holder library; None: the
    cutter alone), stick_out, shank_clearance, holder_clearance as run_surface; holder_collision 'tilt' (the
    default: the tool tilts away from the face within tilt_limit_deg and the Tarus's C limits, positions no
    tilt clears are left out, the pass split there) | 'leave_out' (not cut where they would come closer). What
    was done: the op's HolderReport, `result.op.Proxy` diagnostics.
    Feeds in mm/min. Each post's output goes to out_dir/<name><suffix> (tarus: .tarus.ngc, apt_cl: .apt,
    others .<post>.ngc) when out_dir is given. On failure a TmmError with the op's message is raised (a
    document opened by the call is closed first).
    """
    whole_tool = dict(holder=holder, stick_out=stick_out, shank_clearance=shank_clearance,
                      holder_clearance=holder_clearance, holder_collision=holder_collision)
    from tmm_workbench.app import op_multipoint, stages
    from tmm_workbench.app import posts as posts_mod
    from tmm_workbench.core.strategies.multipoint import MultipointParams

    method_name = option("method", method, by_core_name(op_multipoint.METHODS))
    shape_name = option("tool_shape", tool_shape, by_core_name(op_multipoint.TOOL_SHAPES))
    anchor_name = option("footprint_anchor", footprint_anchor, by_core_name(op_multipoint.ANCHORS))
    if pass_spacing is None:  # the README's and the new op's default: the side step from the scallop
        pass_spacing = "scallop"
    spacing_name = option("pass_spacing", pass_spacing, by_core_name(op_multipoint.PASS_SPACINGS))
    numbers(Ro=(Ro, NON_NEGATIVE), Ri=(Ri, NON_NEGATIVE),
             side_step=(side_step, spec_of(MultipointParams, "side_step")),
             forward_step=(forward_step, spec_of(MultipointParams, "forward_step")),
             scallop=(scallop, spec_of(MultipointParams, "scallop")),
             feed_angle_deg=(feed_angle_deg, spec_of(MultipointParams, "feed_angle_deg")), margin=(margin, LENGTH),
             tilt_limit_deg=(tilt_limit_deg, spec_of(MultipointParams, "beta_max_deg")),
             tolerance=(tolerance, spec_of(MultipointParams, "tol")),
             axis_retract=(axis_retract, NON_NEGATIVE),
             surface_extension=(surface_extension, spec_of(MultipointParams, "extend")),
             gouge_tolerance=(gouge_tolerance, spec_of(MultipointParams, "between_tol")))  # heights, feeds: run's
    if Ro + Ri <= 0:
        raise TmmError("the tool has no size: Ro + Ri must be > 0")
    cutter = Cutter.flat(2 * Ro) if Ri == 0 else Cutter.torus(Ro, Ri)  # a flat one is refused by the op
    values: dict[str, Any] = {
        "Method": method_name, "ToolShape": shape_name, "SideStep": side_step, "ForwardStep": forward_step,
        "FeedAngle": feed_angle_deg, "BoundaryMargin": margin, "ZigZag": bool(zigzag), "AxisRetract": axis_retract,
        "SurfaceExtension": surface_extension, "FootprintAnchor": anchor_name, "PassSpacing": spacing_name}
    for prop, value in (("TiltLimit", tilt_limit_deg), ("Tolerance", tolerance), ("GougeTolerance", gouge_tolerance),
                        ("Scallop", scallop)):
        if value is not None:
            values[prop] = value
    values.update(stages.api_values(op_multipoint.TOOL_STAGES, MultipointParams, whole_tool, face_source))
    out = Path(out_dir) if out_dir else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    targets = {post: out / f"{name}{POST_SUFFIXES.get(post, f'.{post}.ngc')}" if out is not None else None
               for post in posts}
    first = posts[0] if posts else None
    r = run("TMM_Multipoint", face_source, tool=cutter, safe_height=safe_height, clearance_height=clearance_height,
            horiz_feed=horiz_feed, vert_feed=vert_feed, spindle_speed=spindle_speed, post=first,
            gcode_path=targets.get(first), fcstd_path=fcstd_path, doc_name=doc_name, progress=progress, **values)
    gcode = {first: r.gcode} if first else {}
    for post in posts[1:]:
        gcode[post] = posts_mod.export(post, [r.op.ToolController, r.op], targets[post])
    files: dict[str, Path] = {post: target for post, target in targets.items() if target is not None}
    if fcstd_path:
        files["fcstd"] = Path(fcstd_path)
    p = r.op.Proxy
    clone, subs = r.op.Base[0]
    return MultipointResult(r.doc, r.job, r.op, (clone, subs[0]), p.toolpath, p.segments, p.results, gcode, files)


# --- stock simulation ----------------------------------------------------------------------------
