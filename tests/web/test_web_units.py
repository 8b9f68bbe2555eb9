"""The web front's parts without a server: the tool path picture's G-code reading (modal words, comments, the moves
before the position is known) and the command's options refused by name."""
from __future__ import annotations

import pytest

from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.web.__main__ import main as web_main
from tmm_workbench.core.preview.toolpath_png import toolpath_of_gcode


def test_gcode_read_back_as_moves():
    text = ("(begin preamble)\nG17 G54 G90\nG0 Z10 (safe: X and Y not known yet)\nG0 X1 Y2 Z10\nG1 Z-1 F300 ; down\n"
            "X4\nY-3.5 Z-1.25\nG0 Z10\nM2\n")
    path = toolpath_of_gcode(text)
    assert [(m.kind, m.x, m.y, m.z) for m in path] == [
        (MoveKind.RAPID, 1, 2, 10), (MoveKind.FEED, 1, 2, -1), (MoveKind.FEED, 4, 2, -1),
        (MoveKind.FEED, 4, -3.5, -1.25), (MoveKind.RAPID, 4, -3.5, 10)]


@pytest.mark.parametrize("args, words", [
    (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], ("--workers", "--scheduler")),
    (["--workers", "-1"], ("--workers", "-1")),
    (["--port", "70000"], ("--port", "70000")),
    (["--timeout", "0"], ("--timeout",)),
    (["--max-upload-mb", "0"], ("--max-upload-mb",)),
])
def test_bad_options_refused_by_name(tmp_path, capsys, args, words):
    assert web_main(["--jobs", str(tmp_path / "jobs"), *args]) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert not (tmp_path / "jobs").exists()


def test_jobs_must_be_a_folder(tmp_path, capsys):
    (tmp_path / "f").write_text("x")
    assert web_main(["--jobs", str(tmp_path / "f")]) == 2 and "not a folder" in capsys.readouterr().err
