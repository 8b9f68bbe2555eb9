"""The tool path picture of a web job: the planner's G-code read back as moves and drawn over the model by the
core's drawing (core.preview.toolpath_png), so the customer sees the path the machine will run. The job's part
(`plan_part`, a Dask task) plans with the batch's `run_part` and then draws into the finished part's folder (the
picture written beside and renamed, so it too appears only whole); a picture that cannot be drawn leaves the plan
as it is and says why in the row."""
from __future__ import annotations

import os
import shutil
import uuid
from pathlib import Path

from tmm_workbench.core.preview.toolpath_png import toolpath_of_gcode

PICTURE = "toolpath.png"


def draw(folder: Path, model: Path, gcode_name: str) -> Path:
    """`folder`/toolpath.png: the G-code `gcode_name` of the folder over `model`; the planner's own picture of it
    (`<name>_toolpath.png`, drawn the same way) when it wrote one."""
    from tmm_workbench.core.geometry.mesh import load_stl
    from tmm_workbench.core.preview.toolpath_png import render_toolpath_png

    tmp = folder / f".{PICTURE}.{uuid.uuid4().hex[:8]}.png"
    planned = folder / f"{Path(gcode_name).stem}_toolpath.png"
    if planned.is_file():
        shutil.copyfile(planned, tmp)
    else:
        toolpath = toolpath_of_gcode((folder / gcode_name).read_text(errors="replace"))
        render_toolpath_png(load_stl(model), toolpath, str(tmp), title="the tool path", size_px=(1400, 650))
    os.replace(tmp, folder / PICTURE)
    return folder / PICTURE


def plan_part(job: str, out_root: str, timeout_s: float, model: str, gcode_name: str) -> dict:
    """The batch part planned (batch.part.run_part) and, when it made G-code, its tool path picture."""
    from tmm_workbench.batch.part import run_part

    row = run_part(job, out_root, timeout_s)
    folder = Path(row.get("folder", ""))
    if (folder / gcode_name).is_file() and not (folder / PICTURE).is_file():
        try:
            draw(folder, Path(model), gcode_name)
        except Exception as exc:   # a drawing problem never fails the plan
            row["picture"] = f"no tool path picture: {type(exc).__name__}: {exc}"
    return row
