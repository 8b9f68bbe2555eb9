"""A STEP model in the planner's job file: the job file takes it (in mm only: the file carries its units), the
launcher has FreeCAD tessellate it (app/step_mesh.py, here a stand-in for freecadcmd) within half the tolerance into
<name>_model.stl, plans on that mesh and hands it to the Job; a STEP FreeCAD cannot read is bad input (exit 2) with
nothing written. The real FreeCAD run: tests/freecad/fc_test_plan.py (PlanStep)."""
from __future__ import annotations

import json
import shutil
import stat
import sys
from pathlib import Path

import pytest
import yaml

from tests.conftest import SHARED_STL
from tmm_workbench.core.plan import launch
from tmm_workbench.core.plan.job_file import PlanInputError, job_from_dict

REPO = Path(__file__).resolve().parents[2]


def step_job(tmp_path: Path) -> dict:
    data = yaml.safe_load((REPO / "tests" / "data" / "plan_beet.yaml").read_text())
    (tmp_path / "part.step").write_text("ISO-10303-21;\nEND-ISO-10303-21;\n")   # read by the stand-in only
    data["model"]["file"] = "part.step"
    data["outputs"]["dir"] = str(tmp_path / "out")
    data["planner"]["compare_cutters"] = False
    return data


def fake_freecad(tmp_path: Path, readable: bool) -> str:
    """Plays freecadcmd: as app/step_mesh.py it writes beet_mm.stl as the tessellation (or exits 2: unreadable),
    as app/plan_run.py what that writes."""
    script = tmp_path / "fake_freecadcmd"
    body = f"""import json, os, shutil, sys
from pathlib import Path
if "TMM_STEP_FILE" in os.environ:
    Path(os.environ["TMM_STEP_FILE"] + ".asked").write_text(os.environ["TMM_STEP_DEFLECTION"])
    if not {readable!r}:
        print("FreeCAD could not read part.step as a STEP model: no shape", file=sys.stderr)
        raise SystemExit(2)
    shutil.copyfile({str(SHARED_STL / 'beet_mm.stl')!r}, os.environ["TMM_STEP_STL"])
    raise SystemExit(0)
f = Path(os.environ["TMM_PLAN_FILE"]).parent
plan = json.loads((f / "plan.json").read_text())
assert Path(plan["model_file"]).is_file(), plan["model_file"]
verified = {{"passed": True, "problems": [], "deepest_gouge_mm": 0.0, "most_material_left_mm": 0.1,
            "cycle_seconds": 60.0, "removed_volume_mm3": 5000.0, "remaining_volume_mm3": 100.0,
            "left_percentiles_mm": {{"50": 0.05}}, "sim_cell_mm": 0.4,
            "ops": [{{"label": o["label"], "moves": 3, "cycle_seconds": 20.0, "rapids_through_stock": 0,
                     "holder": None}} for o in plan["ops"]]}}
(f / "verify.json").write_text(json.dumps(verified))
"""
    script.write_text(f"#!{sys.executable}\n{body}")
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    return str(script)


def run(tmp_path: Path, data: dict, freecad: str) -> int:
    (tmp_path / "job.yaml").write_text(yaml.safe_dump(data))
    return launch.run(str(tmp_path / "job.yaml"), freecad, quiet=True)


def test_step_tessellated_then_planned(tmp_path: Path) -> None:
    data = step_job(tmp_path)
    data["outputs"]["gcode"] = False
    assert run(tmp_path, data, fake_freecad(tmp_path, True)) == launch.VERIFIED
    out = tmp_path / "out"
    assert sorted(p.name for p in out.iterdir()) == ["part_model.stl", "report.html", "report.json"]
    # within half the tolerance (0.01 mm) of the solid
    assert float((tmp_path / "part.step.asked").read_text()) == pytest.approx(0.5 * 0.01)
    report = json.loads((out / "report.json").read_text())
    assert report["analysis"]["triangles"] == 4629 and report["passed"]
    assert (out / "part_model.stl").read_bytes() == (SHARED_STL / "beet_mm.stl").read_bytes()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".part.")]


def test_unreadable_step_bad_input_nothing_written(tmp_path: Path, capsys) -> None:
    assert run(tmp_path, step_job(tmp_path), fake_freecad(tmp_path, False)) == launch.BAD_INPUT
    err = capsys.readouterr().err
    assert "bad input: model.file: FreeCAD could not read part.step" in err
    assert not (tmp_path / "out").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".part.")]


def test_step_only_in_mm_and_other_suffixes_refused(tmp_path: Path) -> None:
    data = step_job(tmp_path)
    data["model"]["units"] = "inch"
    with pytest.raises(PlanInputError, match=r"model.units.*'inch'.*mm for a STEP file"):
        job_from_dict(data, tmp_path / "job.yaml")
    shutil.copyfile(tmp_path / "part.step", tmp_path / "part.iges")
    data["model"].update(file="part.iges", units="mm")
    with pytest.raises(PlanInputError, match=r"model.file.*part.iges.*STL \(.stl\) or STEP \(.step, .stp\)"):
        job_from_dict(data, tmp_path / "job.yaml")
