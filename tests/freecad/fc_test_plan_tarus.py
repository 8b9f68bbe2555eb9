"""The planner on the Tarus 5-axis mill (tests/data/plan_tarus.yaml: seed 000's convex window, 51 x 53 mm): the
plan's 5-axis mesh op run in the Job after the roughing, the whole Job posted by the Tarus post (and the APT CL
post), simulated (the 5-axis stock simulation) and verified; its simulated cycle time near the planner's estimate;
the report and page with the decision. Then the 5-axis op made to fail (a tilt beyond the machine's C range): the
3-axis plan it replaced is run instead, verified, and the reason reported. About 40 s on FreeCAD 0.20."""
from __future__ import annotations

import json
import os
import re
import shutil
from dataclasses import replace
from pathlib import Path

from fc_helpers import OUT, FreeCADTestCase, close_all
from tmm_workbench.app import plan_five, plan_run
from tmm_workbench.core.plan import five_axis, launch
from tmm_workbench.core.plan.job_file import read_job

JOB = Path(__file__).resolve().parents[1] / "data" / "plan_tarus.yaml"


def planned(folder: Path):
    job = read_job(JOB)
    job = replace(job, outputs=replace(job.outputs, dir=folder.parent / f"{folder.name}_out"))
    mesh, _, an, plan = launch.make_plan(job)
    return job, mesh, an, plan


class PlanTarus(FreeCADTestCase):
    def test_five_axis_plan_verified(self) -> None:
        folder = OUT / "plan_tarus"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        job, mesh, an, plan = planned(folder)
        choice = plan.five_axis
        self.assertIsNotNone(choice)
        (folder / "plan.json").write_text(json.dumps(launch.plan_document(job, plan, job.model.file)))
        os.environ["TMM_PLAN_FILE"] = str(folder / "plan.json")
        self.assertEqual(plan_run.main(), 0)
        verified = json.loads((folder / "verify.json").read_text())
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertNotIn("five_axis_fallback", verified)
        self.assertEqual([o["label"] for o in verified["ops"]], [o.label for o in plan.ops])
        self.assertLess(verified["deepest_gouge_mm"], job.finish.tolerance)
        five = verified["ops"][1]
        self.assertTrue(five["label"].startswith(five_axis.LABEL))
        # the simulation times the op by the Tarus post, as the planner's estimate did (its own path, the same
        # strategy and settings)
        self.assertLess(abs(five["cycle_seconds"] - choice.seconds_5axis), 0.2 * choice.seconds_5axis)
        self.assertLess(five["cycle_seconds"], choice.seconds_3axis)
        # the whole Job through the Tarus post: joints, the head tilted in the 5-axis op, upright in the roughing
        gcode = (folder / "seed000_convex_window.ngc").read_text()
        self.assertIn("(TMM Tarus post", gcode)
        roughing, finish = gcode.split(f"(operation: {five['label']})")
        tilts = [abs(float(c)) for c in re.findall(r" C(-?\d+\.\d+)", finish)]
        self.assertTrue(all(abs(float(c)) < 1e-9 for c in re.findall(r" C(-?\d+\.\d+)", roughing)))
        self.assertGreater(max(tilts), 1.0)
        self.assertLessEqual(max(tilts), job.machine.tilt_limit + 1e-6)
        apt = (folder / "seed000_convex_window.apt").read_text()
        self.assertGreater(apt.count("GOTO/"), 100)
        tip = folder / launch.TIP_GCODE   # tool-tip coordinates for the picture
        self.assertIn("TCP mode", tip.read_text())
        # the launcher's pages: the decision with both times, the machine on the setup sheet
        for name in ("plan.json", "verify.json"):
            (folder / name).unlink()
        report = launch.finish_outputs(folder, job, mesh, an, plan, verified)
        out = job.outputs.dir
        self.assertFalse((out / launch.TIP_GCODE).exists())
        self.assertGreater((out / "seed000_convex_window_toolpath.png").stat().st_size, 10_000)
        self.assertEqual(report["machine"]["type"], "tarus5")
        page = (out / "report.html").read_text()
        self.assertIn("5-axis finishing", page)
        self.assertIn(f"{choice.seconds_5axis / 60:.2f} min", page)
        close_all()

    def test_failing_five_axis_op_falls_back(self) -> None:
        folder = OUT / "plan_tarus_fallback"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        job, _, _, plan = planned(folder)
        doc = launch.plan_document(job, plan, job.model.file)
        five = next(op for op in doc["ops"] if op["api"] == "run_mesh5")
        five["kwargs"]["tilt_limit_deg"] = 60.0   # beyond the Tarus's C range: the op refuses it
        doc["fcstd"] = False
        results, verified = plan_five.run(doc, folder, plan_run.run_plan)
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertIn("tilt limit 60", verified["five_axis_fallback"])
        self.assertIn("the 3-axis plan instead", verified["replanned"][0])
        fallback = [o["label"] for o in doc["five_axis"]["fallback_ops"]]
        self.assertEqual([r.op.Label for r in results], fallback)
        self.assertTrue(any(label.startswith("Finish shallow") for label in fallback))
        five_axis.fallen_back(plan, plan.five_axis, verified["five_axis_fallback"])
        self.assertEqual([op.label for op in plan.ops], fallback)
        self.assertIn("(TMM Tarus post", (folder / "seed000_convex_window.ngc").read_text())
        close_all()
