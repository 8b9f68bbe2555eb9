"""GUI test of a new user's first steps: FreeCAD under Xvfb runs tests/gui/gui_first_steps.py (grey op buttons that say
why, TMM's toolbar without FreeCAD's Job, Job from mesh / STL opening the Job's panel with the stock shown and a ball
end mill with feeds) and must exit 0, leaving a non-blank screenshot."""
from __future__ import annotations

import json
from pathlib import Path

from tests.conftest import SHARED_STL
from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN, _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui" / "first_job_panel.png"  # docs/gui keeps a copy
TIMEOUT_S = 180
STL = str(SHARED_STL / "sphere_on_plate.stl")


def test_gui_first_steps(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_first_steps.json"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    PNG.unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_first_steps.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result), TMM_GUI_STL=STL,
        QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert info["op_without_job"][0] is False and "create one first" in info["op_without_job"][1], info
    assert "Job" not in info["path_toolbar"], info["path_toolbar"]
    assert info["job_panel_open"] and info["stock_visible"], info
    shape, diameter, feed, plunge, rpm = info["tool"]
    assert "ballend" in shape and diameter == 6.0 and feed > 0 and plunge > 0 and rpm > 0, info["tool"]
    assert info["bounds"] and all(not shown and "stand-in" in text for _, text, shown in info["bounds"]), info
    assert info["panel_closed"] and info["op_with_job"] and info["dead_wrappers_kept"] == [], info
    assert PNG.is_file() and PNG.stat().st_size > 10_000 and not _blank(PNG)
