"""The automatic planner without FreeCAD (core.plan): the job file's checks (each bad field named with its value
and what is allowed, exit code 2, nothing written), the model analysis, the decisions and their reasons, the
launcher's exit codes and its moving of complete outputs only (with a stand-in for freecadcmd)."""
from __future__ import annotations

import copy
import json
import math
import stat
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import SHARED_STL, grid_mesh
from tmm_workbench.core.footprint import reach
from tmm_workbench.core.plan import analysis, decide, launch, materials
from tmm_workbench.core.plan.job_file import PlanInputError, job_from_dict, read_job
from tmm_workbench.core.tools.cutter import Cutter

REPO = Path(__file__).resolve().parents[2]
BEET_JOB = REPO / "tests" / "data" / "plan_beet.yaml"


def good(tmp_path: Path) -> dict:
    data = yaml.safe_load(BEET_JOB.read_text())
    data["outputs"]["dir"] = str(tmp_path / "out")
    return data


def refused(tmp_path: Path, data: dict) -> str:
    with pytest.raises(PlanInputError) as ctx:
        job_from_dict(data, tmp_path / "job.yaml")
    return str(ctx.value)


def test_good_job_reads(tmp_path: Path) -> None:
    job = read_job(BEET_JOB)
    assert job.model.file == (SHARED_STL / "beet_mm.stl").resolve()
    assert [t.type for t in job.tools] == ["flat", "ball", "bull"]
    assert job.tools[1].corner_radius == 3.0 and job.tools[0].corner_radius == 0.0
    assert job.outputs.name == "beet_mm" and job.planner.sim_cell == 0.4
    as_json = tmp_path / "job.json"
    as_json.write_text(json.dumps(yaml.safe_load(BEET_JOB.read_text()).__or__({"outputs": {"dir": "o"}})))
    assert read_job(as_json).tools == job.tools


BAD = [  # (change, words the message must hold: the field, the value, what is allowed)
    (lambda d: d.update(colour="red"), ["job file", "colour", "allowed"]),
    (lambda d: d["tools"][0].update(coating="TiN"), ["tools[0]", "coating", "flute_length"]),
    (lambda d: d["tools"][1].update(type="drill"), ["tools[1].type", "'drill'", "flat, ball, bull"]),
    (lambda d: d["tools"][1].update(corner_radius=1.0), ["tools[1].corner_radius", "only for type bull"]),
    (lambda d: d["tools"][2].update(corner_radius=4.0), ["tools[2].corner_radius", "4.0", "(0, 3]"]),
    (lambda d: d["tools"][0].update(diameter=-3), ["tools[0].diameter", "-3", "(0, 100]"]),
    (lambda d: d["tools"][0].update(flutes=2.5), ["tools[0].flutes", "2.5", "whole number"]),
    (lambda d: d["tools"][0].update(stick_out=30), ["tools[0].stick_out", "holder"]),
    (lambda d: d["tools"][0].update(holder="ER99"), ["tools[0].holder", "ER99", "ER11"]),
    (lambda d: d["tools"][0].update(holder="HSK63A shrink 6x80"), ["tools[0].holder", "8 mm shank", "6-6"]),
    (lambda d: d["tools"].append(dict(d["tools"][0])), ["tools[3].name", "T1 flat D8", "no other tool"]),
    (lambda d: d.update(tools=[]), ["tools", "non-empty list"]),
    (lambda d: d.update(material="steel"), ["material", "'steel'", "aluminium", "modelling_foam"]),
    (lambda d: d["finish"].update(cusp=0), ["finish.cusp", "0", "[0.0001, 5]"]),
    (lambda d: d["finish"].update(cusp="fine"), ["finish.cusp", "'fine'"]),
    (lambda d: d["model"].update(units="cm"), ["model.units", "'cm'", "mm, inch"]),
    (lambda d: d["model"].update(file="nowhere.stl"), ["model.file", "nowhere.stl", "existing model file"]),
    (lambda d: d["model"].update(file="part.iges"), ["model.file", "part.iges", "STL (.stl) or STEP"]),
    (lambda d: d["machine"].update(post="fanuc"), ["machine.post", "'fanuc'", "linuxcnc"]),
    (lambda d: d["machine"].update(type="5-axis"), ["machine.type", "'5-axis'", "3-axis"]),
    (lambda d: d["machine"].update(travels=[300, 200]), ["machine.travels", "[x, y, z]"]),
    (lambda d: d["stock"].update(type="sphere"), ["stock.type", "'sphere'", "box, cylinder, solid"]),
    (lambda d: d["stock"].update(margin=-1), ["stock.margin", "-1", "[0, 1000]"]),
    (lambda d: d.update(format="tmm-plan 2"), ["format", "tmm-plan 2", "tmm-plan 1"]),
    (lambda d: d.pop("finish"), ["job file", "missing", "finish"]),
    (lambda d: d["outputs"].update(name="../x"), ["outputs.name", "../x", "without folders"]),
    (lambda d: d["planner"].update(sim_cell=0), ["planner.sim_cell", "0", "[0.02, 5]"]),
]


