"""The engine of the headless API (app.api): one TMM op on a model in a Path Job, computed, posted and saved, and
`run`, the one entry for every mesh op by its registry name with its properties as the op's property editor names
them (checked against the op's own declarations: the names, their ranges, their choices).

    from tmm_workbench.app.api_run import run
    r = run("TMM_Surface", "part.stl", tool="ballend", diameter=6, StepOverMode="Cusp", CuspHeight=0.01,
            gcode_path="part.ngc")

`run_surface`, `run_roughing`, `run_waterline` and `run_mesh5` (app.api) are the same with the API's argument names.
"""
from __future__ import annotations

import difflib
import math
import os
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Optional, Union

import FreeCAD

from tmm_workbench.app import face_source, geometry, op_base, posts, registry, tools, work_estimate
from tmm_workbench.app import job as jobs
from tmm_workbench.app import progress as progress_mod
from tmm_workbench.app.api_args import (FEED, LENGTH, NON_NEGATIVE, POSITIVE, SPEED, CallbackProgress,
                                        numbers, option)
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.toolpath import Toolpath
from tmm_workbench.core.tools.cutter import Cutter

MESH_OPS = ("TMM_Surface", "TMM_Roughing", "TMM_Waterline", "TMM_Mesh5")
FACE_OPS = ("TMM_Multipoint",)   # a Bézier / B-spline face (app.face_source), a new document and Job for it
AUTO_POST = "auto"   # run's default post: linuxcnc for a 3-axis op, tarus for a 5-axis one (job.FIVE_AXIS_OPS)


StockBox = tuple[float, float, float, float, float, float]


@dataclass
class SurfaceResult:
    doc: Any             # App.Document holding everything
    job: Any             # the Path Job
    op: Any              # the TMM op (Surface; also what run_roughing and run_waterline return)
    gcode: str           # post-processed G-code
    toolpath: Toolpath   # the core tool path the op's Path was made from
    mesh: TriMesh        # the core mesh that was machined
    cleanup: Any = None  # run_mesh5's companion clean-up op (a TMM Surface, Region 'Rest'), when asked for


@contextmanager
def api_document(own: bool, name: str, existing: Any, fcstd_path: Any) -> Iterator[Any]:
    """The document an API call works in: a new one named `name` (`own`; closed again when the call fails, so
    no half-made document is left) or `existing`; saved to `fcstd_path` (when given) once the call succeeded."""
    doc = FreeCAD.newDocument(name) if own else existing
    try:
        yield doc
    except BaseException:
        if own:
            FreeCAD.closeDocument(doc.Name)
        raise
    if fcstd_path:
        Path(fcstd_path).parent.mkdir(parents=True, exist_ok=True)
        doc.saveAs(str(fcstd_path))


def heights(job: Any, model_top: float, safe_height: Optional[float], clearance_height: Optional[float]) -> dict:
    """SafeHeight and ClearanceHeight: given, or the top of the model or of the Job's stock, whichever is
    higher, + 5 mm and + 10 mm."""
    top = max(model_top, stock_top(job))
    safe = top + 5.0 if safe_height is None else float(safe_height)
    clearance = max(top + 10.0, safe) if clearance_height is None else float(clearance_height)
    return {"SafeHeight": safe, "ClearanceHeight": clearance}


def bit(doc: Any, shape: Union[str, Cutter], diameter: float, corner_radius: float) -> Any:
    return (tools.bit_for_cutter(doc, shape) if isinstance(shape, Cutter)
            else tools.make_tool_bit(doc, shape, diameter, corner_radius))


def model_values(jm: jobs.JobModel) -> dict:
    """The op's model properties for a prepared model: its STL file or its object."""
    return {"StlFile": jm.stl_file} if jm.stl_file else {"Model": jm.link}


def post_op(doc: Any, job: Any, tc: Any, op: Any, post: Optional[str], gcode_path: Any,
            progress: Any) -> SurfaceResult:
    """The Job's post set to `post` (when it offers it), the op computed, its G-code (with its tool controller;
    none without a post)."""
    if post:
        jobs.choose_post(job, post)  # when the Job offers it
    compute(op, progress)
    gcode = posts.export(post, [tc, op], gcode_path) if post else ""
    return SurfaceResult(doc, job, op, gcode, op.Proxy.toolpath, getattr(op.Proxy, "mesh", None))


