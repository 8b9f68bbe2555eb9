"""GUI test of the stock collisions in TMM Simulate: FreeCAD under Xvfb runs tests/gui/gui_sim_holder.py (a
holder-safe finish of the cavity simulated from the raw block: the panel reports the shank in uncut stock, red
markers inside the simulated stock's node, gone on Close) and must exit 0 within the time limit."""
from __future__ import annotations

import json
from pathlib import Path

from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN, _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui" / "sim_holder.png"
TIMEOUT_S = 240


def test_gui_sim_holder(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_sim_holder.json"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    PNG.unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_sim_holder.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result),
        QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert info["markers"] > 0 and info["markers_after_close"] == -1 and not info["stock_node_after_close"], info
    assert PNG.is_file() and PNG.stat().st_size > 10_000 and not _blank(PNG)
