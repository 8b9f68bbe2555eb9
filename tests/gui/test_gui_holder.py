"""GUI test of the whole tool's pictures: FreeCAD under Xvfb runs tests/gui/gui_holder.py (the places the holder
left drawn on the op, hidden and shown by its view property; TMM Shortest stick-out's box) and must exit 0 within
the time limit, leaving a non-blank screenshot."""
from __future__ import annotations

import json
from pathlib import Path

from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN, _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui" / "holder_regions.png"
TIMEOUT_S = 240


def test_gui_holder(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_holder.json"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    PNG.unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_holder.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result),
        TMM_TEST_OUT=str(tmp_path), QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert info["regions"] > 10 and info["drawn"] == info["regions"] and info["drawn_hidden"] == 0
    assert "Shortest stick-out" in info["box"], info["box"]
    assert PNG.is_file() and PNG.stat().st_size > 10_000 and not _blank(PNG), PNG
