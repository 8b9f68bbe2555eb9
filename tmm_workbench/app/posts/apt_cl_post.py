"""TMM post for APT CL files (seed 000 Appendix B style): GOTO/x,y,z,i,j,k with the tool tip and the unit
tool axis, CUTTER, TOOLNO, LOADTL, FEDRAT, SPINDL, RAPID, COOLNT records. Reads TMM's 5-axis Path
representation (X Y Z tip, U V W tool axis; docs/path5.md); plain 3-axis paths post with axis 0,0,1.
All logic lives in tmm_workbench.core.post.apt_writer; this module keeps no state between exports.
"""
from tmm_workbench.core.post import apt_writer as _writer
from tmm_workbench.app import hooks as _hooks
from tmm_workbench.app import post_objects as _objects

TOOLTIP = """TMM APT CL post: GOTO/x,y,z,i,j,k (tool tip and tool axis), CUTTER, LOADTL, FEDRAT, SPINDL."""
TOOLTIP_ARGS = _writer.TOOLTIP_ARGS
MACHINE_NAME = "APT CL"
UNITS = "G21"


def export(objectslist, filename, argstring):
    """APT CL text for `objectslist`; written to `filename` unless it is '-'. TmmError for what it
    cannot write, before anything is written."""
    options = _writer.parse_args(argstring)
    text = _writer.write_apt(_objects.program_from_objects(objectslist), options)
    if filename and filename != "-":
        with open(filename, "w") as f:
            f.write(text)
    return text


export = _hooks.reported("post 'apt_cl'", export)  # a failure shows a message box in the GUI