def stock_top(job: Any) -> float:
    stock = getattr(job, "Stock", None)
    return float(stock.Shape.BoundBox.ZMax) if stock is not None and not stock.Shape.isNull() else -math.inf


def compute(op: Any, progress: Union[bool, Callable[[float], bool]]) -> None:
    """Recomputes the op with the caller's progress (a callback, True for the default reporter, False for
    none); raises TmmError with the op's status when it fails or computes no tool path."""
    factory = None
    if callable(progress):
        factory = lambda label: CallbackProgress(progress)  # noqa: E731
    op.Proxy.progress_enabled = bool(progress)
    with progress_mod.using(factory):
        op.touch()
        # the whole document: whatever an earlier op depends on and was touched since (on FreeCAD 1.1, a ToolBit
        # whose dimension changed rebuilds its shape body after a recompute, touching its ops' inputs again;
        # compat.settle_toolbit rebuilds it before an op uses it) is brought up to date with this op
        op.Document.recompute()
    if op.isValid() and getattr(op.Proxy, "cancelled", False):
        raise TmmError(f"{op.Label}: tool path computation cancelled")
    if not op.isValid() or op.Proxy.toolpath is None:
        raise TmmError(op.getStatusString() if not op.isValid() else f"{op.Label}: no tool path computed")


def stock_box_checked(stock: Any) -> StockBox:
    from tmm_workbench.core.params import check_finite

    try:
        box = tuple(float(v) for v in stock)
    except (TypeError, ValueError):
        raise TmmError(f"stock must be (xmin, ymin, zmin, xmax, ymax, zmax) in mm, got {stock!r}") from None
    if len(box) != 6:
        raise TmmError(f"stock must be (xmin, ymin, zmin, xmax, ymax, zmax) in mm, got {stock!r}")
    check_finite("stock", box)
    if not (box[3] > box[0] and box[4] > box[1] and box[5] > box[2]):
        raise TmmError(f"stock box is empty: x {box[0]:g}..{box[3]:g}, y {box[1]:g}..{box[4]:g}, "
                       f"z {box[2]:g}..{box[5]:g} mm")
    return box  # type: ignore[return-value]


def base_bounds(base: Any) -> Any:
    """The bounds of a stock's Base: its shape's, or (the Job's Model group: it has no shape of its own in a GUI
    session) those of the shapes in it, as FreeCAD's stock from the base takes them."""
    if hasattr(base, "Shape"):
        return base.Shape.BoundBox
    bb = FreeCAD.BoundBox()
    for o in getattr(base, "Group", []):
        bb.add(o.Shape.BoundBox)
    return bb if bb.isValid() else None


def set_stock(job: Any, stock: Optional[StockBox], margin: float, above: float) -> None:
    """The Job's box stock (FreeCAD's stock from the base, its extents set): `stock` exactly, or the model's box
    grown by `margin` on the sides and `above` on top."""
    s = job.Stock
    bb = base_bounds(s.Base) if getattr(s, "Base", None) is not None else None
    if bb is None or not hasattr(s, "ExtXneg"):
        raise TmmError(f"Job '{job.Label}': its stock is not FreeCAD's stock from the base; set it in the Job")
    if stock is None:
        ext = (margin, margin, 1.0, margin, margin, above)
    else:
        ext = (bb.XMin - stock[0], bb.YMin - stock[1], bb.ZMin - stock[2],
               stock[3] - bb.XMax, stock[4] - bb.YMax, stock[5] - bb.ZMax)
    for name, v in zip(("ExtXneg", "ExtYneg", "ExtZneg", "ExtXpos", "ExtYpos", "ExtZpos"), ext):
        setattr(s, name, v)
    job.Document.recompute()


