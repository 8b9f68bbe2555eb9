"""GUI test of TMM Simulate's picture: FreeCAD under Xvfb runs tests/gui/gui_pictures.py (the model hidden while the
coloured stock shows, the colour band following the tolerance with the extremes told, the deviation along the normal
on a design with walls) and must exit 0 within the time limit, leaving non-blank screenshots."""
from __future__ import annotations

import json
from pathlib import Path

from tests.conftest import SHARED_STL
from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN, _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui" / "simulate_band.png"  # docs/gui keeps a copy
VERTICAL_PNG = PNG.with_name("simulate_vertical.png")
TIMEOUT_S = 240
STL = str(SHARED_STL / "sphere_on_plate.stl")


def test_gui_pictures(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_pictures.json"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    for png in (PNG, VERTICAL_PNG):
        png.unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_pictures.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result), TMM_GUI_STL=STL,
        QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    # the model, its stand-in and the path hidden while the stock shows, back on Close
    assert info["mesh_visible_before"] and not any(info["while_shown"].values()), info
    assert info["after_close"] == {"mesh": True, "op": True, "node": False}, info
    # the band is the tolerance; the extremes beyond it are told with their values
    assert info["band_default"][:2] == [0.01, 0.01] and info["band_default"][2].startswith("Auto"), info
    auto, vertical = info["legend_auto"], info["legend_vertical"]
    assert (auto["min"], auto["max"]) == (-0.01, 0.01) and (vertical["min"], vertical["max"]) == (-0.01, 0.01)
    above, below, high, low = vertical["beyond"]
    assert above > 0 and abs(high - info["max_left_vertical"]) < 1e-9 and "up to" in vertical["beyond_text"], info
    # sphere_on_plate has walls: Auto reads along the normal, where the largest deviation is smaller
    assert "along the normal" in auto["title"] and "vertical" in vertical["title"], info
    assert auto["beyond"][2] < 0.9 * high, info
    # the band follows the tolerance until it is set itself
    assert abs(info["band_after_tolerance"] - 0.02) < 1e-9 and info["band_set"] == [0.05, 0.05], info
    assert info["stock_node_after_recolour"] and info["mesh_hidden_after_recolour"], info
    for png in (PNG, VERTICAL_PNG):
        assert png.is_file() and png.stat().st_size > 10_000 and not _blank(png), png
