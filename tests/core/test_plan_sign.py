"""The planner on seed 003's sign (core.geometry.sign): the roughing tool is one that gets down between the
letters (a flat D16 stays more than 1 mm above most of the sign: the roughing op would find no material it can
remove), the rest as for any model."""
from __future__ import annotations

from pathlib import Path

import yaml

from tmm_workbench.core.geometry.mesh import save_stl
from tmm_workbench.core.geometry.sign import SignSpec, make_sign
from tmm_workbench.core.plan import launch
from tmm_workbench.core.plan.job_file import job_from_dict

JOB = Path(__file__).resolve().parents[1] / "data" / "plan_beet.yaml"


def test_sign_roughed_by_a_tool_that_gets_between_the_letters(tmp_path):
    stl = save_stl(make_sign(SignSpec("TMM 2026", width=100, height=50, cell=0.5)).mesh, tmp_path / "sign.stl")
    data = yaml.safe_load(JOB.read_text())
    data["model"]["file"] = str(stl)
    data["tools"] = [
        {"name": "T16", "type": "flat", "diameter": 16, "flutes": 3, "flute_length": 30},
        {"name": "T12", "type": "flat", "diameter": 12, "flutes": 3, "flute_length": 30},
        {"name": "B6", "type": "ball", "diameter": 6, "flutes": 2, "flute_length": 20},
        {"name": "R6", "type": "bull", "diameter": 6, "corner_radius": 1, "flutes": 2, "flute_length": 20}]
    job = job_from_dict(data, tmp_path / "sign.yaml")
    _, _, an, plan = launch.make_plan(job)
    rough = plan.ops[0]
    assert rough.api == "run_roughing" and rough.tool == "T12", rough
    area = 100 * 50
    assert an.reach["T16"].far_area > 0.5 * area > an.reach["T12"].far_area
    assert any("1 mm of at least 0.5 of its area" in d["reason"] for d in plan.as_dict()["decisions"])