@pytest.mark.parametrize("change, words", BAD, ids=[w[0] for _, w in BAD])
def test_bad_field_named(tmp_path: Path, change, words) -> None:
    data = good(tmp_path)
    change(data)
    text = refused(tmp_path, data)
    for w in words:
        assert w in text, (w, text)


def short(tool: dict, flutes: float) -> None:
    """The tool reaching `flutes` mm: its flute length, no holder."""
    tool.update(flute_length=flutes)
    tool.pop("holder", None)
    tool.pop("stick_out", None)


def run_job(tmp_path: Path, data: dict, freecad: str = "freecadcmd-not-needed") -> int:
    path = tmp_path / "job.yaml"
    path.write_text(yaml.safe_dump(data))
    return launch.run(str(path), freecad, quiet=True)


@pytest.mark.parametrize("change, words", [
    (lambda d: d["machine"].update(travels=[20, 200, 100]), ["machine.travels", "in x", "20 mm travel"]),
    (lambda d: [short(t, 5) for t in d["tools"]], ["tools", "reaches the roughing depth", "5 mm"]),
    (lambda d: d.update(tools=[d["tools"][0]]), ["tools", "no ball or bull-nose"]),
    (lambda d: d["finish"].update(cusp=0.0001), ["finish.cusp", "0.0001", "tighter than"]),
    (lambda d: d["tools"][1].update(diameter="six"), ["tools[1].diameter", "'six'"]),
    (lambda d: [short(t, 6) for t in d["tools"][1:]], ["no ball or bull-nose tool reaches the model's height "
                                                       "7.2 mm", "6 mm"]),
    (lambda d: d.update(tools="missing_tools.yaml"), ["tools file not found", "missing_tools.yaml"]),
], ids=["travels", "depth", "no radiused", "cusp too tight", "diameter text", "radiused too short", "tools file"])
def test_bad_input_exit_2_nothing_written(tmp_path: Path, capsys, change, words) -> None:
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    change(data)
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    err = capsys.readouterr().err
    assert "bad input" in err
    for w in words:
        assert w in err, (w, err)
    assert not (tmp_path / "out").exists()
    assert list(tmp_path.iterdir()) == [tmp_path / "job.yaml"]