def add_tool(job: Any, bit: Any, horiz_feed_mm_s: float, vert_feed_mm_s: float, spindle_speed: float) -> Any:
    """A further tool controller in `job` for `bit` (the next tool number)."""
    from tmm_workbench.app.compat import PathToolController

    FreeCAD.setActiveDocument(job.Document.Name)
    number = max([int(t.ToolNumber) for t in job.Tools.Group] + [0]) + 1
    tc = PathToolController.Create(f"TC: {bit.Label}", bit, number)
    job.Proxy.addToolController(tc)
    tc.HorizFeed = horiz_feed_mm_s
    tc.VertFeed = vert_feed_mm_s
    tc.SpindleSpeed = float(spindle_speed)
    return tc


def run_op(op_name: str, model: Any, job: Any, values: dict, stock_ext: tuple, shape: Union[str, Cutter],
           diameter: float, corner_radius: float, safe_height: Optional[float], clearance_height: Optional[float],
           horiz_feed: float, vert_feed: float, spindle_speed: float, post: Optional[str], gcode_path: Any,
           fcstd_path: Any, doc_name: str, progress: Any, tool_controller: Any = None,
           label: Optional[str] = None) -> SurfaceResult:
    """The op (property `values`) in a new Job for `model` (a mesh op's box stock; a face op's face) or in `job`
    with a further tool controller (or `tool_controller`, one of the Job's: run checked it); computed, posted,
    saved. A document opened here is closed on failure."""
    job = getattr(job, "job", None) or job
    if job is None and model is None:
        raise TmmError("model: give an STL path, a Mesh or a Part object (or a job to add the op to)")
    face = op_name in FACE_OPS
    own_doc = job is None and (face_source.owns_document(model) if face else isinstance(model, (str, os.PathLike)))
    if own_doc and not face and not Path(model).expanduser().is_file():
        raise TmmError(f"STL file not found: {model}")
    existing = None if own_doc else (job.Document if job is not None else
                                     (face_source.face_pair(model)[0] if face else model).Document)
    with api_document(own_doc, doc_name, existing, fcstd_path) as doc:
        values = dict(values)
        if job is None:
            job, model_props, top = (face_source.face_job(doc, model) if face else
                                     new_mesh_job(doc, model, stock_ext))
            values.update(model_props)
            tc = jobs.set_tool(job, bit(doc, shape, diameter, corner_radius), horiz_feed / 60.0,
                               vert_feed / 60.0, spindle_speed)
        else:  # the Job's stock and model stay; the op machines `model` when one is given
            values.update(mesh_values(model))
            top = max(m.Shape.BoundBox.ZMax for m in job.Model.Group)
            tc = tool_controller or add_tool(job, bit(doc, shape, diameter, corner_radius), horiz_feed / 60.0,
                                             vert_feed / 60.0, spindle_speed)
        values.update(heights(job, top, safe_height, clearance_height))
        values["ToolController"] = tc
        op = registry.create(op_name, job, values)
        if label:   # before it computes: its Path (and G-code) opens with its label
            op.Label = label
        result = post_op(doc, job, tc, op, post, gcode_path, progress)
    return result


def new_mesh_job(doc: Any, model: Any, stock_ext: Optional[tuple]) -> tuple[Any, dict, float]:
    """A Job around the mesh model (its stand-in box for a mesh), its stock set when asked, the op's model
    properties and the model's top."""
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    job = jobs.create_job(doc, jm.job_base)
    if stock_ext is not None:
        set_stock(job, *stock_ext)
    return job, model_values(jm), max(m.Shape.BoundBox.ZMax for m in job.Model.Group)


def mesh_values(model: Any) -> dict:
    """The op's model properties for `model` in an existing Job (None: the Job's model)."""
    if isinstance(model, (str, os.PathLike)):
        geometry.mesh_from_stl(model)  # a clear error for a missing or bad file
        return {"StlFile": str(Path(model).expanduser().resolve())}
    return {} if model is None else {"Model": model}


