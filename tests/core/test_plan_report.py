"""The planner's page for people (core.plan.report_html) from a report as core.plan.launch writes it: the verdict,
the verification's numbers, the setup sheet (stock, material, zero point, tools with holder and stick-out, the ops
with their times), every decision with its reason, the pictures embedded; text escaped; the same bytes twice."""
from __future__ import annotations

import base64
import re
from html import escape
from pathlib import Path

import pytest
import yaml

from tmm_workbench.core.plan import launch
from tmm_workbench.core.plan.job_file import job_from_dict
from tmm_workbench.core.plan.report_html import report_html

BEET_JOB = Path(__file__).resolve().parents[2] / "tests" / "data" / "plan_beet.yaml"


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    data = yaml.safe_load(BEET_JOB.read_text())
    data["planner"]["compare_cutters"] = False
    data["outputs"]["dir"] = str(tmp_path_factory.mktemp("out"))
    job = job_from_dict(data, BEET_JOB)
    _, _, an, plan = launch.make_plan(job)
    return job, an, plan


def verification(plan, passed: bool = True) -> dict:
    """What app/plan_run.py writes, its numbers made up (each op its own cycle time, to find it on the page)."""
    ops = [{"label": op.label, "moves": 100 + i, "cycle_seconds": 61.0 + 10 * i, "rapids_through_stock": 0,
            "holder": None} for i, op in enumerate(plan.ops)]
    return {"passed": passed, "problems": [] if passed else ["gouged 0.0500 mm below the model <& \"here\">"],
            "deepest_gouge_mm": 0.0042, "most_material_left_mm": 2.39, "left_percentiles_mm": {"50": 0.1456},
            "removed_volume_mm3": 5361.6, "remaining_volume_mm3": 113.2, "sim_cell_mm": 0.4,
            "cycle_seconds": sum(o["cycle_seconds"] for o in ops), "ops": ops, "replanned": [],
            "left_in_reach": {"tool": plan.reach_tool, "reached_mm2": 611.5, "out_of_reach_mm2": 21.3,
                              "left_above_tolerance_mm2": 3.25, "allowance_mm": 0.1,
                              "left_above_allowance_mm2": 0.75, "most_left_mm": 0.0421,
                              "left_99_percentile_mm": 0.0097}}


def test_page_holds_the_report(planned) -> None:
    job, an, plan = planned
    rep = launch.report(job, an, plan, verification(plan), ["beet_mm.ngc", "report.html", "report.json"])
    heat, path = b"\x89PNG heat map bytes", b"\x89PNG tool path bytes"
    page = report_html(rep, "beet_mm", heat, path)
    assert "VERIFIED" in page and "VERIFICATION FAILED" not in page
    text = re.sub(r"<[^>]+>", " ", page)   # the words as shown
    for words in ("0.0042 mm (tolerance 0.01 mm)", "2.39 mm", "5361.6 mm3", "113.2 mm3", "modelling foam",
                  "ER16 nut", "linuxcnc", f"left where {plan.reach_tool} reaches", "3.25 mm2 above the tolerance "
                  "(0.75 mm2 above the cusp asked, 0.1 mm), most 0.0421 mm", "21.3 mm2 of 632.8"):
        assert words in text, words
    # the stock's size from the plan's box, the zero point named
    box = plan.stock_box
    assert " x ".join(f"{b - a:.2f}" for a, b in zip(box[:3], box[3:])) in text
    assert "zero point" in text and f"Z{round(box[5], 4):g}" in text
    # every op with its tool number and its own time (1:01, 1:11, ...), in order
    rows = [f"{i}  {escape(op.label)}  T" for i, op in enumerate(plan.ops, 1)]
    positions = [text.find(r) for r in rows]
    assert -1 not in positions and positions == sorted(positions)
    for i in range(len(plan.ops)):
        assert f"{(61 + 10 * i) // 60}:{(61 + 10 * i) % 60:02d}" in text
    # each used tool once in the setup sheet, with its stick-out (the job's, or the API's default)
    used = dict.fromkeys(op.tool for op in plan.ops)
    for number, name in enumerate(used, 1):
        tool = next(t for t in rep["tools"] if t["name"] == name)
        assert re.search(rf"T{number}\s+{re.escape(escape(name))}\s+{tool['type']}", text), name
    ball = next(t for t in rep["tools"] if t["name"] == "T2 ball D6")
    assert ball["stick_out_mm"] == 30.0 and ball["holder"] == "ER16 nut"
    flat = next(t for t in rep["tools"] if t["name"] == "T1 flat D8")
    assert flat["stick_out_mm"] == pytest.approx(20 + 4 * 8 - 3 * 8)   # the ToolBit's length less the grip
    assert "T3 bull D6 r1" not in text.split("Decisions")[0]            # not used: not on the setup sheet
    # every decision with its reason
    for d in plan.decisions:
        assert escape(d.reason) in page, d.topic
    # the pictures inside the page
    for png in (heat, path):
        assert f"data:image/png;base64,{base64.b64encode(png).decode()}" in page
    # the same report gives the same bytes
    assert report_html(rep, "beet_mm", heat, path) == page


