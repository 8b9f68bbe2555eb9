"""GUI test of reopening saved TMM documents: FreeCAD under Xvfb runs tests/gui/gui_reopen.py (a Job with each TMM op
saved and reopened) and must exit 0; the report view shows no error while they load (no "setAttr failed");
a good Apply's undo step is named after the op."""
from __future__ import annotations

import json
from pathlib import Path

from tests.conftest import SHARED_STL
from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN

HERE = Path(__file__).resolve().parent
TIMEOUT_S = 240
STL = str(SHARED_STL / "sphere_on_plate.stl")


def test_gui_reopen(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_reopen.json"
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_reopen.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_RESULT=str(result), TMM_GUI_STL=STL, QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert len(info["ops"]) == 3, info["ops"]
    # every step of the panel is named after the op, the first one too (not FreeCAD's "AreaOp Operation")
    assert info["undo"][:2] == ["Edit Finish sphere"] * 2, info["undo"]
    assert not any("AreaOp" in step or "TMM operation" in step for step in info["undo"]), info["undo"]
    for key in ("mesh_messages", "face_messages"):
        assert "setAttr failed" not in info[key] and "Traceback" not in info[key], f"{key}:\n{info[key]}"
