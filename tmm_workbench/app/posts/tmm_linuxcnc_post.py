"""TMM's fast linuxcnc post: the G-code FreeCAD's linuxcnc post writes (the same words, rounding, preamble,
tool change and coolant lines; the header names this post), 6-7x faster on large surface jobs
(docs/posts.md). Same arguments (--precision, --line-numbers, --no-comments, --no-header, --modal,
--axis-modal, --inches, --no-tlo, --preamble, --postamble). All logic lives in
tmm_workbench.app.gcode_dialects; no module state is kept between exports (FreeCAD reloads posts).
"""
from tmm_workbench.app import gcode_dialects as _dialects
from tmm_workbench.app import gcode_fast as _fast
from tmm_workbench.app import hooks as _hooks

TOOLTIP = """TMM fast linuxcnc post: FreeCAD's linuxcnc G-code (3-axis mill, G21/G20, G43 after M6), written
6-7x faster."""
TOOLTIP_ARGS = _fast.parser("linuxcnc").format_help()
MACHINE_NAME = "LinuxCNC"
UNITS = "G21"


def export(objectslist, filename, argstring):
    """G-code for `objectslist` (tool controllers and ops); written to `filename` unless it is '-'."""
    return _dialects.export("linuxcnc", objectslist, filename, argstring, __name__)


export = _hooks.reported("post 'tmm_linuxcnc'", export)  # a failure shows a message box in the GUI