def test_failed_page_escaped_and_without_pictures(planned) -> None:
    job, an, plan = planned
    rep = launch.report(job, an, plan, verification(plan, passed=False), ["report.json"])
    page = report_html(rep, "beet <mm>")
    assert "VERIFICATION FAILED" in page
    assert "gouged 0.0500 mm below the model &lt;&amp; &quot;here&quot;&gt;" in page
    assert "<mm>" not in page and "beet &lt;mm&gt;" in page
    assert "data:image" not in page and "not drawn" in page


def test_tarus_on_the_setup_sheet(planned) -> None:
    """The machine's row names the Tarus and its tilt limit, and travels it does not check."""
    from dataclasses import replace

    job, an, plan = planned
    tarus = replace(job, machine=replace(job.machine, type="tarus5", post="tarus", travels=(1e4, 1e4, 1e4),
                                         tilt_limit=30.0))
    page = report_html(launch.report(tarus, an, plan, verification(plan), ["beet_mm.ngc"]), "beet_mm")
    assert "Tarus 5-axis (tarus5), the tool at most 30 deg from the surface normal, tarus post, travels not checked" \
        in page
    page = report_html(launch.report(job, an, plan, verification(plan), ["beet_mm.ngc"]), "beet_mm")
    assert "linuxcnc post, travels 300 x 200 x 100 mm" in page and "Tarus" not in page


def test_outcome_lines_say_the_changes_the_verdict_and_each_op() -> None:
    """The outcome `tmm plan` prints and TMM Auto's result box shows: what the run changed first, the verdict with
    its numbers, each op's cycle time only when asked; a failed run names its problems."""
    verified = {"passed": True, "problems": [], "deepest_gouge_mm": 0.0012, "most_material_left_mm": 0.25,
                "cycle_seconds": 754.0, "replanned": ["left out Rest T4 ball D3: shank too close"],
                "ops": [{"label": "Roughing T1 flat D8", "cycle_seconds": 600.5},
                        {"label": "Finish T2 ball D6", "cycle_seconds": 153.5}]}
    assert launch.outcome_lines(verified) == [
        "plan changed: left out Rest T4 ball D3: shank too close",
        "verified; deepest gouge 0.0012 mm, most left 0.25 mm, cycle 12.6 min"]
    assert launch.outcome_lines(verified, ops=True)[2:] == ["  Roughing T1 flat D8: 600.5 s",
                                                            "  Finish T2 ball D6: 153.5 s"]
    failed = dict(verified, passed=False, problems=["gouged 0.0300 mm below the model", "2 rapids through stock"],
                  replanned=[])
    assert launch.outcome_lines(failed) == [
        "verification FAILED: gouged 0.0300 mm below the model; 2 rapids through stock; deepest gouge 0.0012 mm, "
        "most left 0.25 mm, cycle 12.6 min"]


def test_rapids_through_stock_are_named_by_their_op():
    """The re-plan takes an op's problems by its label: a rapid through stock is one of its op's (it was one
    problem for the whole Job, and the op the re-plan left out for it was named with no reason)."""
    from tmm_workbench.app.plan_run import rapid_problems

    problems = rapid_problems([("Clean-up T6 ball D1", 10, 0.5), ("Rest T3", 3, 1.296),
                               ("Clean-up T6 ball D1", 12, 0.7)])
    assert problems == ["Clean-up T6 ball D1: 2 rapids through stock (deepest 0.700 mm)",
                        "Rest T3: 1 rapid through stock (deepest 1.296 mm)"]
    assert rapid_problems([]) == []
