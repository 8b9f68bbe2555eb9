"""The wait a user sees after `run_surface` (FreeCAD's Python; benchmarks/adaptive_end_to_end.py and
benchmarks/cusp_item7_e2e.py): OK to path is run_surface's time less a second linuxcnc post of the op, timed here."""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any


def user_wait(r: Any, total: float, again: Path) -> dict:
    """The row of run_surface's result `r` that took `total` seconds (the op's recompute and its post): moves,
    G-code lines, ok_to_path, post_s (the op posted again to `again`), total; the document is closed."""
    import FreeCAD

    from tmm_workbench.app import posts

    t1 = time.perf_counter()
    posts.export("linuxcnc", [r.op.ToolController, r.op], str(again))
    post_s = time.perf_counter() - t1
    row = dict(moves=len(r.toolpath.moves), lines=len(r.gcode.splitlines()), ok_to_path=total - post_s,
               post_s=post_s, total=total)
    FreeCAD.closeDocument(r.doc.Name)
    return row
