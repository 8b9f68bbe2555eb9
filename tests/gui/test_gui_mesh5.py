"""GUI test of the 5-axis mesh op's panel: FreeCAD under Xvfb runs tests/gui/gui_mesh5.py (the panel opened on
the op the API made, a coarser tolerance and a smaller tilt limit typed, OK) and must exit 0 within the time
limit with the op recomputed from the typed values."""
from __future__ import annotations

import json
from pathlib import Path

from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN

HERE = Path(__file__).resolve().parent
TIMEOUT_S = 240


def test_gui_mesh5_panel(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_mesh5.json"
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_mesh5.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_RESULT=str(result), QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert info["values_after"] == [0.2, 18.0], info
    shown, held, offered = info["holder"]
    assert shown == held == "FromToolController" and "ER16 nut" in offered and "None" in offered, info
    assert info["stick_out"][0] == info["stick_out"][1] == 0.0, info
    assert info["cleanup_marks_view"], info
    assert info["valid"] and info["commands"] > 10, info
    # a tolerance 4x coarser: wider passes; the tilt limit holds (the tilt from the vertical on this patch is the
    # tilt from the normal plus the normal's own, at most 11.5 deg)
    assert 1 <= info["passes_after"] < info["passes_before"], info
    assert info["summary_after"].startswith(f"{info['passes_after']} passes"), info
    assert info["largest_tilt_deg"] <= 18.0 + 11.6, info
