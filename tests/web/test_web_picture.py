"""The tool path picture's G-code reading: modal words, comments, the moves before the position is known."""
from __future__ import annotations

from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.web.picture import toolpath_of_gcode


def test_gcode_read_back_as_moves():
    text = ("(begin preamble)\nG17 G54 G90\nG0 Z10 (safe: X and Y not known yet)\nG0 X1 Y2 Z10\nG1 Z-1 F300 ; down\n"
            "X4\nY-3.5 Z-1.25\nG0 Z10\nM2\n")
    path = toolpath_of_gcode(text)
    assert [(m.kind, m.x, m.y, m.z) for m in path] == [
        (MoveKind.RAPID, 1, 2, 10), (MoveKind.FEED, 1, 2, -1), (MoveKind.FEED, 4, 2, -1),
        (MoveKind.FEED, 4, -3.5, -1.25), (MoveKind.RAPID, 4, -3.5, 10)]
