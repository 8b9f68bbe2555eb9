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
    return job


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
