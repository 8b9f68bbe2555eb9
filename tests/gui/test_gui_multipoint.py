"""GUI test of the 5-axis op: FreeCAD under Xvfb runs tests/gui/gui_multipoint.py (the tool axes shown,
coloured and hidden, the panel with the Scallop field fitting 1000 px, TMM Simulate on the 5-axis Job) and
must exit 0 within the time limit, leaving a non-blank screenshot in docs/gui/."""
from __future__ import annotations

import json
from pathlib import Path

from tests.freecad import fc_process
from tests.gui.test_gui_smoke import FREECAD, XVFB_RUN, _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui" / "multipoint_axes.png"  # docs/gui keeps a copy
SIM_PNG = PNG.with_name("multipoint_simulate.png")
TIMEOUT_S = 240


def test_gui_multipoint(tmp_path: Path) -> None:
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / "gui_multipoint.json"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    PNG.unlink(missing_ok=True)
    SIM_PNG.unlink(missing_ok=True)
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_multipoint.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result),
        QTWEBENGINE_DISABLE_SANDBOX="1")
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert info["axes_shown"] > 0 and info["axes_hidden"] == 0 and info["axes_every_1"] == info["positions"]
    assert info["contact_colours_match"] and info["tilt_colours_distinct"] > 10
    # the axes hide with their op, carry a legend, and are out of the way while the simulated stock shows
    assert info["axes_op_hidden"] == 0 and info["axes_op_shown"] == info["axes_shown"], info
    assert info["legend_lines"][1:] == ["green: two contacts", "orange: one contact"], info["legend_lines"]
    assert not info["sim_face_visible"] and info["sim_axes"] == 0, info
    assert info["closed_face_visible"] and info["closed_axes"] > 0, info
    assert info["pass_spacing"][0] == "Scallop" and abs(info["scallop_field"][0] - 0.5) < 1e-9
    assert info["warning_fixed_30"][0] and not info["warning_fixed_20"] and not info["warning_scallop_30"]
    assert info["page_height"] < 760 and info["task_panel_height"] <= 1000, info
    assert info["sim_max_left"] is not None, info["sim_status"]
    # the app's own simulator (1 mm cells) reads the scallop the op was asked for (0.5 mm), and no gouge
    assert info["sim_max_left"] <= 0.5 * 1.02 and info["sim_min_deviation"] >= -0.01, info
    for png in (PNG, SIM_PNG):
        assert png.is_file() and png.stat().st_size > 10_000, png
        assert not _blank(png), f"{png} is blank"
