"""TMM Auto under Xvfb (tests/gui/gui_auto.py): beet_mm.stl selected, the command from the TMM toolbar, a recipe
chosen in its panel. Asserted: a missing tool library refused by name with the panel open and nothing added; a run
cancelled at its first progress dialog leaves the document as it was and writes nothing; OK leaves a Job with the
planned ops (each computed) in the document, selected, a result box naming the ops and the report, and the output
folder with report.html naming every op. Screenshots in out/gui."""
from __future__ import annotations

import json
import re
from pathlib import Path

from tests.conftest import SHARED_STL
from tests.gui.launch import SHOTS, check_shots, run_session
from tmm_workbench.core.plan.launch import outcome_lines

TIMEOUT_S = 300


def test_gui_auto(tmp_path: Path) -> None:
    pngs = [SHOTS / f"{name}.png" for name in ("auto_1_panel", "auto_2_job")]
    for png in pngs:
        png.unlink(missing_ok=True)
    out = tmp_path / "plan"
    info = run_session("gui_auto.py", tmp_path, TIMEOUT_S, TMM_GUI_SHOTS=str(SHOTS), TMM_GUI_OUT=str(out),
                       TMM_GUI_STL=str(SHARED_STL / "beet_mm.stl"))
    assert "TMM Auto" in info["toolbar"], info["toolbar"]
    assert "tools" in info["refused_status"] and "no_such_tools.yaml" in info["refused_status"], info
    assert info["refused_panel_open"] and info["refused_unchanged"], info
    assert info["cancelled_at"], "no progress dialog to cancel"
    assert info["cancelled_status"].startswith("Cancelled"), info["cancelled_status"]
    assert info["cancelled_panel_open"] and info["cancelled_unchanged"] and not info["cancelled_out_exists"], info
    assert len(info["jobs"]) == 1, info["jobs"]
    labels = [label for label, *_ in info["ops"]]
    assert labels[0].startswith("Roughing") and any(label.startswith("Finish") for label in labels), labels
    assert all(valid and moves > 10 for _, valid, moves in info["ops"]), info["ops"]
    assert info["selected"] == [info["job_name"]], info
    # the box says what the report says, as `tmm plan` says it: the verdict with its numbers, each op's time
    report = json.loads((out / "report.json").read_text())
    box = info["box"].splitlines()
    assert box[2:] == outcome_lines(report["verification"], ops=True) + [f"Report: {out / 'report.html'}"], box
    assert any(line.startswith("verified; deepest gouge") for line in box), box
    for label in labels:
        assert any(line.startswith(f"  {label}: ") and line.endswith(" s") for line in box), (label, box)
        assert f"<td>{label}</td>" in info["html"], label
    assert {"beet_mm_model.stl", "job.json", "beet_mm.ngc", "beet_mm_sim.png", "beet_mm_toolpath.png",
            "report.html", "report.json"} <= set(info["files"]), info["files"]
    assert not [f for f in info["files"] if f.endswith(".FCStd")], info["files"]   # the Job stays in the open doc
    assert re.search(r"VERIFIED|VERIFICATION FAILED", info["html"])
    check_shots(pngs)