def test_unreadable_files_exit_2(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "job.yaml"
    bad.write_text("model: [unclosed\n")
    assert launch.run(str(bad), quiet=True) == launch.BAD_INPUT
    assert "not readable as YAML" in capsys.readouterr().err
    assert launch.run(str(tmp_path / "none.yaml"), quiet=True) == launch.BAD_INPUT
    stl = tmp_path / "empty.stl"
    stl.write_bytes(b"")
    data = good(tmp_path)
    data["model"]["file"] = str(stl)
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    assert "model.file" in capsys.readouterr().err


def test_materials_table() -> None:
    foam, alu = (materials.cutting(m, 6.0, 2, 24000, 5000) for m in ("modelling_foam", "aluminium"))
    assert foam.feed > alu.feed and foam.step_down > alu.step_down
    assert alu.rpm == pytest.approx(250_000 / (math.pi * 6))
    capped = materials.cutting("mdf", 3.0, 2, 10000, 800)
    assert capped.rpm == 10000 and capped.feed == 800 and capped.plunge == pytest.approx(800 / 3)
    assert materials.cutting("mdf", 4.5, 2, 1e5, 1e5).chip_load == pytest.approx((0.04 + 0.10) / 2)


def test_analysis_slopes_and_reach() -> None:
    # a 40 x 30 tray: a flat floor and a 45-degree ramp up to a plateau (concave edge: sharp)
    mesh = grid_mesh(lambda x, y: np.clip(x - 15.0, 0.0, 10.0), 40, 30, (0, 0, 40, 30), "ramp")
    tools = [("ball D4", Cutter.ball(4.0)), ("flat D6", Cutter.flat(6.0))]
    an = analysis.analyse(mesh, 0.5, tools, 0.01)
    assert an.size == pytest.approx((40.0, 30.0, 10.0))
    assert an.slope_area["0-1"] == pytest.approx(30 / (30 + 10 * math.sqrt(2)), abs=0.02)
    assert an.slope_area["30-45"] + an.slope_area["45-60"] == pytest.approx(1 - an.slope_area["0-1"], abs=0.02)
    assert an.down_share == 0.0 and an.flat_share > 0.6
    assert 0.2 < an.share_steeper(40.0) < 0.3                    # the ramp's 10 mm of 40 seen from above
    # the sharp concave edge at the ramp's foot: the ball leaves a fillet there, the flat's corner fits the 135 deg
    assert an.reach["ball D4"].unreached_area > 0 and an.reach["ball D4"].deepest_left > 0.1
    assert an.reach["flat D6"].unreached_area == 0.0
    assert an.concave_radius == (0.0, 2.0)


def test_analysis_reach_test_with_the_whole_tool() -> None:
    # a floor beside a wall 10 mm high: a ball D2 with 2 mm flutes reaches the floor at the wall's foot alone, but
    # its shank (1 mm clearance) holds it up within its radius and clearance of the wall; a 15 mm flute does not
    from tmm_workbench.core.tools.assembly import ToolAssembly

    mesh = grid_mesh(lambda x, y: np.clip((x - 15.0) * 10.0, 0.0, 10.0), 80, 20, (0, 0, 40, 10), "wall")
    ball = Cutter.ball(2.0)
    short = ToolAssembly(ball, 2.0, 20.0, flute_length=2.0, holder="ER11 nut")
    long = ToolAssembly(ball, 2.0, 20.0, flute_length=15.0, holder="ER11 nut")
    an = analysis.analyse(mesh, 0.25, [("alone", ball), ("short", ball, short), ("long", ball, long),
                                       ("none", ball, None)], 0.01)
    alone = an.reach["alone"].unreached_area
    assert an.reach["short"].unreached_area > alone + 10 * 1.5   # a 1.5 mm band more along the 10 mm wall at least
    assert an.reach["long"].unreached_area == an.reach["none"].unreached_area == alone


def test_reach_excess_reads_a_step_beside_a_cell_as_the_flat_side() -> None:
    # a floor; the envelope of a ball r0.5 held up by its shank beside a wall: 0.2 mm above the floor one cell off
    # the step (its nearest plunge 0.4 mm away: at least 0.14 mm off along the normal), 5 mm above beyond it
    cell = 0.2
    design = np.zeros((5, 12))
    envelope = np.zeros_like(design)
    envelope[:, 6] = 0.042
    envelope[:, 7] = 0.2
    envelope[:, 8:] = 5.0
    excess = reach.reach_excess(envelope, design, cell, 0.5)
    assert excess[2, 7] > 0.1               # out of reach (the central difference read the step's slope: reached)
    assert excess[2, 3] <= 0.0              # on the floor it plunges to
    # a smooth 75 deg flank the envelope stands 0.03 mm above vertically: 0.03 cos 75 along the normal, as before
    ramp = np.tile(np.arange(12) * cell * math.tan(math.radians(75.0)), (5, 1))
    flank = reach.reach_excess(ramp + 0.03, ramp, cell, 0.5)
    assert flank[2, 5] == pytest.approx(0.03 * math.cos(math.radians(75.0)) -
                                        cell ** 2 / (8 * 0.5 * math.cos(math.radians(75.0)) ** 2), rel=1e-6)
    assert np.allclose(reach.gentle_cosine(ramp, cell)[:, 1:-1], math.cos(math.radians(75.0)))


def plan_of(tmp_path: Path, data: dict):
    job = job_from_dict(data, tmp_path / "job.yaml")
    return launch.make_plan(job)


def test_decisions_beet(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["tools"].append({"name": "T4 flat D20", "type": "flat", "diameter": 20, "flute_length": 30})
    data["tools"].append({"name": "T5 ball D2", "type": "ball", "diameter": 2, "flute_length": 12})
    mesh, moved, an, plan = plan_of(tmp_path, data)
    assert not moved
    topics = [d.topic for d in plan.decisions]
    assert topics[:3] == ["model", "roughing tool", "roughing layers"]
    rough = plan.ops[0]
    # D20 is wider than half the beet's 22 mm side: the D8 flat is the largest that fits
    assert rough.api == "run_roughing" and rough.tool == "T1 flat D8"
    assert "reaches the" in plan.decisions[1].reason
    assert rough.kwargs["step_down"] == 16.0 and rough.kwargs["stock_to_leave"] == decide.ROUGH_LEAVE
    assert (rough.kwargs["layer_mode"], rough.kwargs["remaining_height"]) == ("tolerance", decide.ROUGH_STAIR)
    lo, hi = mesh.bounds
    assert rough.kwargs["stock"] == pytest.approx([lo[0] - 2, lo[1] - 2, lo[2], hi[0] + 2, hi[1] + 2, hi[2] + 1],
                                                  abs=1e-4)
    apis = [o.api for o in plan.ops]
    assert apis[1:3] == ["run_surface", "run_waterline"]
    shallow, steep = plan.ops[1], plan.ops[2]
    assert steep.tool == "T2 ball D6"                                 # the largest ball for the walls
    assert "seed 003 section 4.2" in next(d.reason for d in plan.decisions if d.topic == "shallow finishing tool")
    transition = shallow.kwargs["slope_range"][1]
    assert decide.TRANSITION_RANGE[0] <= transition <= decide.TRANSITION_RANGE[1]
    # the waterline's levels keep the cusp at the transition slope
    from tmm_workbench.core.footprint.cusp import plane_cusp

    dz = steep.kwargs["step_down"]
    assert plane_cusp(Cutter.ball(6.0), dz / math.tan(math.radians(transition)), transition) <= 0.1 + 1e-6
    assert plane_cusp(Cutter.ball(6.0), (dz + 0.01) / math.tan(math.radians(transition)), transition) > 0.1
    library = job_from_dict(data, tmp_path / "job.yaml").tools
    cutter = decide.cutter_of(next(t for t in library if t.name == shallow.tool))
    step = shallow.kwargs["stepover"]
    assert plane_cusp(cutter, step, transition) <= 0.1 + 1e-6 < plane_cusp(cutter, step + 0.01, transition)
    # the shallow tool takes the largest step-over keeping the cusp (the comparison ranks by volume only)
    from tmm_workbench.core.footprint.cusp import stepover_for_cusp

    candidates = d_choice(plan, "finishing candidates").split(", ")
    widest = max(stepover_for_cusp(decide.cutter_of(t), 0.1, 45.0) for t in library if t.name in candidates)
    assert stepover_for_cusp(cutter, 0.1, 45.0) >= (1 - decide.STEP_TIE) * widest
    # every decision has its reason; the feeds are the material table's
    assert all(d.reason for d in plan.decisions)
    assert plan.cutting["T2 ball D6"]["rpm"] == round(materials.cutting("modelling_foam", 6, 2, 24000, 5000).rpm)
    # the same input gives the same plan
    again = plan_of(tmp_path, data)[3]
    assert json.dumps(again.as_dict(), sort_keys=True) == json.dumps(plan.as_dict(), sort_keys=True)


def d_choice(plan: decide.Plan, topic: str) -> str:
    return next(d.choice for d in plan.decisions if d.topic == topic)


def test_no_comparison_and_placement(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["planner"].update(compare_cutters=False, analysis_cell=5.0)   # 25 times the size: a coarse grid
    data["model"]["units"] = "inch"
    data["model"]["translate"] = [100, 0, 0]
    data["machine"]["travels"] = [1000, 1000, 400]
    data["tools"] = [{"name": "big", "type": "flat", "diameter": 50, "flute_length": 300},
                     {"name": "ball", "type": "ball", "diameter": 10, "flute_length": 300}]
    mesh, moved, an, plan = plan_of(tmp_path, data)
    src = read_job(BEET_JOB)
    lo0 = launch.load_stl(src.model.file).bounds[0]
    assert moved and mesh.bounds[0] == pytest.approx(lo0 * 25.4 + [100, 0, 0])
    d = {x.topic: x for x in plan.decisions}
    assert d["shallow finishing tool"].choice.startswith("ball") and "comparison is off" in \
        d["shallow finishing tool"].reason
    assert d["transition slope"].choice == f"{decide.TRANSITION_DEG:g} deg"


def stand_in(tmp_path: Path, passed: bool, fail: bool = False) -> str:
    """An executable playing freecadcmd: writes what app/plan_run.py writes (or fails)."""
    script = tmp_path / "fake_freecadcmd"
    verified = {"passed": passed, "problems": [] if passed else ["gouged 0.0500 mm"], "deepest_gouge_mm": 0.0,
                "most_material_left_mm": 0.1, "cycle_seconds": 60.0, "removed_volume_mm3": 5000.0,
                "remaining_volume_mm3": 100.0, "left_percentiles_mm": {"50": 0.05}, "sim_cell_mm": 0.4}
    body = "raise SystemExit(3)" if fail else (
        "import json, os\nfrom pathlib import Path\nf = Path(os.environ['TMM_PLAN_FILE']).parent\n"
        "plan = json.loads((f / 'plan.json').read_text())\n"
        "(f / (plan['name'] + '.ngc')).write_text('G0 X0 Y0 Z5\\nG1 Z-1\\nG1 X10\\n')\n"
        f"verified = {verified!r}\n"
        "verified['ops'] = [{'label': o['label'], 'moves': 3, 'cycle_seconds': 20.0, 'rapids_through_stock': 0,"
        " 'holder': None} for o in plan['ops']]\n"
        "(f / 'verify.json').write_text(json.dumps(verified))\n")
    script.write_text(f"#!{sys.executable}\n{body}\n")
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    return str(script)


@pytest.mark.parametrize("passed, code", [(True, launch.VERIFIED), (False, launch.FAILED)])
def test_launcher_moves_complete_outputs(tmp_path: Path, passed: bool, code: int) -> None:
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    assert run_job(tmp_path, data, stand_in(tmp_path, passed)) == code
    out = tmp_path / "out"
    files = ["beet_mm.ngc", "beet_mm_toolpath.png", "report.html", "report.json"]
    assert sorted(p.name for p in out.iterdir()) == files
    rep = json.loads((out / "report.json").read_text())
    assert rep["passed"] is passed and rep["files"] == files
    assert ("VERIFIED" if passed else "VERIFICATION FAILED") in (out / "report.html").read_text()
    assert [d["topic"] for d in rep["plan"]["decisions"]][:2] == ["model", "roughing tool"]
    assert rep["analysis"]["triangles"] > 1000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".beet_mm.")]   # no temporary folder left


def test_launcher_failed_run_writes_nothing(tmp_path: Path, capsys) -> None:
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    assert run_job(tmp_path, data, stand_in(tmp_path, True, fail=True)) == launch.FAILED
    assert "the FreeCAD run failed (exit 3)" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".beet_mm.")]
    assert run_job(tmp_path, copy.deepcopy(data), str(tmp_path / "no_such_freecadcmd")) == launch.FAILED
    assert "could not start" in capsys.readouterr().err