def proxy_class(op: str) -> type:
    """The proxy class of the op registered as `op` (its declarations: PROPERTIES, CHOICES, PARAMS)."""
    try:
        module = registry.entry(op).app()
    except KeyError as exc:
        raise TmmError(str(exc.args[0])) from None
    return next(v for v in vars(module).values() if isinstance(v, type) and issubclass(v, op_base.TmmOp)
                and v.__module__ == module.__name__)


def check_properties(op: str, properties: dict[str, Any]) -> None:
    """Each property named as the op declares it, a choice among its choices, a number within its range."""
    cls = proxy_class(op)
    rows = {row.name for row in cls.PROPERTIES}
    for name, value in properties.items():
        if name not in rows:
            close = difflib.get_close_matches(name, rows, 1)
            hint = f" (did you mean {close[0]}?)" if close else ""
            raise TmmError(f"{op} has no property {name!r}{hint}; its properties: {', '.join(sorted(rows))}")
        choices = cls.CHOICES.get(name)
        if choices is not None and isinstance(value, str):
            option(name, value, {c.lower(): c for c in choices})
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            work_estimate.check_value(cls, name, value if isinstance(value, int) else float(value))


def checked_post(op: str, post: Optional[str]) -> Optional[str]:
    """The post for `op`: AUTO_POST gives linuxcnc for a 3-axis op, tarus for a 5-axis one; a 5-axis op with a
    3-axis post is refused (it would drop the tool axes)."""
    five = op in jobs.FIVE_AXIS_OPS
    if post == AUTO_POST:
        return jobs.FIVE_AXIS_POSTS[0] if five else jobs.DEFAULT_POST
    if five and post is not None and post not in jobs.FIVE_AXIS_POSTS:
        raise TmmError(f"post {post!r} cannot write the tool axes of {op}: it must be one of "
                       f"{', '.join(jobs.FIVE_AXIS_POSTS)} (or None: not posted)")
    return post


def check_controller(tc: Any, job: Any, shape: Union[str, Cutter], diameter: float, corner_radius: float,
                     feeds: dict[str, float]) -> None:
    """`tc` a tool controller of `job` whose tool and feeds are the ones the call names: several ops of one tool
    share its controller (the G-code changes tools only where the tool changes), and the call's tool arguments
    are checked against it, never dropped for it."""
    job = getattr(job, "job", None) or job
    if job is None:
        raise TmmError("tool_controller: give job= as well (the Job the tool controller belongs to)")
    if tc not in job.Tools.Group:
        raise TmmError(f"tool_controller {getattr(tc, 'Label', tc)!r} is not a tool controller of Job "
                       f"'{job.Label}'")
    has = tools.cutter_from_tool(tc.Tool)
    asked = shape if isinstance(shape, Cutter) else named_cutter(shape, diameter, corner_radius)
    sizes = ("diameter", "corner_radius", "bottom_angle_deg", "taper_angle_deg")
    if not all(math.isclose(getattr(has, k), getattr(asked, k), abs_tol=1e-6) for k in sizes):
        raise TmmError(f"tool_controller {tc.Label!r} holds a {has.describe()}, the call asks for a "
                       f"{asked.describe()}: give the controller's tool (or no tool_controller)")
    for name, prop, scale in (("horiz_feed", "HorizFeed", 60.0), ("vert_feed", "VertFeed", 60.0),
                              ("spindle_speed", "SpindleSpeed", 1.0)):
        value = scale * float(getattr(getattr(tc, prop), "Value", getattr(tc, prop)))
        if not math.isclose(value, feeds[name], rel_tol=1e-6, abs_tol=1e-6):
            raise TmmError(f"{name} {feeds[name]:g} is not tool_controller {tc.Label!r}'s {value:g}: give the "
                           f"controller's (or no tool_controller)")


def named_cutter(shape: str, diameter: float, corner_radius: float) -> Cutter:
    """The cutter a tool named by shape ('ballend', 'bullnose', 'endmill') and size is."""
    return (Cutter.ball(diameter) if shape == "ballend" else
            Cutter.bull(diameter, corner_radius) if shape == "bullnose" and corner_radius > 0 else
            Cutter.flat(diameter))


