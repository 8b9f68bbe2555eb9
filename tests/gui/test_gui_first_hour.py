"""A new user's first hour under Xvfb (tests/gui/gui_first_hour.py): an STL to a Job, roughing, waterline, a cusp
finish in a sketch region, TMM Simulate and a post; a Bézier patch through the 5-axis op with the panel's defaults,
TMM Simulate and the tarus post. Asserted: every op computes; a step-over wider than the tool is refused before
computing and a cusp spacing with a flat end mill warned; the estimate told before OK is within 0.6-1.6x of the
computed path's cutting time; 5-axis Simulate works with the default tool shape; the ops and their undo steps carry
the user's names. Screenshots in out/gui (docs/gui with TMM_GUI_REFRESH_DOCS=1)."""
from __future__ import annotations

from pathlib import Path

from tests.conftest import SHARED_STL
from tests.gui.launch import SHOTS, check_shots, run_session

TIMEOUT_S = 240
STL = str(SHARED_STL / "sphere_on_plate.stl")
SHOT_NAMES = ("hour_1_job_from_stl", "hour_2_flat_cusp_warned", "hour_3_cusp_finish_panel", "hour_4_simulate_3axis",
              "hour_5_simulate_5axis")


def test_gui_first_hour(tmp_path: Path) -> None:
    pngs = [SHOTS / f"{name}.png" for name in SHOT_NAMES]
    for png in pngs:
        png.unlink(missing_ok=True)
    info = run_session("gui_first_hour.py", tmp_path, TIMEOUT_S, TMM_GUI_SHOTS=str(SHOTS), TMM_GUI_STL=STL)
    assert info["job_panel"], info
    for op in ("roughing", "waterline", "surface", "multipoint"):
        assert info[op][0] and info[op][1] > 10, (op, info[op])
    # refused before anything is computed: the field's message on the status line and in OK's box, panel open
    assert "StepOver 500 mm is wider than the tool (diameter 6 mm)" in info["wide_stepover_status"], info
    assert "Not computed" in info["wide_stepover_box"] and "StepOver 500 mm" in info["wide_stepover_box"], info
    assert info["wide_stepover_panel_open"], info
    assert "flat end mill" in info["flat_cusp_status"] and "ball or bull-nose" in info["flat_cusp_status"], info
    # the estimate told before OK (on the status line) against the path OK computed, with the ball again
    assert info["estimate_text"] in info["surface_status_before"] and "ball" in info["surface_tool"].lower(), info
    ratio = info["estimate_s"] / info["computed_cutting_s"]
    assert 0.6 <= ratio <= 1.6, (ratio, info["estimate_text"], info["computed_cutting_s"])
    # the user's words: labels, undo steps, no FreeCAD default name
    assert info["surface_label"].startswith("TMM Surface") and info["roughing_label"].startswith("TMM Roughing"), info
    assert info["roughing_undo"][:2] == [f"Edit {info['roughing_label']}", "Create TMM Roughing"], info
    assert not any("AreaOp" in name for name in info["surface_undo"]), info["surface_undo"]
    sim3 = info["4_simulate_3axis"]
    assert sim3["max_left"] is not None and not sim3["status"].startswith("GOUGED"), sim3
    assert info["post"][1] > 100 and info["post"][2] > 50, info["post"]
    # 5-axis with the panel's defaults: the tool shape from the tool bit, simulated and posted
    assert info["mp_defaults"][0] == "FromToolBit", info["mp_defaults"]
    assert "will fail" not in info["mp_reopened_status"], info["mp_reopened_status"]
    sim5 = info["5_simulate_5axis"]
    assert sim5["max_left"] is not None, sim5
    assert info["tarus"][0] > 50 and info["tarus"][1] > 10, info["tarus"]
    assert info["message_boxes"] == [], info["message_boxes"]   # no modal box on the way
    check_shots(pngs)
