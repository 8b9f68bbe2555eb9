"""A user session at the TMM Surface panel under Xvfb (tests/gui/gui_user_input.py): typed values keep their
unit and range, values above the work limit are refused before any compute, zero feeds and failures are shown
in the status line and in message boxes; each step leaves a non-blank screenshot in docs/gui."""
from __future__ import annotations

import json
from pathlib import Path

from tests.conftest import SHARED_STL
from tests.freecad import fc_process
from tests.gui.test_gui_smoke import _blank

HERE = Path(__file__).resolve().parent
SHOTS = fc_process.ROOT / "out" / "gui"  # docs/gui keeps a copy of each
FREECAD = fc_process.find("freecad", "FreeCAD")
XVFB_RUN = fc_process.find("xvfb-run")
TIMEOUT_S = 150
STL = str(SHARED_STL / "sphere_on_plate.stl")
STEPS = ("01_bare_number_is_mm", "02_negative_refused", "03_work_limit_refused", "04_status_after_apply",
         "05_stepover_zero_box", "06_missing_stl_box", "07_zero_feed_panel", "08_waterline_limit_refused")


def test_gui_user_input(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_user_input.json"
    for name in STEPS:
        (SHOTS / f"{name}.png").unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_user_input.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_RESULT=str(result), TMM_GUI_SHOTS=str(SHOTS), TMM_GUI_STL=STL,
        QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    # what the session asserted, checked again from its record
    assert abs(info["sample_raw"] - 1.5) < 1e-12 and abs(info["sample_prop"] - 1.5) < 1e-12, info
    assert "CL points" in info["limit_refused"] and "Not computed" in info["box_limit"], info
    assert "moves" in info["status_apply"][0], info["status_apply"]
    assert "file not found" in info["box_missing_stl"] and "Traceback" not in info["report_missing_stl"], info
    assert "HorizFeed must be a feed > 0" in info["status_zero_feed"][0], info["status_zero_feed"]
    assert "SpindleSpeed is 0 rpm" in info["status_zero_feed"][0], info["status_zero_feed"]
    assert "waterline drops and points" in info["wl_refused"] and "Not computed" in info["box_wl_limit"], info
    assert info["box_post"].startswith("post 'tarus': "), info["box_post"]
    for name in STEPS:
        png = SHOTS / f"{name}.png"
        assert png.is_file() and png.stat().st_size > 5_000, png
        assert not _blank(png), f"{png} is blank"
