"""Job glue: a Path Job for a mesh, an STL file or a Part object, and its tool controller (ToolBits are
made by app.tools, the one ToolBit map)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

import FreeCAD

from tmm_workbench.app import geometry, hooks, model_proxy
from tmm_workbench.app import compat
from tmm_workbench.app.compat import PathJob
from tmm_workbench.core.errors import TmmError

ModelInput = Union[str, os.PathLike, Any]  # STL path, Mesh::Feature or Part::Feature

@dataclass
class JobModel:
    """What the Job holds (`job_base`) and what the op machines (`link` xor `stl_file`)."""
    job_base: Any
    link: Any = None
    stl_file: Optional[str] = None


def prepare_model(doc: Any, model: ModelInput) -> JobModel:
    """A Part object is a Job model as it is; a mesh or an STL file gets a stand-in box."""
    if isinstance(model, (str, os.PathLike)):
        path = Path(model).expanduser()
        geometry.mesh_from_stl(path)  # a clear error for a missing or bad file (and it is cached)
        return JobModel(model_proxy.create(doc, stl_file=str(path.resolve())), stl_file=str(path.resolve()))
    if not hasattr(model, "TypeId"):
        raise TmmError(f"model must be an STL path, a Mesh object or a Part object, got {type(model).__name__}")
    if model.isDerivedFrom("Mesh::Feature"):
        if model.Mesh.CountFacets == 0:
            raise TmmError(f"mesh object '{model.Label}' has no triangles")
        return JobModel(model_proxy.create(doc, source=model), link=model)
    if hasattr(model, "Shape"):
        if model.Shape.isNull() or not model.Shape.Faces:
            raise TmmError(f"'{model.Label}' has no faces to machine")
        return JobModel(model, link=model)
    raise TmmError(f"'{model.Label}' ({model.TypeId}) is neither a mesh nor a Part shape")


def create_job(doc: Any, base: Any, name: str = "Job") -> Any:
    """A Path Job around `base` (a solid) in `doc`; the Job code needs `doc` to be the active one."""
    FreeCAD.setActiveDocument(doc.Name)
    job = PathJob.Create(name, [base])
    hooks.attach_view("job", job)
    set_default_post(job)
    return job


# --- the tool a Job from a mesh starts with ------------------------------------------------------------
# A ball end mill (what sculptured surfaces are finished with) and its feeds from this table: diameter mm ->
# (feed mm/min, plunge mm/min, spindle rpm), moderate values for a carbide ball in aluminium or plastics (the
# API's defaults for 6 mm). A start the user adjusts to the material and the machine, never a feed of 0.
BALL_FEEDS = {3.0: (600.0, 200.0, 14000.0), 6.0: (1000.0, 300.0, 10000.0), 10.0: (1400.0, 400.0, 8000.0)}
START_BALL_MM = 6.0


def start_tool(job: Any, diameter: float = START_BALL_MM) -> Any:
    """The Job's first tool controller with a ball end mill of `diameter` (a BALL_FEEDS size) and its feeds, in
    place of FreeCAD's default 5 mm end mill at feed 0."""
    from tmm_workbench.app import tools

    if diameter not in BALL_FEEDS:
        raise TmmError(f"start tool diameter must be one of {', '.join(f'{d:g}' for d in BALL_FEEDS)} mm, "
                       f"got {diameter:g}")
    feed, plunge, rpm = BALL_FEEDS[diameter]
    bit = tools.make_tool_bit(job.Document, "ballend", diameter)
    return set_tool(job, bit, feed / 60.0, plunge / 60.0, rpm)


# --- the Job's post: a working one, not FreeCAD's first in the list -------------------------------------
DEFAULT_POST = "linuxcnc"
FIVE_AXIS_POSTS = ("tarus", "apt_cl")  # the first is the default for a Job whose first op is 5-axis
FIVE_AXIS_OPS = ("TMM_Multipoint", "TMM_Mesh5")


def user_default_post() -> str:
    """The post chosen in FreeCAD's preferences (Path/CAM Job: default post processor), '' when none."""
    from tmm_workbench.app.compat import PathPreferences

    return PathPreferences.defaultPostProcessor() or ""


def choose_post(job: Any, post: str) -> bool:
    """Sets the Job's post (with TMM's default arguments) when the Job offers it."""
    from tmm_workbench.app import posts

    try:
        offered = list(job.getEnumerationsOfProperty("PostProcessor") or [])
    except Exception:  # an old Job without the enumeration
        offered = []
    if post not in offered:
        return False
    job.PostProcessor = post
    job.PostProcessorArgs = posts.DEFAULT_ARGS.get(post, "--no-show-editor")
    return True


def set_default_post(job: Any) -> None:
    """A new Job gets linuxcnc unless the user chose a default post: FreeCAD otherwise keeps the first post in
    its list (KineticNCBeamicon2), which fails on our paths."""
    if not user_default_post():
        choose_post(job, DEFAULT_POST)


def post_for_first_op(job: Any, op: Any, op_type: str) -> None:
    """When a 5-axis op is the Job's first op the Job posts with tarus (a 3-axis post cannot write its tool
    axes); a 3-axis op keeps the Job's post, made linuxcnc if it is still FreeCAD's first in the list. A default
    post chosen in the preferences is kept."""
    if any(o.Name != op.Name for o in job.Operations.Group) or user_default_post():
        return
    if op_type in FIVE_AXIS_OPS:
        if job.PostProcessor not in FIVE_AXIS_POSTS:
            choose_post(job, FIVE_AXIS_POSTS[0])
        return
    offered = list(job.getEnumerationsOfProperty("PostProcessor") or [])
    if offered and job.PostProcessor == offered[0] and offered[0] != DEFAULT_POST:
        choose_post(job, DEFAULT_POST)


def set_tool(job: Any, bit: Any, horiz_feed_mm_s: float, vert_feed_mm_s: float,
             spindle_speed: float) -> Any:
    """Put `bit` into the Job's (first) tool controller, replacing the Job's default bit."""
    tc = job.Tools.Group[0]
    old = tc.Tool
    tc.Tool = bit
    if old is not None and old is not bit and hasattr(old, "Proxy"):
        compat.remove_toolbit(old)
    tc.Label = f"TC: {bit.Label}"
    tc.HorizFeed = horiz_feed_mm_s
    tc.VertFeed = vert_feed_mm_s
    tc.SpindleSpeed = float(spindle_speed)
    return tc
