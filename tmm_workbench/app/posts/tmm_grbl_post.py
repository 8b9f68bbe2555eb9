"""TMM's fast grbl post: the G-code FreeCAD's grbl post writes (the same words, rounding, preamble, arcs with
I J K, M6 commented out unless --tool-change; the header names this post), 6-7x faster on large surface
jobs (docs/posts.md). Same arguments (--precision, --line-numbers, --no-comments, --no-header, --inches,
--tool-change, --wait-for-spindle, --return-to, --bcnc, --preamble, --postamble; --translate_drill is
accepted and ignored: drill cycles are written as they are). All logic lives in
tmm_workbench.app.gcode_dialects; no module state is kept between exports (FreeCAD reloads posts).
"""
from tmm_workbench.app import gcode_dialects as _dialects
from tmm_workbench.app import gcode_fast as _fast
from tmm_workbench.app import hooks as _hooks

TOOLTIP = """TMM fast grbl post: FreeCAD's grbl G-code (arcs with I J K, M6 commented out), written 6-7x
faster."""
TOOLTIP_ARGS = _fast.parser("grbl").format_help()
MACHINE_NAME = "grbl"
UNITS = "G21"


def export(objectslist, filename, argstring):
    """G-code for `objectslist` (tool controllers and ops); written to `filename` unless it is '-'."""
    return _dialects.export("grbl", objectslist, filename, argstring, __name__)


export = _hooks.reported("post 'tmm_grbl'", export)  # a failure shows a message box in the GUI
