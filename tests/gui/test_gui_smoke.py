"""GUI smoke test: FreeCAD under Xvfb runs tests/gui/gui_smoke.py (workbench, Job, op, task panel,
screenshot, TMM Simulate) and must exit 0 within the time limit, leaving non-blank PNGs."""
from __future__ import annotations

import json
from pathlib import Path


from tests.conftest import SHARED_STL
from tests.freecad import fc_process
from tests.gui.launch import FREECAD, XVFB_RUN
from tests.gui.launch import blank as _blank

HERE = Path(__file__).resolve().parent
PNG = fc_process.ROOT / "out" / "gui_smoke.png"
SIM_PNG = PNG.with_name("gui_simulate.png")  # gui_smoke.py writes it beside PNG
TIMEOUT_S = 120
STL = str(SHARED_STL / "sphere_on_plate.stl")  # where the test finds it, also inside a chroot


def test_gui_smoke(tmp_path: Path) -> None:
    # scripts/setup.sh installs both: missing ones fail the test rather than skip it.
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result, headless_doc = tmp_path / "gui_smoke.json", tmp_path / "headless.FCStd"
    PNG.unlink(missing_ok=True)
    SIM_PNG.unlink(missing_ok=True)
    freecadcmd = fc_process.find("freecadcmd", "FreeCADCmd")
    if freecadcmd:  # a document saved without the GUI, for the GUI to reopen
        code, out = fc_process.run([freecadcmd, str(HERE / "make_headless_doc.py")], cwd=tmp_path, timeout=120,
                                   TMM_GUI_REOPEN=str(headless_doc), TMM_GUI_STL=STL)
        assert code == 0 and headless_doc.is_file(), out
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / "gui_smoke.py")],
        cwd=tmp_path, timeout=TIMEOUT_S, TMM_GUI_PNG=str(PNG), TMM_GUI_RESULT=str(result),
        TMM_GUI_REOPEN=str(headless_doc) if freecadcmd else "", TMM_GUI_STL=STL,
        QTWEBENGINE_DISABLE_SANDBOX="1")  # FreeCAD's start page uses QtWebEngine, which refuses root
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    assert (info["stale_attribute_type"], info["rewrapped_type"]) == ("QWidget", "QCheckBox"), info
    assert info["rewrapped_same_object"] and info["right_kept"], info
    assert info["workbench"] == "TMMWorkbench" and info["panel_open"] and info["cancel_seen"]
    assert info["multipoint_command_panel"] and "two" in info["multipoint_contacts"]
    assert info.get("reopened_panel") or not freecadcmd
    assert info.get("roughing_valid") and info.get("waterline_valid"), info  # made by their commands, OK: a path
    assert info.get("mp_anchor") == ["Tip", ["Axis", "Tip"]] and abs(info.get("mp_extension", 0) - 12.7) < 1e-9
    # no traceback of TMM's CAM toolbar manipulator (1.x)
    assert "cam_integration" not in out, fc_process.failure_text(out)
    assert PNG.is_file() and PNG.stat().st_size > 10_000
    assert not _blank(PNG), "the screenshot is blank"
    # TMM Simulate: the panel's numbers, the coloured stock shown and removed on Close, nothing left behind
    sim = {k: v for k, v in info.items() if k.startswith("sim_")}
    assert not info["sim_gouged"] and info["sim_max_left"] > 0, sim
    assert info["sim_node"] and info["sim_node_removed"], sim
    assert info["sim_doc_unchanged"] and info["sim_visibility_restored"], sim
    assert SIM_PNG.is_file() and SIM_PNG.stat().st_size > 10_000
    assert not _blank(SIM_PNG), "the simulation screenshot is blank"

