"""The planner on seed 003's sign (core.geometry.sign): the roughing tool is one that gets down between the
letters (a flat D16 stays more than 1 mm above most of the sign: the roughing op would find no material it can
remove), the rest as for any model."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from tmm_workbench.core.geometry.mesh import save_stl
from tmm_workbench.core.geometry.sign import SignSpec, make_sign
from tmm_workbench.core.plan import decide, launch
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


def sign_job(tmp_path, tools: list):
    """Seed 003's wooden sign of tests/core/sign.py (block letters and a border raised 2.5 mm, walls at 85 deg:
    sharp concave corners at their feet) with `tools` after a flat D8 roughing tool, comparison off (fast)."""
    from tests.core.sign import sign_mesh

    stl = save_stl(sign_mesh(0.4), tmp_path / "sign.stl")
    data = yaml.safe_load(JOB.read_text())
    data["model"]["file"] = str(stl)
    data["planner"]["compare_cutters"] = False
    data["finish"]["cusp"] = 0.02
    data["tools"] = [{"name": "F8", "type": "flat", "diameter": 8, "flutes": 2, "flute_length": 20}] + tools
    return job_from_dict(data, tmp_path / "sign.yaml")


BALLS = [{"name": f"B{d:g}", "type": "ball", "diameter": d, "flutes": 2, "flute_length": 10} for d in (6, 3, 1)]


def test_pencil_after_the_rest_in_the_corners(tmp_path):
    """The ball D6 finishes, the D3 takes the rest, and the D1, which the reach tests say leaves far less in the
    letters' corners, pencils the creases with passes outward over the band between the D3's radius and its own
    (only where material is left; optional: left out if it alone fails the verification)."""
    _, _, an, plan = launch.make_plan(sign_job(tmp_path, BALLS))
    labels = [o.label for o in plan.ops]
    assert labels[-3:] == ["Rest B3", "Pencil B1", "Clean-up B1"], labels
    rest, pencil, cleanup = plan.ops[-3:]
    assert rest.kwargs["region"] == "rest" and "pattern" not in rest.kwargs
    step = pencil.kwargs["stepover"]   # the cusp's step-over of the D1: (1.5 - 0.5) mm covered outward
    wanted = {"region": "rest", "rest_from": "earlier_ops", "pattern": "pencil", "pencil_source": "creases",
              "pencil_passes": 1 + math.ceil(1.0 / step), "rest_tolerance": 0.01}
    assert {k: pencil.kwargs.get(k) for k in wanted} == wanted
    assert pencil.optional and rest.optional and cleanup.optional
    # then the D1 as a raster over what is still left that it reaches (the floors between the creases' passes)
    assert {k: cleanup.kwargs.get(k) for k in ("region", "rest_from", "pattern", "stepover")} == {
        "region": "rest", "rest_from": "earlier_ops", "pattern": None, "stepover": step}
    left = {t: an.reach[t].unreached_area for t in ("B6", "B3", "B1")}
    assert left["B6"] > left["B3"] > left["B1"] + decide.PENCIL_GAIN * an.seen_area > 0, left
    why = next(d for d in plan.decisions if d.topic == "pencil")
    assert why.choice.startswith("B1 (ball D1") and f"{left['B3']:.0f} mm2" in why.reason, why


def test_no_pencil_without_a_smaller_tool_that_reaches_more(tmp_path):
    """Without the D1 the rest is the last op and the pencil decision says why there is none; a D2.8 that the
    reach tests find hardly better than the D3 is not worth its op either."""
    _, _, _, plan = launch.make_plan(sign_job(tmp_path, BALLS[:2]))
    assert [o.label for o in plan.ops][-1] == "Rest B3"   # nor a clean-up
    why = next(d for d in plan.decisions if d.topic == "pencil")
    assert why.choice == "none" and "no smaller library tool" in why.reason
    near = BALLS[:2] + [{"name": "B2.8", "type": "ball", "diameter": 2.8, "flutes": 2, "flute_length": 10}]
    _, an, plan = launch.make_plan(sign_job(tmp_path, near))[1:]
    assert an.reach["B2.8"].unreached_area > an.reach["B3"].unreached_area - decide.PENCIL_GAIN * an.seen_area
    assert not any(o.label.startswith("Pencil") for o in plan.ops)


def test_left_in_reach_judges_only_what_the_smallest_tool_reaches():
    """The Job's deviation judged where the smallest library tool reaches: a patch left 0.05 mm on the open
    background counts (its area, its depth), 1 mm left in the sharp corner at the border's foot (out of any
    ball's reach) does not; a larger ball reaches less."""
    from tests.core.sign import BORDER, sign_mesh
    from tmm_workbench.core.plan.left_check import left_in_reach
    from tmm_workbench.core.sim.grid import Grid
    from tmm_workbench.core.sim.stock import mesh_heights
    from tmm_workbench.core.tools.cutter import Cutter

    mesh = sign_mesh(0.4)
    grid = Grid.covering(0, 0, 84, 44, 0.4)
    design = mesh_heights(mesh, grid)
    x, y = np.meshgrid(grid.xs(), grid.ys())
    deviation = np.zeros_like(design)
    patch = (x > 5) & (x < 7) & (y > 5) & (y < 7)
    corner = (x > BORDER) & (x < BORDER + 0.4) & (y > 10) & (y < 30)
    deviation[patch], deviation[corner] = 0.05, 1.0
    small = left_in_reach(mesh, grid, design, deviation, "B1", Cutter.ball(1.0), 0.01)
    assert small["left_above_tolerance_mm2"] == pytest.approx(patch.sum() * 0.16)
    assert small["most_left_mm"] == pytest.approx(0.05)
    assert small["out_of_reach_mm2"] >= corner.sum() * 0.16
    assert small["left_above_allowance_mm2"] == small["left_above_tolerance_mm2"]   # the cusp under the tolerance
    # a finish whose cusp is above the 0.05 mm the patch keeps: its passes leave that by design
    coarse = left_in_reach(mesh, grid, design, deviation, "B1", Cutter.ball(1.0), 0.01, cusp=0.06)
    assert coarse["allowance_mm"] == 0.06 and coarse["left_above_allowance_mm2"] == 0.0
    assert coarse["left_above_tolerance_mm2"] == small["left_above_tolerance_mm2"]
    large = left_in_reach(mesh, grid, design, deviation, "B6", Cutter.ball(6.0), 0.01)
    assert large["out_of_reach_mm2"] > small["out_of_reach_mm2"]
    assert large["reached_mm2"] + large["out_of_reach_mm2"] == pytest.approx(small["reached_mm2"] +
                                                                              small["out_of_reach_mm2"])


