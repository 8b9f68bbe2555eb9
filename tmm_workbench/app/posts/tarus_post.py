"""TMM post for the 5-axis Tarus mill (head A about Z carrying the tilt C): joint moves through the
machine model (tmm_workbench.core.machine.tarus), pivot-compensated by default or tool-tip coordinates for a
control in TCP mode (--tcp), inverse-time feeds on moves that turn A or C, A and C in degrees (never scaled
by --inches). Reads TMM's 5-axis Path representation (X Y Z tip, U V W tool axis; docs/path5.md); plain
3-axis paths post too. A move out of the joint limits is an error and no file is written.
All logic lives in tmm_workbench.core.post.tarus_writer; this module only adapts FreeCAD's post interface
and keeps no state between exports (FreeCAD reloads posts, module globals would leak otherwise).
"""
from tmm_workbench.app import hooks as _hooks
from tmm_workbench.app import post_objects as _objects
from tmm_workbench.core.post import tarus_writer as _writer

TOOLTIP = """TMM Tarus 5-axis post: X Y Z A C joint moves (pivot-compensated, or tool tip with --tcp),
inverse-time feeds for 5-axis moves, joint limit check. Reads TMM's X Y Z + U V W (tool axis) moves."""
TOOLTIP_ARGS = _writer.TOOLTIP_ARGS
MACHINE_NAME = "Tarus TPI-2000"
UNITS = "G21"
LAST_RESULT = None  # the last export's TarusResult (text, cycle time, moves); reset on every export


def export(objectslist, filename, argstring):
    """G-code for `objectslist` (tool controllers and ops); written to `filename` unless it is '-'.
    Raises TmmError (bad arguments, limits, unsupported commands) before anything is written."""
    global LAST_RESULT
    LAST_RESULT = None
    machine, options = _writer.parse_args(argstring)
    result = _writer.write_tarus(_objects.program_from_objects(objectslist), machine, options)
    if filename and filename != "-":
        with open(filename, "w") as f:
            f.write(result.text)
    LAST_RESULT = result
    return result.text


export = _hooks.reported("post 'tarus'", export)  # a failure shows a message box in the GUI