def test_tools_file_and_candidates(tmp_path: Path) -> None:
    data = good(tmp_path)
    library = data["tools"] + [{"name": "T4 ball D2", "type": "ball", "diameter": 2, "flute_length": 10},
                               {"name": "T5 ball D4 short", "type": "ball", "diameter": 4, "flute_length": 5}]
    (tmp_path / "shop.yaml").write_text(yaml.safe_dump({"tools": library}))
    data["tools"] = "shop.yaml"
    _, _, an, plan = plan_of(tmp_path, data)
    d = {x.topic: x for x in plan.decisions}
    # the D2 is smaller than the largest ball (kept for the rest); the short D4 does not reach the 7.2 mm height
    assert d["finishing candidates"].choice == "T2 ball D6, T3 bull D6 r1"
    assert d["finishing candidates"].reason.endswith("left for the rest: T4 ball D2")
    assert d["tools left out"].choice == "T5 ball D4 short (5 mm)"
    assert "T5 ball D4 short" not in {o.tool for o in plan.ops}
    (tmp_path / "shop.yaml").write_text(yaml.safe_dump(library))
    with pytest.raises(PlanInputError, match="tools file shop.yaml: got .*one field, tools"):
        job_from_dict(data, tmp_path / "job.yaml")


def test_roughing_stops_where_its_flutes_end(tmp_path: Path) -> None:
    """A roughing tool reaching the depth by its stick-out but with shorter flutes roughs down only as far as
    its flutes keep the shank clear of the walls (ktoolcav: the shank rubbed the walls below the flutes)."""
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    data["tools"][0].update(flute_length=5, holder="ER16 nut", stick_out=30)
    _, _, _, plan = plan_of(tmp_path, data)
    rough = plan.ops[0]
    top = plan.stock_box[5]
    assert rough.tool == "T1 flat D8"
    assert rough.kwargs["final_z"] == pytest.approx(top - 5 + decide.ROUGH_SHANK_CLEAR)
    assert "shank" in next(d.reason for d in plan.decisions if d.topic == "roughing depth")
    # flutes long enough: down to the model
    _, _, _, plan = plan_of(tmp_path, good(tmp_path))
    assert "final_z" not in plan.ops[0].kwargs
    assert "roughing depth" not in [d.topic for d in plan.decisions]