def test_left_in_reach_with_the_whole_tool():
    """A D1 whose flutes are 1 mm long does not reach the background within its shank's radius and clearance of
    the border's 2.5 mm wall (its shank would meet the wall's top): what is left there counts with the cutter
    alone, not with the whole tool; with 10 mm flutes the shank passes above the wall and it counts again."""
    from tests.core.sign import BORDER, sign_mesh
    from tmm_workbench.core.plan.left_check import left_in_reach, whole_tool
    from tmm_workbench.core.sim.grid import Grid
    from tmm_workbench.core.sim.stock import mesh_heights
    from tmm_workbench.core.tools.cutter import Cutter

    mesh = sign_mesh(0.4)
    grid = Grid.covering(0, 0, 84, 44, 0.4)
    design = mesh_heights(mesh, grid)
    x, y = np.meshgrid(grid.xs(), grid.ys())
    deviation = np.zeros_like(design)
    band = (x > BORDER + 0.8) & (x < BORDER + 1.2) & (y > 10) & (y < 30)   # one column, 0.8-1.2 mm out
    deviation[band] = 0.05
    cutter = Cutter.ball(1.0)
    spec = {"holder": "ER11 nut", "stick_out": 20.0, "flute_length": 1.0, "length": 30.0, "shank_diameter": None}
    alone = left_in_reach(mesh, grid, design, deviation, "B1", cutter, 0.01)
    short = left_in_reach(mesh, grid, design, deviation, "B1", cutter, 0.01, assembly=whole_tool(cutter, spec))
    assert alone["left_above_tolerance_mm2"] == pytest.approx(band.sum() * 0.16)
    assert short["left_above_tolerance_mm2"] < 0.5 * alone["left_above_tolerance_mm2"]
    assert short["out_of_reach_mm2"] > alone["out_of_reach_mm2"] + 0.5 * band.sum() * 0.16
    long = whole_tool(cutter, dict(spec, flute_length=10.0))
    assert left_in_reach(mesh, grid, design, deviation, "B1", cutter, 0.01, assembly=long) == alone
    assert whole_tool(cutter, dict(spec, holder=None)) is None   # no holder: no shank checked
