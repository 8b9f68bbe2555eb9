"""The planner on the Tarus 5-axis mill (tests/data/plan_tarus.yaml: seed 000's convex window, 51 x 53 mm): the
plan's 5-axis mesh op run in the Job after the roughing, the whole Job posted by the Tarus post (and the APT CL
post), simulated (the 5-axis stock simulation) and verified; its simulated cycle time near the planner's estimate;
the report and page with the decision. Then the 5-axis op made to fail (a tilt beyond the machine's C range): the
3-axis plan it replaced is run instead, verified, and the reason reported; and TMM Auto (plan_object) on a piece
of the window whose 5-axis op does not verify falls back the same way in the model's document."""
from __future__ import annotations

import json
import os
import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np

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
        # the simulation times the op by the Tarus post, as the planner's estimate does with the estimated passes
        # (it runs low: the op's postures turn A more at the links; core.plan.mesh5_estimate)
        sim = five["cycle_seconds"]
        self.assertTrue(-0.35 * sim < choice.seconds_5axis - sim < 0.1 * sim, (choice.seconds_5axis, sim))
        self.assertLess(sim, choice.seconds_3axis)
        five_axis.after_run(plan, verified)   # the built op's time beside the estimate
        self.assertEqual(verified["five_axis"]["built_seconds"], sim)
        self.assertFalse(verified["five_axis"]["slower_than_three_axis"])
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
        self.assertIn(f"{sim / 60:.2f} min as built", page)
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

    def test_tmm_auto_falls_back_when_not_verified(self) -> None:
        """TMM Auto (plan_object) with the Tarus recipe and planner.five_axis: always on a 25 x 27 mm piece of the
        window, the first verification (the 5-axis Job's) made to fail with a gouge (injected: the op itself
        verifies): the 3-axis plan is made instead in the model's document with nothing of the 5-axis Job left,
        verified, the reason in the report."""
        import FreeCAD
        import Mesh

        from tmm_workbench.core.geometry.mesh import TriMesh, load_stl, save_stl
        from tmm_workbench.core.plan import recipes

        folder = OUT / "plan_tarus_auto"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        mesh = load_stl(JOB.parent / "seed000_convex_window.stl")
        c = mesh.vertices[mesh.triangles].mean(axis=1)
        keep = mesh.triangles[(c[:, 0] < 127.0) & (c[:, 1] < -6.0)]
        used, index = np.unique(keep, return_inverse=True)
        stl = save_stl(TriMesh(mesh.vertices[used], index.reshape(-1, 3), "piece"), folder / "piece.stl")
        doc = FreeCAD.newDocument("TarusAuto")
        model = doc.addObject("Mesh::Feature", "Piece")
        model.Mesh = Mesh.Mesh(str(stl))
        doc.recompute()
        data = recipes.job_data("modelling_foam", "draft", "Tarus 5-axis", "", str(folder / "out"), "piece")
        data["planner"]["five_axis"] = "always"
        verify, seen = plan_run.verify, []

        def first_gouges(results, plan, where, progress=False):
            report = verify(results, plan, where, progress)
            seen.append([r.op.Label for r in results])
            if len(seen) == 1:
                report.update(passed=False, gouged=True, problems=["gouged 0.5000 mm below the model (injected)"])
            return report

        plan_run.verify = first_gouges
        try:
            job, report = plan_run.plan_object(model, data, progress=False)
        finally:
            plan_run.verify = verify
        self.assertTrue(any(label.startswith(five_axis.LABEL) for label in seen[0]), seen)
        verified = report["verification"]
        self.assertTrue(report["passed"], report["problems"])
        self.assertIn("did not verify: gouged 0.5000 mm", verified["five_axis_fallback"])
        labels = [op.Label for op in job.Operations.Group]
        self.assertFalse(any(label.startswith(five_axis.LABEL) for label in labels), labels)
        self.assertTrue(any(label.startswith("Finish") for label in labels), labels)
        jobs = [o for o in doc.Objects if o.TypeId == "Path::FeaturePython" and hasattr(o, "Operations")]
        self.assertEqual(len(jobs), 1)   # the 5-axis Job removed
        self.assertFalse(any(o.Label.startswith(five_axis.LABEL) for o in doc.Objects))
        decisions = [d for d in report["plan"]["decisions"] if d["topic"] == five_axis.TOPIC]
        self.assertEqual(decisions[-1]["choice"], "fell back to the 3-axis plan")
        self.assertTrue((folder / "out" / "piece.ngc").is_file())
        close_all()