def test_deep_walls_finished_first(tmp_path: Path) -> None:
    """A pocket deeper than the finishing ball's flutes: its shank would pass within its clearance of what the
    roughing leaves on the walls, so the flat whose flutes reach finishes the walls by waterline first, nothing
    left, as deep as its own shank stays clear. A ball without a holder (no shank checked) or with flutes
    reaching the depth needs none."""
    pocket = grid_mesh(lambda x, y: np.where((np.abs(x) < 10) & (np.abs(y) < 10), 0.0, 10.0), 80, 80,
                       (-20, -20, 20, 20), "pocket")
    stl = tmp_path / "pocket.stl"
    from tmm_workbench.core.geometry.mesh import save_stl

    save_stl(pocket, stl)
    data = good(tmp_path)
    data["model"]["file"] = str(stl)
    data["planner"]["compare_cutters"] = False
    data["tools"] = [{"name": "F8", "type": "flat", "diameter": 8, "flute_length": 10.5, "holder": "ER16 nut",
                      "stick_out": 30},
                     {"name": "B6", "type": "ball", "diameter": 6, "flute_length": 4, "holder": "ER16 nut",
                      "stick_out": 30}]
    plan = plan_of(tmp_path, data)[3]
    face, walls = plan.ops[1:3]
    assert (face.api, face.tool, face.label) == ("run_surface", "F8", "Face plateaus F8")
    assert face.kwargs["final_depth"] == walls.kwargs["bottom_z"] and face.kwargs["off_model"] == "skip"
    assert (walls.api, walls.tool, walls.label) == ("run_waterline", "F8", "Finish walls F8")
    top = plan.stock_box[5]
    assert walls.kwargs["stock_to_leave"] == 0.0 and walls.kwargs["top_z"] == pytest.approx(10.0)
    assert walls.kwargs["bottom_z"] == pytest.approx(top - 10.5 + decide.ROUGH_SHANK_CLEAR)
    assert "B6" in next(d.reason for d in plan.decisions if d.topic == "deep walls")
    for change in ({"flute_length": 13}, {"holder": None, "stick_out": None, "flute_length": 13}):
        data["tools"][1].update(change)
        data["tools"][1] = {k: v for k, v in data["tools"][1].items() if v is not None}
        plan = plan_of(tmp_path, data)[3]
        assert not any(o.label.startswith("Finish walls") for o in plan.ops)