def check_tool_taken(op: str, shape: Union[str, Cutter], diameter: float, corner_radius: float) -> None:
    """The op's strategy's own tool check (core check_tool, where it has one), before a document is made."""
    check = getattr(registry.entry(op).core(), "check_tool", None)
    if check is None:
        return
    check(shape if isinstance(shape, Cutter) else named_cutter(shape, diameter, corner_radius))


def run(op: str, model: Any = None, *, job: Any = None, tool: Union[str, Cutter] = "ballend", diameter: float = 6.0,
        corner_radius: float = 0.0, stock: Optional[StockBox] = None, stock_margin: Optional[float] = None,
        stock_above: Optional[float] = None, safe_height: Optional[float] = None,
        clearance_height: Optional[float] = None, horiz_feed: float = 1000.0, vert_feed: float = 300.0,
        spindle_speed: float = 10000.0, post: Optional[str] = AUTO_POST, gcode_path: Any = None,
        fcstd_path: Any = None, doc_name: str = "TMM", progress: Union[bool, Callable[[float], bool]] = True,
        tool_controller: Any = None, label: Optional[str] = None, **properties: Any) -> SurfaceResult:
    """The op registered as `op` on `model` with `properties` (the op's property names and values: StepOver=0.5,
    Pattern="OneWay"), computed, posted (`post` None: not posted; AUTO_POST: linuxcnc, or tarus for a 5-axis op,
    which takes only tarus or apt_cl), saved (as app.api.run_surface).
    A mesh op (MESH_OPS): `model` an STL path, a Mesh or a Part object (None with `job`: the Job's model), in a new
    Job or added to `job` with its own tool controller (or `tool_controller`, one of the Job's: its tool and feeds
    those the call names); the Job's stock: FreeCAD's default for a new Job unless `stock` (a box) or
    `stock_margin` / `stock_above` (mm around the model) is given. `label`: the op's label (in the Job and in its
    G-code; None: the op's own).
    A face op (FACE_OPS): `model` a face source (app.face_source), in a new Job around it.
    TmmError names a property the op does not have, a choice it does not offer, a number out of its range, an
    argument the op would ignore."""
    if op not in MESH_OPS + FACE_OPS:
        raise TmmError(f"run: op must be one of {', '.join(MESH_OPS + FACE_OPS)}, got {op!r}")
    if op in FACE_OPS:  # a face op's Job is made around its face, with FreeCAD's default stock
        for name, value in (("job", job), ("stock", stock), ("stock_margin", stock_margin),
                            ("stock_above", stock_above)):
            if value is not None:
                raise TmmError(f"{name} is not used by {op}: it machines one face in a new Job around it")
    numbers(diameter=(diameter, POSITIVE), corner_radius=(corner_radius, NON_NEGATIVE),
            stock_margin=(stock_margin, LENGTH), stock_above=(stock_above, LENGTH),
            safe_height=(safe_height, LENGTH), clearance_height=(clearance_height, LENGTH),
            horiz_feed=(horiz_feed, FEED), vert_feed=(vert_feed, FEED), spindle_speed=(spindle_speed, SPEED))
    check_properties(op, properties)
    shape = tool if isinstance(tool, Cutter) else option("tool", tool, tools.SHAPE_ALIASES,
                                                          sorted(set(tools.SHAPE_ALIASES.values())))
    post = checked_post(op, post)
    check_tool_taken(op, shape, diameter, corner_radius)
    if tool_controller is not None:
        check_controller(tool_controller, job, shape, diameter, corner_radius,
                         {"horiz_feed": horiz_feed, "vert_feed": vert_feed, "spindle_speed": spindle_speed})
    if stock is not None:
        stock_box_checked(stock)
    given = stock is not None or stock_margin is not None or stock_above is not None
    stock_ext = (stock, 1.0 if stock_margin is None else stock_margin,
                 1.0 if stock_above is None else stock_above) if given else None
    return run_op(op, model, job, properties, stock_ext, shape, diameter, corner_radius, safe_height,
                  clearance_height, horiz_feed, vert_feed, spindle_speed, post, gcode_path, fcstd_path, doc_name,
                  progress, tool_controller, label)
