"""The planner on the Tarus 5-axis mill (core.plan.job_file's machine tarus5, core.plan.five_axis): the machine
read and checked (its post, tilt limit, the APT CL output, planner.five_axis), holders given to a FreeCAD library's
tools by the job's `holders`, and the 5-axis decision: on seed 000's convex window (tests/data/plan_tarus.yaml) the
tilted flat end replaces the 3-axis finishing with both estimated times in its reason, the 3-axis ops kept as the
fallback; never, a solid model and a 3-axis machine keep the 3-axis plan with the reason."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from tests.core.test_plan import good, refused
from tests.core.test_plan_inputs import FC_TOOLS, job_of
from tmm_workbench.core.plan import five_axis, launch
from tmm_workbench.core.plan.job_file import NO_TRAVELS, TARUS_TILT_MAX, job_from_dict

TARUS_JOB = Path(__file__).resolve().parents[1] / "data" / "plan_tarus.yaml"


def tarus(tmp_path: Path) -> dict:
    data = yaml.safe_load(TARUS_JOB.read_text())
    data["model"]["file"] = str(TARUS_JOB.parent / data["model"]["file"])
    data["outputs"]["dir"] = str(tmp_path / "out")
    return data


# --- the machine ---------------------------------------------------------------------------------------------

def test_tarus_shorthand_and_fields(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["machine"] = "tarus"
    m = job_of(tmp_path, data).machine
    assert (m.type, m.post, m.travels, m.tilt_limit, m.five_axis) == ("tarus5", "tarus", NO_TRAVELS, TARUS_TILT_MAX,
                                                                       True)
    data["machine"] = {"type": "tarus5", "tilt_limit": 30, "travels": [500, 400, 300], "rapid": [9000, 9000]}
    data["outputs"]["apt_cl"] = True
    job = job_of(tmp_path, data)
    assert (job.machine.tilt_limit, job.machine.travels, job.outputs.apt_cl) == (30.0, (500.0, 400.0, 300.0), True)
    assert not read_default(tmp_path).outputs.apt_cl and not read_default(tmp_path).machine.five_axis


def read_default(tmp_path: Path):
    return job_from_dict(good(tmp_path), tmp_path / "job.yaml")


@pytest.mark.parametrize("machine, words", [
    ({"type": "tarus5", "post": "linuxcnc"}, ["machine.post", "'linuxcnc'", "one of tarus"]),
    ({"type": "3-axis", "post": "tarus", "travels": [300, 200, 100]}, ["machine.post", "'tarus'", "tarus5"]),
    ({"type": "tarus5", "tilt_limit": 50}, ["machine.tilt_limit", "50", "(0, 45]"]),
    ({"type": "tarus5", "tilt_limit": 0}, ["machine.tilt_limit", "(0, 45]"]),
    ({"type": "3-axis", "post": "linuxcnc", "travels": [300, 200, 100], "tilt_limit": 30},
     ["machine (type 3-axis)", "unknown field", "tilt_limit"]),
    ({"type": "5-axis"}, ["machine.type", "'5-axis'", "3-axis, tarus5"]),
    ("tarus 5", ["machine", "'tarus 5'", "'tarus'"]),
])
def test_bad_machine_named(tmp_path: Path, machine, words: list) -> None:
    data = good(tmp_path)
    data["machine"] = machine
    text = refused(tmp_path, data)
    assert all(w in text for w in words), text


def test_five_axis_choice_checked(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["planner"]["five_axis"] = "always"   # on the beet job's 3-axis machine
    assert all(w in refused(tmp_path, data) for w in ("planner.five_axis", "'always'", "tarus5"))
    data["planner"]["five_axis"] = "sometimes"
    assert "auto, always, never" in refused(tmp_path, data)
    data = good(tmp_path)
    data["outputs"]["apt_cl"] = "yes"
    assert "outputs.apt_cl" in refused(tmp_path, data)


# --- holders for a library's tools ----------------------------------------------------------------------------

def test_library_tools_get_holders(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["tools"] = str(FC_TOOLS / "v0_20" / "Library" / "Default.fctl")
    data["holders"] = {"T3": {"holder": "ER16 nut", "stick_out": 45}, "T4 6 mm Bull Nose": {"holder": "ER16 nut"}}
    tools = {t.name.split()[0]: t for t in job_of(tmp_path, data).tools}
    assert (tools["T3"].holder, tools["T3"].stick_out) == ("ER16 nut", 45.0)   # by its number
    assert (tools["T4"].holder, tools["T4"].stick_out) == ("ER16 nut", None)   # by its name
    assert tools["T1"].holder is None


@pytest.mark.parametrize("holders, words", [
    ({"T9": {"holder": "ER16 nut"}}, ["holders", "'T9'", "one library tool", "T1 5mm Endmill"]),
    ({"T3": {"holder": "no such holder"}}, ["tools[1].holder", "'no such holder'", "TMM's library"]),
    ({"T3": {"holder": "ER16 nut", "stick_out": 10}}, ["tools[1].stick_out", "10", "[40, 1000]"]),
    ({"T3": {"stick_out": 45}}, ["holders['T3']", "missing", "holder"]),
    ({"T3": "ER16 nut"}, ["holders['T3']", "'ER16 nut'", "a mapping"]),
    (["ER16 nut"], ["holders", "a mapping of tool names"]),
])
def test_bad_holders_named(tmp_path: Path, holders, words: list) -> None:
    data = good(tmp_path)
    data["tools"] = str(FC_TOOLS / "v0_20" / "Library" / "Default.fctl")
    data["holders"] = holders
    text = refused(tmp_path, data)
    assert all(w in text for w in words), text


def test_second_holder_refused(tmp_path: Path) -> None:
    data = good(tmp_path)   # the beet job's T2 has its own holder
    data["holders"] = {"T2 ball D6": {"holder": "ER16 nut"}}
    assert all(w in refused(tmp_path, data) for w in ("holders['T2 ball D6']", "no second holder", "ER16 nut"))


# --- the decision -----------------------------------------------------------------------------------------------

def test_five_axis_pays_on_the_convex_window(tmp_path: Path) -> None:
    job = job_of(tmp_path, tarus(tmp_path))
    _, _, _, plan = launch.make_plan(job)
    choice = plan.five_axis
    assert choice is not None and choice.seconds_5axis < choice.seconds_3axis
    labels = [op.label for op in plan.ops]
    assert labels == ["Roughing T1 flat D10", "Finish 5-axis T1 flat D10"]
    op = plan.ops[1]
    assert op.api == "run_mesh5" and op.kwargs["tool"] == "endmill" and op.kwargs["post"] == "tarus"
    assert op.kwargs["tolerance"] == job.finish.cusp and op.kwargs["tilt_limit_deg"] == 45.0
    fallback = [o.label for o in choice.fallback_ops]
    assert fallback[0] == labels[0] and any(f.startswith("Finish shallow") for f in fallback)
    decision = next(d for d in plan.decisions if d.topic == five_axis.TOPIC)
    for minutes in (choice.seconds_5axis / 60, choice.seconds_3axis / 60):   # both times in the reason
        assert f"{minutes:.2f}" in decision.reason
    doc = launch.plan_document(job, plan, job.model.file)
    assert doc["five_axis"]["fallback_ops"][1]["label"] == fallback[1] and doc["apt_cl"] is True
    # after the Job's run: the built op's simulated time beside the estimate, said when it is slower than the
    # 3-axis estimate
    for built, slower in ((choice.seconds_5axis * 1.1, False), (choice.seconds_3axis + 1.0, True)):
        verified = {"ops": [{"label": labels[0], "cycle_seconds": 60.0}, {"label": op.label, "cycle_seconds": built}]}
        five_axis.after_run(plan, verified)
        row = verified["five_axis"]
        assert (row["built_seconds"], row["slower_than_three_axis"]) == (round(built, 1), slower)
        assert plan.decisions[-1].choice == ("built: slower than the 3-axis estimate" if slower else "built")
        assert f"{built / 60:.2f} min as built" in plan.decisions[-1].reason
    assert choice.as_dict()["built_seconds"] == round(built, 1)
    # the FreeCAD side's fallback: the 3-axis ops back, the reason written
    five_axis.after_run(plan, {"five_axis_fallback": "did not verify: gouged", "ops": []})
    assert [o.label for o in plan.ops] == fallback
    assert plan.decisions[-1].choice == "fell back to the 3-axis plan" and "gouged" in plan.decisions[-1].reason


def test_never_and_solid_keep_the_3_axis_plan(tmp_path: Path) -> None:
    data = tarus(tmp_path)
    data["planner"]["five_axis"] = "never"
    _, _, _, plan = launch.make_plan(job_of(tmp_path, data))
    assert plan.five_axis is None and not any(op.api == "run_mesh5" for op in plan.ops)
    assert [(d.choice, d.reason) for d in plan.decisions if d.topic == five_axis.TOPIC] == \
        [("none", "planner.five_axis: never")]
    data = good(tmp_path)   # the beet, a closed solid: its underside faces down
    data["machine"] = "tarus"
    _, _, _, plan = launch.make_plan(job_of(tmp_path, data))
    (reason,) = [d.reason for d in plan.decisions if d.topic == five_axis.TOPIC]
    assert plan.five_axis is None and "faces down" in reason


def test_a_small_flat_end_does_not_pay(tmp_path: Path) -> None:
    """A flat D2 against the ball D10's raster: the 5-axis finish is slower, the plan stays 3-axis, both times in
    the reason."""
    data = tarus(tmp_path)
    data["tools"][0].update(name="T1 flat D2", diameter=2)
    _, _, _, plan = launch.make_plan(job_of(tmp_path, data))
    assert plan.five_axis is None and not any(op.api == "run_mesh5" for op in plan.ops)
    (d,) = [d for d in plan.decisions if d.topic == five_axis.TOPIC]
    minutes = [float(m) for m in re.findall(r"(\d+\.\d\d) min", d.reason)]
    assert d.choice == "none" and d.reason.startswith("it does not pay") and "T1 flat D2" in d.reason
    assert minutes[0] > minutes[-1]   # the 5-axis time first, the 3-axis finishing's sum last


def test_always_takes_the_slower_five_axis_finish(tmp_path: Path) -> None:
    """planner.five_axis: always with the flat D2 that does not pay: the 5-axis op goes in all the same, slower
    than the 3-axis estimate, the reason says why."""
    data = tarus(tmp_path)
    data["tools"][0].update(name="T1 flat D2", diameter=2)
    data["planner"]["five_axis"] = "always"
    _, _, _, plan = launch.make_plan(job_of(tmp_path, data))
    choice = plan.five_axis
    assert choice is not None and choice.seconds_5axis > choice.seconds_3axis
    assert [op.label for op in plan.ops][-1] == "Finish 5-axis T1 flat D2"
    (d,) = [d for d in plan.decisions if d.topic == five_axis.TOPIC]
    assert d.reason.startswith("planner.five_axis: always") and f"{choice.seconds_5axis / 60:.2f}" in d.reason
