"""Headless API for macros and scripts: an STL (or a FreeCAD mesh / Part) to G-code in one call.

Run under FreeCAD (`freecadcmd script.py`, or the GUI's Python console), with the add-on installed:

    from tmm_workbench.app.api import run_surface
    r = run_surface("/path/part.stl", tool="ballend", diameter=6, stepover=0.5, sample_step=0.25,
                    post="linuxcnc", gcode_path="/tmp/part.ngc", fcstd_path="/tmp/part.FCStd")
    print(len(r.toolpath), "moves;", r.gcode.count("\\nG1"), "G1 lines")

The call builds a Path Job (the mesh gets a stand-in box, see model_proxy), a ToolBit and tool
controller, a 'TMM 3-axis Surface' op, recomputes, post-processes and optionally saves. Feeds are
given in mm/min here (FreeCAD stores mm/s). Heights default to the model top + 5 mm (safe) and
+ 10 mm (clearance). A FreeCAD object input is machined in its own document; an STL path opens a
new document `doc_name`. On failure a TmmError with the op's message is raised (a document opened
by the call is closed first).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional, Union

import FreeCAD

from tmm_workbench.app import job as jobs
from tmm_workbench.app import op_surface, posts
from tmm_workbench.app import progress as progress_mod
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.mesh import TriMesh
from tmm_workbench.core.toolpath import Toolpath

TOOL_ALIASES = {"ballend": "ballend", "ball": "ballend", "endmill": "endmill", "flat": "endmill",
                "bullnose": "bullnose", "bull": "bullnose"}
PATTERN_NAMES = {"zigzag": "ZigZag", "oneway": "OneWay"}
BOUNDARY_NAMES = {"model": "Model", "stock": "Stock"}


@dataclass
class SurfaceResult:
    doc: Any             # App.Document holding everything
    job: Any             # the Path Job
    op: Any              # the TMM_Surface operation
    gcode: str           # post-processed G-code
    toolpath: Toolpath   # the core tool path the op's Path was made from
    mesh: TriMesh        # the core mesh that was machined


def run_surface(model: Union[str, os.PathLike, Any], *, tool: str = "ballend", diameter: float = 6.0,
                corner_radius: float = 0.0, stepover: float = 1.0, sample_step: float = 0.5,
                angle_deg: float = 0.0, pattern: str = "zigzag", stock_to_leave: float = 0.0,
                boundary: str = "model", margin: float = 0.0, safe_height: Optional[float] = None,
                clearance_height: Optional[float] = None, horiz_feed: float = 1000.0,
                vert_feed: float = 300.0, spindle_speed: float = 10000.0, post: str = "linuxcnc",
                gcode_path: Optional[Union[str, os.PathLike]] = None,
                fcstd_path: Optional[Union[str, os.PathLike]] = None, doc_name: str = "TMM",
                progress: Union[bool, Callable[[float], bool]] = True) -> SurfaceResult:
    """3-axis raster finishing of `model` (STL path, Mesh::Feature or Part::Feature) to G-code.

    tool: 'ballend' | 'endmill' | 'bullnose' (FreeCAD ToolBit shapes; corner_radius for bullnose).
    pattern: 'zigzag' | 'oneway'; boundary: 'model' | 'stock' XY box grown by `margin` (mm).
    Feeds in mm/min. progress: True (progress bar / text lines), False (quiet), or a callable
    `f(fraction) -> bool` returning False to cancel.
    """
    shape = TOOL_ALIASES.get(str(tool).lower())
    if shape is None:
        raise TmmError(f"tool must be one of {', '.join(sorted(set(TOOL_ALIASES.values())))}, got {tool!r}")
    pattern_name = PATTERN_NAMES.get(str(pattern).lower())
    if pattern_name is None:
        raise TmmError(f"pattern must be 'zigzag' or 'oneway', got {pattern!r}")
    boundary_name = BOUNDARY_NAMES.get(str(boundary).lower())
    if boundary_name is None:
        raise TmmError(f"boundary must be 'model' or 'stock', got {boundary!r}")

    own_doc = isinstance(model, (str, os.PathLike))
    if own_doc and not Path(model).expanduser().is_file():
        raise TmmError(f"STL file not found: {model}")
    doc = FreeCAD.newDocument(doc_name) if own_doc else model.Document
    try:
        result = _build(doc, model, shape, diameter, corner_radius, stepover, sample_step, angle_deg,
                        pattern_name, stock_to_leave, boundary_name, margin, safe_height, clearance_height,
                        horiz_feed, vert_feed, spindle_speed, post, gcode_path, progress)
    except BaseException:
        if own_doc:
            FreeCAD.closeDocument(doc.Name)
        raise
    if fcstd_path:
        Path(fcstd_path).parent.mkdir(parents=True, exist_ok=True)
        doc.saveAs(str(fcstd_path))
    return result


def _build(doc: Any, model: Any, shape: str, diameter: float, corner_radius: float, stepover: float,
           sample_step: float, angle_deg: float, pattern: str, stock_to_leave: float, boundary: str,
           margin: float, safe_height: Optional[float], clearance_height: Optional[float],
           horiz_feed: float, vert_feed: float, spindle_speed: float, post: str,
           gcode_path: Any, progress: Any) -> SurfaceResult:
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    top = jm.job_base.Shape.BoundBox.ZMax
    safe = top + 5.0 if safe_height is None else float(safe_height)
    clearance = max(top + 10.0, safe) if clearance_height is None else float(clearance_height)

    job = jobs.create_job(doc, jm.job_base)
    bit = jobs.make_tool_bit(doc, shape, diameter, corner_radius)
    tc = jobs.set_tool(job, bit, horiz_feed / 60.0, vert_feed / 60.0, spindle_speed)
    values = {"StepOver": stepover, "SampleStep": sample_step, "RasterAngle": angle_deg,
              "Pattern": pattern, "StockToLeave": stock_to_leave, "BoundaryShape": boundary,
              "BoundaryMargin": margin, "SafeHeight": safe, "ClearanceHeight": clearance}
    if jm.stl_file:
        values["StlFile"] = jm.stl_file
    else:
        values["Model"] = jm.link
    op = op_surface.Create(op_surface.OP_NAME, parentJob=job, values=values)
    if post in _job_posts(job):
        job.PostProcessor = post
        job.PostProcessorArgs = posts.DEFAULT_ARGS.get(post, "")

    factory = None
    if callable(progress):
        factory = lambda label: _CallbackProgress(progress)  # noqa: E731
    op.Proxy.progress_enabled = bool(progress)
    with progress_mod.using(factory):
        op.touch()
        doc.recompute()
    if not op.isValid() or op.Proxy.toolpath is None:
        raise TmmError(op.getStatusString() if not op.isValid() else f"{op.Label}: no tool path computed")
    gcode = posts.export(post, [tc, op], gcode_path)
    return SurfaceResult(doc, job, op, gcode, op.Proxy.toolpath, op.Proxy.mesh)


def _job_posts(job: Any) -> list[str]:
    try:
        return list(job.getEnumerationsOfProperty("PostProcessor") or [])
    except Exception:
        return []


class _CallbackProgress(progress_mod.ProgressReporter):
    def __init__(self, callback: Callable[[float], bool]) -> None:
        self.callback = callback

    def __call__(self, fraction: float) -> bool:
        return bool(self.callback(fraction))
