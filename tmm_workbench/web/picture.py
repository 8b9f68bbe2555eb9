"""The tool path picture of a web job: the planner's G-code read back as moves and drawn over the model by the
core's drawing (core.preview.toolpath_png), so the customer sees the path the machine will run. The job's part
(`plan_part`, a Dask task) plans with the batch's `run_part` and then draws into the finished part's folder (the
picture written beside and renamed, so it too appears only whole); a picture that cannot be drawn leaves the plan
as it is and says why in the row."""
from __future__ import annotations

import os
import re
import uuid
from pathlib import Path

from tmm_workbench.core.toolpath import MoveKind, Toolpath

PICTURE = "toolpath.png"
_WORD = re.compile(r"([GXYZ])\s*([-+]?\d*\.?\d+)")


def toolpath_of_gcode(text: str) -> Toolpath:
    """The G0 / G1 (and G2 / G3, as lines to their end: for drawing) moves of a 3-axis program in absolute mm,
    coordinates modal (a move before all three are known is not drawn: its start is the machine's); comments in
    parentheses or after ';' skipped."""
    path = Toolpath()
    pos: dict[str, float] = {}
    mode = None
    for line in text.splitlines():
        line = re.sub(r"\([^)]*\)", "", line).split(";")[0].upper()
        words = _WORD.findall(line)
        moved = False
        for letter, value in words:
            if letter == "G" and value in ("0", "00", "1", "01", "2", "02", "3", "03"):
                mode = int(value)
            elif letter in "XYZ":
                pos[letter] = float(value)
                moved = True
        if moved and mode is not None and len(pos) == 3:
            path.add(MoveKind.RAPID if mode == 0 else MoveKind.FEED, pos["X"], pos["Y"], pos["Z"])
    return path


def draw(folder: Path, model: Path, gcode_name: str) -> Path:
    """`folder`/toolpath.png: the G-code `gcode_name` of the folder over `model`."""
    from tmm_workbench.core.geometry.mesh import load_stl
    from tmm_workbench.core.preview.toolpath_png import render_toolpath_png

    toolpath = toolpath_of_gcode((folder / gcode_name).read_text(errors="replace"))
    tmp = folder / f".{PICTURE}.{uuid.uuid4().hex[:8]}.png"
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
