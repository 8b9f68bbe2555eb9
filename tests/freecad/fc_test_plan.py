"""The automatic planner's FreeCAD side (app/plan_run.py) on the plan core.plan makes for tests/data/plan_beet.yaml
(beet_mm.stl, coarse values): one Job with the planned ops, their tool controllers and feeds, the whole Job posted
(every tool's change in the G-code), simulated and verified (no gouge below the tolerance, no rapid through stock),
the document saved and reopened with its ops recomputing after a changed value. On a block raised from a plate
(sharp concave corners at its foot): the rest and the pencil planned, run, and what they take off verified. A STEP
model tessellated and planned."""
from __future__ import annotations

import json
import os
import re
import shutil
import sys
from pathlib import Path
from typing import Any

import FreeCAD
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, close_all, parse_gcode
from tmm_workbench.app import op_base, plan_run
from tmm_workbench.core.plan import launch, progress_note
from tmm_workbench.core.plan.job_file import read_job

JOB = Path(__file__).resolve().parents[1] / "data" / "plan_beet.yaml"


def freecadcmd() -> str:
    """The freecadcmd running this test (the command starts one itself)."""
    home = Path(FreeCAD.getHomePath()) / "bin"
    for c in (os.environ.get("TMM_FREECADCMD"), sys.executable if "freecad" in Path(sys.executable).name.lower()
              else None, shutil.which("freecadcmd"), shutil.which("FreeCADCmd"), home / "freecadcmd",
              home / "FreeCADCmd"):
        if c and Path(c).is_file():
            return str(c)
    raise AssertionError(f"no freecadcmd found (sys.executable {sys.executable}, {home}); set TMM_FREECADCMD")


class failing:
    """plan_run.verify made to name `label` failing (shank too close) on the calls `when(n, labels)` says (n from
    1, the labels of the ops verified), the labels of each call appended to `calls`."""

    def __init__(self, label: str, calls: list, when: Any) -> None:
        self.label, self.calls, self.when, self.real = label, calls, when, plan_run.verify

    def __enter__(self) -> "failing":
        def verify(results: list, plan_doc: dict, out: Path, progress: Any = False) -> dict:
            report = self.real(results, plan_doc, out, progress)
            self.calls.append([r.op.Label for r in results])
            if self.when(len(self.calls), self.calls[-1]):
                report.update(passed=False, problems=[f"{self.label}: shank too close"], failing_ops=[self.label])
            return report

        plan_run.verify = verify
        return self

    def __exit__(self, *exc: Any) -> None:
        plan_run.verify = self.real


class PlanBeet(FreeCADTestCase):
    def test_plan_runs_verified(self) -> None:
        job = read_job(JOB)
        _, moved, an, plan = launch.make_plan(job)
        self.assertFalse(moved)
        folder = OUT / "plan_beet"
        folder.mkdir(parents=True, exist_ok=True)
        doc = launch.plan_document(job, plan, job.model.file)
        (folder / "plan.json").write_text(json.dumps(doc))
        os.environ["TMM_PLAN_FILE"] = str(folder / "plan.json")
        os.environ[progress_note.ENV] = str(folder / "progress.json")
        computed: dict = {}
        real = op_base.TmmOp.execute

        def counted(proxy: Any, obj: Any) -> None:
            computed[obj.Name] = computed.get(obj.Name, 0) + 1
            real(proxy, obj)

        op_base.TmmOp.execute = counted
        try:
            self.assertEqual(plan_run.main(), 0)
        finally:
            op_base.TmmOp.execute = real
            del os.environ[progress_note.ENV]
        verified = json.loads((folder / "verify.json").read_text())
        self.assertTrue(verified["passed"], verified["problems"])
        # each op computed once, with its library tool (no second computation once the controller is set; on 1.1
        # none when the bit's shape body is rebuilt after the next recompute: compat.settle_toolbit)
        self.assertEqual(sorted(computed.values()), [1] * len(plan.ops))
        last = progress_note.read(folder / "progress.json")   # the run's last progress note: its last step
        self.assertEqual(last, {"step": len(plan.ops) + 4, "steps": len(plan.ops) + 4, "doing": "saving the document"})
        self.assertLess(verified["deepest_gouge_mm"], job.finish.tolerance)
        self.assertEqual([o["label"] for o in verified["ops"]], [o.label for o in plan.ops])
        self.assertTrue(all(o["moves"] > 0 and o["cycle_seconds"] > 0 for o in verified["ops"]))
        self.assertAlmostEqual(verified["cycle_seconds"], sum(o["cycle_seconds"] for o in verified["ops"]), delta=0.2)
        reach = verified["left_in_reach"]   # judged where the most reaching tool reaches; the rest reported
        self.assertEqual(reach["tool"], plan.reach_tool)
        self.assertGreater(reach["reached_mm2"], 0)
        self.assertGreater(reach["out_of_reach_mm2"], 0)      # the beet's underside seen from above, its wrinkles
        self.assertGreaterEqual(reach["most_left_mm"], reach["left_99_percentile_mm"])
        self.assertGreater(verified["removed_volume_mm3"], 0)
        # the whole Job in one G-code file: each planned tool's change and spindle speed, feeds from the table
        gcode = (folder / "beet_mm.ngc").read_text()
        tools = list(dict.fromkeys(op.tool for op in plan.ops))   # the library's tools in their first use
        self.assertLess(len(tools), len(plan.ops))                # the ball finishes both shallow and steep
        self.assertEqual(gcode.count("M6 T"), len(tools))
        for number, name in enumerate(tools, 1):
            op = next(o for o in plan.ops if o.tool == name)
            for line in (f"M6 T{number}", f"(begin operation: TC: {name})", f"M3 S{op.kwargs['spindle_speed']}"):
                self.assertTrue(line in gcode, line)   # (assertIn would print the whole G-code)
        for op in plan.ops:   # each op's Path opens with its planned label (set before it computed)
            self.assertTrue(f"({op.label})" in gcode, op.label)
        feeds = {f for *_, f in parse_gcode(gcode) if f is not None}
        self.assertIn(plan.ops[0].kwargs["horiz_feed"], feeds)
        self.assertTrue((folder / "beet_mm_sim.png").stat().st_size > 10_000)
        close_all()
        # an ordinary Job: opened again, a value changed, recomputed
        reopened = FreeCAD.openDocument(str(folder / "beet_mm.FCStd"))
        ops = {o.Label: o for o in reopened.Objects if o.Label in {p.label for p in plan.ops}}
        self.assertEqual(sorted(ops), sorted(p.label for p in plan.ops))
        self.assertEqual(sorted(o.ToolController.Label for o in ops.values()),
                         sorted(f"TC: {p.tool}" for p in plan.ops))
        # the library's tool on its controller: flute length, overall length (stick-out + 3 D grip), holder
        ball = next(o.ToolController for o in ops.values() if o.ToolController.Label == "TC: T2 ball D6")
        self.assertAlmostEqual(float(ball.Tool.CuttingEdgeHeight), 20.0)
        self.assertAlmostEqual(float(ball.Tool.Length), 30.0 + 3 * 6.0)
        self.assertEqual((ball.TmmHolder, float(ball.TmmStickOut)), ("ER16 nut", 30.0))
        self.assertIsNotNone(next(o for o in verified["ops"] if "T2" in o["label"])["holder"])
        steep = ops[plan.ops[-1].label]
        self.assertAlmostEqual(float(steep.StepDown), plan.ops[-1].kwargs["step_down"], places=6)
        before = len(steep.Path.Commands)
        steep.StepDown = 2 * float(steep.StepDown)
        reopened.recompute()
        self.assertTrue(steep.isValid(), steep.getStatusString())
        self.assertLess(len(steep.Path.Commands), before)

    def test_optional_op_left_out(self) -> None:
        """An optional op (the rest) failing the verification alone is changed (its moves left out where the shank
        would come too close, core.plan.replan), and when that fails too, left out and the Job verified again: the
        verifications with it are made to name the last op (a real one needs a long run); the last is the real."""
        job = read_job(JOB)
        _, _, _, plan = launch.make_plan(job)
        folder = OUT / "plan_beet_drop"
        folder.mkdir(parents=True, exist_ok=True)
        doc = launch.plan_document(job, plan, job.model.file)
        last = doc["ops"][-1]
        last["optional"] = True
        (folder / "plan.json").write_text(json.dumps(doc))
        os.environ["TMM_PLAN_FILE"] = str(folder / "plan.json")
        calls: list = []
        with failing(last["label"], calls, lambda n, labels: last["label"] in labels):
            self.assertEqual(plan_run.main(), 0)
        verified = json.loads((folder / "verify.json").read_text())
        # with it, with it changed, with it as planned again (failing), without it
        self.assertEqual(calls[1:3], [calls[0], calls[0]])
        self.assertEqual(calls[3], calls[0][:-1])
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertEqual(verified["replanned"], [f"left out {last['label']}: {last['label']}: shank too close"])
        self.assertEqual([o["label"] for o in verified["ops"]], calls[3])
        gcode = (folder / "beet_mm.ngc").read_text()
        self.assertFalse(f"(begin operation: {last['label']})" in gcode)
        self.assertTrue(f"(begin operation: {doc['ops'][0]['label']})" in gcode)
        saved = FreeCAD.openDocument(str(folder / "beet_mm.FCStd"))
        self.assertFalse([o for o in saved.Objects if o.Label == last["label"]])

    def test_optional_op_changed(self) -> None:
        """An optional op failing the verification alone, verified once its moves where the shank would come too
        close are left out in place of lifted (the second verification is the real one), is kept so changed."""
        job = read_job(JOB)
        _, _, _, plan = launch.make_plan(job)
        folder = OUT / "plan_beet_change"
        folder.mkdir(parents=True, exist_ok=True)
        doc = dict(launch.plan_document(job, plan, job.model.file), gcode=False, fcstd=False, heat_map=False)
        last = doc["ops"][-1]
        last["optional"] = True
        calls: list = []
        with failing(last["label"], calls, lambda n, labels: n == 1):
            results, verified = plan_run.run_plan(doc, folder)
        self.assertEqual(len(calls), 2)
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertEqual(len(verified["replanned"]), 1)
        self.assertTrue(verified["replanned"][0].startswith(f"changed {last['label']}: its moves where the shank"))
        self.assertEqual([r.op.Label for r in results], [o["label"] for o in doc["ops"]])
        self.assertEqual(results[-1].op.HolderCollision, "LeaveOut")
        self.assertEqual(results[0].op.getPropertyByName("HolderCollision"), "Lift")   # the others as planned

    def test_optional_op_with_nothing_to_cut_left_out(self) -> None:
        """An optional rest op whose Region 'Rest' is empty (the ops before it left nothing above its rest tolerance)
        fails to compute: it is removed with its tool controller and named with the reason, the run goes on and
        verifies (it stopped the whole run before, 3-axis and 5-axis alike); a required op's failure still stops it."""
        job = read_job(JOB)
        _, _, _, plan = launch.make_plan(job)
        folder = OUT / "plan_beet_nothing"
        folder.mkdir(parents=True, exist_ok=True)
        doc = dict(launch.plan_document(job, plan, job.model.file), gcode=False, fcstd=False, heat_map=False)
        shallow = next(o for o in doc["ops"] if o["api"] == "run_surface")
        rest = dict(shallow, label="Rest T3 bull D6 r1", tool="T3 bull D6 r1", optional=True,
                    kwargs=dict(shallow["kwargs"], tool="bullnose", corner_radius=1.0, region="rest",
                                rest_tolerance=10.0))   # the beet is 7 mm tall: nothing is left 10 mm above it
        doc["ops"].append(rest)
        results, verified = plan_run.run_plan(doc, folder)
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertEqual(len(verified["replanned"]), 1)
        self.assertTrue(verified["replanned"][0].startswith(f"left out {rest['label']}: Region 'Rest'"),
                        verified["replanned"])
        self.assertEqual([r.op.Label for r in results], [o["label"] for o in doc["ops"][:-1]])
        self.assertEqual(sorted(o.Name for o in results[0].job.Operations.Group), sorted(r.op.Name for r in results))
        self.assertEqual(len(results[0].job.Tools.Group), len({r.op.ToolController.Name for r in results}))
        rest["optional"] = False
        with self.assertRaises(Exception):
            plan_run.run_plan(doc, OUT / "plan_beet_nothing_required")

    def test_command_end_to_end(self) -> None:
        """`python -m tmm_workbench.plan`'s run(): the core plans, a freecadcmd of its own runs the plan, the files
        appear in the output folder (and nothing else beside it), exit code 0."""
        import yaml

        data = yaml.safe_load(JOB.read_text())
        data["model"]["file"] = str(read_job(JOB).model.file)
        data["outputs"]["dir"] = str(OUT / "plan_command" / "out")
        job_file = OUT / "plan_command" / "job.yaml"
        shutil.rmtree(job_file.parent, ignore_errors=True)   # a run before in the same output folder left its files
        job_file.parent.mkdir(parents=True)
        job_file.write_text(yaml.safe_dump(data))
        self.assertEqual(launch.run(str(job_file), freecadcmd(), quiet=True), launch.VERIFIED)
        out = OUT / "plan_command" / "out"
        self.assertEqual(sorted(p.name for p in out.iterdir()),
                         ["beet_mm.FCStd", "beet_mm.ngc", "beet_mm_sim.png", "beet_mm_toolpath.png", "report.html",
                          "report.json"])
        self.assertEqual(sorted(p.name for p in out.parent.iterdir()), ["job.yaml", "out"])
        report = json.loads((out / "report.json").read_text())
        self.assertTrue(report["passed"])
        self.assertEqual(report["files"], sorted(p.name for p in out.iterdir()))
        self.assertEqual([o["label"] for o in report["verification"]["ops"]],
                         [o["label"] for o in report["plan"]["ops"]])
        self.assertTrue(all(d["reason"] for d in report["plan"]["decisions"]))
        # the page for people: the verdict, each op (in the setup sheet's op list), both pictures inside
        page = (out / "report.html").read_text()
        self.assertTrue("VERIFIED" in page)
        for op in report["plan"]["ops"]:
            self.assertTrue(f"<td>{op['label']}</td>" in page, op["label"])
        self.assertEqual(page.count("data:image/png;base64,"), 2)
        self.assertGreater((out / "beet_mm_toolpath.png").stat().st_size, 10_000)
        # the same job file again: the same files byte for byte (but the document, where FreeCAD stores times)
        data["outputs"]["dir"] = str(OUT / "plan_command" / "again")
        job_file.write_text(yaml.safe_dump(data))
        self.assertEqual(launch.run(str(job_file), freecadcmd(), quiet=True), launch.VERIFIED)
        again = OUT / "plan_command" / "again"
        for name in report["files"]:
            if name.endswith(".FCStd"):
                continue
            self.assertEqual((out / name).read_bytes(), (again / name).read_bytes(), name)


def block_on_plate() -> Any:
    """A 30 x 20 mm plate with a 12 x 6 mm block raised 2.5 mm in its middle, a height field on 0.4 mm (its walls
    one cell wide, 81 deg): a ball leaves a fillet of its radius at the block's foot."""
    from tmm_workbench.core.geometry.mesh import TriMesh

    nx, ny = 76, 51
    X, Y = np.meshgrid(np.linspace(0, 30, nx), np.linspace(0, 20, ny))
    Z = np.where((np.abs(X - 15) <= 6) & (np.abs(Y - 10) <= 3), 2.5, 0.0)
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    faces = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return TriMesh(np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]), faces, "block")


class PlanPencil(FreeCADTestCase):
    def test_rest_and_pencil_take_the_corners(self) -> None:
        """Ball D6 finishing, D3 rest, D1 pencil along the creases the D3 leaves, D1 clean-up raster: the rest and
        the pencil report less volume after than before, and the simulation of the Job without the pencil and the
        clean-up leaves more above the tolerance where the D1 reaches (and more volume) than with them."""
        import yaml

        from tmm_workbench.core.geometry.mesh import save_stl
        from tmm_workbench.core.plan.job_file import job_from_dict

        folder = OUT / "plan_pencil"
        folder.mkdir(parents=True, exist_ok=True)
        data = yaml.safe_load(JOB.read_text())
        data["model"]["file"] = str(save_stl(block_on_plate(), folder / "block.stl"))
        data["outputs"]["dir"] = str(folder / "out")
        data["planner"].update(compare_cutters=False, sim_cell=0.2)
        data["finish"]["cusp"] = 0.01   # the finishing's cusps within the tolerance: what is left above it, corners
        data["tools"] = [{"name": "F8", "type": "flat", "diameter": 8, "flute_length": 20}] + [
            {"name": f"B{d}", "type": "ball", "diameter": d, "flute_length": 10} for d in (6, 3, 1)]
        job = job_from_dict(data, folder / "job.yaml")
        _, _, an, plan = launch.make_plan(job)
        self.assertEqual([o.label for o in plan.ops][-3:], ["Rest B3", "Pencil B1", "Clean-up B1"])
        doc = dict(launch.plan_document(job, plan, job.model.file), gcode=False, fcstd=False, heat_map=False)
        results, verified = plan_run.run_plan(doc, folder)
        self.assertTrue(verified["passed"], verified["problems"])
        self.assertEqual(verified["replanned"], [])
        rows = {o["label"]: o for o in verified["ops"]}
        for label in ("Rest B3", "Pencil B1"):
            before, after = (float(v) for v in re.search(r"([\d.]+) mm3 above the design before, ([\d.]+) mm3 "
                                                          r"after", rows[label]["rest"]).groups())
            self.assertLess(after, 0.5 * before, rows[label]["rest"])
        plan_run.remove_unused(results[0].job, results[:-2])   # the clean-up and the pencil (their tool controller)
        without = plan_run.verify(results[:-2], doc, folder)
        with_it, left = verified["left_in_reach"], without["left_in_reach"]
        self.assertEqual(with_it["tool"], "B1")
        self.assertGreater(left["left_above_tolerance_mm2"], 1.5 * with_it["left_above_tolerance_mm2"] + 5.0)
        self.assertGreater(without["remaining_volume_mm3"], verified["remaining_volume_mm3"])


class PlanStep(FreeCADTestCase):
    def test_step_model_planned(self) -> None:
        """A STEP made here from a Part solid (a 30 x 20 x 4 mm plate with a boss r 6 h 3): app/step_mesh.py
        tessellates it within half the tolerance (every triangle's centre that close to the solid's surface, the
        boss's rim in facets as fine as that needs), a file that is no STEP is refused; `tmm plan` on it runs
        verified and leaves the tessellation beside the G-code."""
        import Part
        import yaml

        from tmm_workbench.app.step_mesh import step_mesh
        from tmm_workbench.core.geometry.mesh import load_stl

        folder = OUT / "plan_step"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        solid = Part.makeBox(30, 20, 4).fuse(Part.makeCylinder(6, 3, FreeCAD.Vector(15, 10, 4)))
        solid.exportStep(str(folder / "part.step"))
        self.assertEqual(step_mesh(folder / "part.step", folder / "mesh.stl", 0.005), len(
            load_stl(folder / "mesh.stl").triangles))
        mesh = load_stl(folder / "mesh.stl")
        centres = mesh.vertices[mesh.triangles].mean(axis=1)
        far = max(solid.distToShape(Part.Vertex(FreeCAD.Vector(*map(float, c))))[0] for c in centres[::7])
        self.assertLess(far, 0.005 + 1e-6)
        rim = np.hypot(mesh.vertices[:, 0] - 15, mesh.vertices[:, 1] - 10)
        on_rim = (np.abs(rim - 6) < 1e-3) & (np.abs(mesh.vertices[:, 2] - 7) < 1e-6)
        self.assertGreater(on_rim.sum(), np.pi / np.arccos(1 - 0.005 / 6) * 0.9)   # facets for a 5 um chord
        (folder / "not.step").write_text("solid not a step\n")
        with self.assertRaises(ValueError):
            step_mesh(folder / "not.step", folder / "not.stl", 0.005)
        data = yaml.safe_load(JOB.read_text())
        data["model"]["file"] = str(folder / "part.step")
        data["outputs"]["dir"] = str(folder / "out")
        data["planner"]["compare_cutters"] = False
        (folder / "job.yaml").write_text(yaml.safe_dump(data))
        self.assertEqual(launch.run(str(folder / "job.yaml"), freecadcmd(), quiet=True), launch.VERIFIED)
        out = sorted(p.name for p in (folder / "out").iterdir())
        self.assertEqual(out, ["part.FCStd", "part.ngc", "part_model.stl", "part_sim.png", "part_toolpath.png",
                               "report.html", "report.json"])
        report = json.loads((folder / "out" / "report.json").read_text())
        self.assertEqual(report["analysis"]["size_mm"], [30.0, 20.0, 7.0])


def stock_job(folder: Path, stock: dict, **machine) -> Any:
    """tests/data/plan_beet.yaml with `stock`, no cutter comparison (a shorter run), the machine's extras."""
    import yaml

    from tmm_workbench.core.plan.job_file import job_from_dict

    folder.mkdir(parents=True, exist_ok=True)
    data = yaml.safe_load(JOB.read_text())
    data["model"]["file"] = str(read_job(JOB).model.file)
    data["outputs"]["dir"] = str(folder / "out")
    data["planner"]["compare_cutters"] = False
    data["stock"] = stock
    data["machine"].update(machine)
    return job_from_dict(data, folder / "job.yaml")


def feed_moves_from(op: Any) -> tuple[np.ndarray, np.ndarray]:
    """The op's cutting moves' start and end points (x, y, z): the position before each G1 (modal) and after."""
    pos, start, end = {}, [], []
    for c in op.Path.Commands:
        before = dict(pos)
        pos.update({k: c.Parameters[k] for k in "XYZ" if k in c.Parameters})
        if c.Name in ("G1", "G01") and len(before) == 3:
            start.append([before[k] for k in "XYZ"])
            end.append([pos[k] for k in "XYZ"])
    return np.array(start), np.array(end)


def feed_moves(op: Any) -> np.ndarray:
    """The op's cutting moves' end points (x, y, z)."""
    return np.array([(c.Parameters["X"], c.Parameters["Y"], c.Parameters["Z"]) for c in op.Path.Commands
                     if c.Name in ("G1", "G01") and {"X", "Y", "Z"} <= set(c.Parameters)])


class PlanStocks(FreeCADTestCase):
    def test_cylinder_stock_planned_and_verified(self) -> None:
        """A cylinder stock: FreeCAD's CreateCylinder in the Job, the roughing cutting only within it (its feed
        moves under the stock's top within the circle grown by the tool's radius but for its entries from the air
        beside it), the simulation starting from
        it (it removes less than the cylinder holds), verified; the machine's rapids on every tool controller."""
        folder = OUT / "plan_cylinder"
        job = stock_job(folder, {"type": "cylinder", "margin": 2, "above": 1}, rapid=[3000, 1500])
        _, _, _, plan = launch.make_plan(job)
        doc = dict(launch.plan_document(job, plan, job.model.file), fcstd=False, heat_map=False)
        stock = doc["stock"]
        results, verified = plan_run.run_plan(doc, folder)
        self.assertTrue(verified["passed"], verified["problems"])
        fc_stock = results[0].job.Stock
        self.assertAlmostEqual(float(fc_stock.Radius), stock["radius_mm"], places=4)
        self.assertAlmostEqual(float(fc_stock.Height), stock["box_mm"][5] - stock["box_mm"][2], places=4)
        base = fc_stock.Placement.Base
        self.assertAlmostEqual(base.x, stock["centre_mm"][0], places=4)
        self.assertAlmostEqual(base.z, stock["box_mm"][2], places=4)
        self.assertEqual([t.Label for t in results[0].job.Tools.Group],   # no default tool left in the Job
                         list(dict.fromkeys(f"TC: {o.tool}" for o in plan.ops)))
        rough = results[0].op
        start, end = feed_moves_from(rough)
        deep = end[:, 2] < stock["box_mm"][5] - 0.01
        self.assertGreater(deep.sum(), 100)
        r_tool = rough.ToolController.Tool.Diameter.Value / 2
        off_axis = np.hypot(end[:, 0] - stock["centre_mm"][0], end[:, 1] - stock["centre_mm"][1])
        outside = deep & (off_axis > stock["radius_mm"] + r_tool + 0.01)
        # the box's corners beyond the cylinder are 21 % of its area: a box stock's clearing would go there; the
        # cylinder's feed moves end within the circle grown by the tool's radius, but for each layer's entry: a
        # plunge in the air beside the stock (straight down: a step-over and the roughing's 1 mm air margin
        # beyond the first loop, whose tool touches the stock), then fed in at depth
        self.assertGreater(outside.sum(), 0)
        plunge = np.all(np.isclose(start[:, :2], end[:, :2], atol=1e-6), axis=1) & (start[:, 2] > end[:, 2])
        self.assertTrue(plunge[outside].all(), end[outside & ~plunge][:5])
        step = float(plan.ops[0].kwargs["stepover_percent"]) / 100 * 2 * r_tool
        self.assertLess(off_axis[outside].max(), stock["radius_mm"] + r_tool + step + 1.0 + 0.05)
        volume = np.pi * stock["radius_mm"] ** 2 * (stock["box_mm"][5] - stock["box_mm"][2])
        self.assertLess(verified["removed_volume_mm3"], volume)
        box = stock["box_mm"]
        self.assertGreater((box[3] - box[0]) * (box[4] - box[1]) * (box[5] - box[2]) - volume, 0.2 * volume)
        for tc in results[0].job.Tools.Group:
            self.assertEqual((tc.HorizRapid.Value, tc.VertRapid.Value), (50.0, 25.0))
        gcode = (folder / "beet_mm.ngc").read_text()
        self.assertTrue("M6 T1" in gcode)

    def test_solid_stock_from_step_and_stl(self) -> None:
        """A solid stock from a STEP (a block whose top slopes): its clone is the Job's stock, the plan verified, the
        simulation removing less than the solid holds; an STL stock sewn into the same solid."""
        import Part

        from tmm_workbench.app.plan_stock import solid_shape
        from tmm_workbench.app.step_mesh import step_mesh
        from tmm_workbench.core.geometry.mesh import load_stl

        folder = OUT / "plan_solid"
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        lo, hi = load_stl(read_job(JOB).model.file).bounds
        x0, x1, z0 = lo[0] - 2, hi[0] + 2, lo[2]
        top = lambda x: hi[2] + 0.5 + 0.3 * (x - x0)   # noqa: E731 - 0.5 mm over the model at its low side
        side = Part.Face(Part.makePolygon([FreeCAD.Vector(x, lo[1] - 2, z) for x, z in
                                           ((x0, z0), (x1, z0), (x1, top(x1)), (x0, top(x0)), (x0, z0))]))
        solid = side.extrude(FreeCAD.Vector(0, hi[1] - lo[1] + 4, 0))
        solid.exportStep(str(folder / "stock.step"))
        job = stock_job(folder, {"type": "solid", "file": str(folder / "stock.step")})
        step_mesh(folder / "stock.step", folder / "stock_mesh.stl", 0.005, solid=True)
        from dataclasses import replace

        job = replace(job, stock=replace(job.stock, mesh_file=folder / "stock_mesh.stl"))
        _, _, _, plan = launch.make_plan(job)
        doc = dict(launch.plan_document(job, plan, job.model.file), gcode=False, fcstd=False, heat_map=False)
        results, verified = plan_run.run_plan(doc, folder)
        self.assertTrue(verified["passed"], verified["problems"])
        fc_stock = results[0].job.Stock
        self.assertEqual(fc_stock.PathResource, "Stock")
        self.assertAlmostEqual(fc_stock.Shape.Volume, solid.Volume, delta=1e-6 * solid.Volume)
        self.assertLess(verified["removed_volume_mm3"], solid.Volume)
        self.assertAlmostEqual(plan.stock_box[5], solid.BoundBox.ZMax, places=3)
        # an STL of the same solid: sewn into a solid of its volume
        from tmm_workbench.app.geometry import mesh_from_shape
        from tmm_workbench.core.geometry.mesh import save_stl

        save_stl(mesh_from_shape(solid, 0.01, "stock"), folder / "stock.stl")
        sewn = solid_shape(folder / "stock.stl", 1.0, [0, 0, 5])
        self.assertAlmostEqual(sewn.Volume, solid.Volume, delta=1e-3 * solid.Volume)
        self.assertAlmostEqual(sewn.BoundBox.ZMax, solid.BoundBox.ZMax + 5, places=3)


class PlanLibrary(FreeCADTestCase):
    def test_library_written_by_freecad(self) -> None:
        """ToolBits made in FreeCAD and saved by FreeCAD's own ToolBit code (0.20 and 1.0: templateAttrs, what
        saveToFile writes; 1.1: to_dict, what its .fctb serializer writes) in FreeCAD's folders, the library
        naming them: read back into the planner's tools with their sizes."""
        from tmm_workbench.app import tools
        from tmm_workbench.core.plan.tool_library import read_library

        doc = FreeCAD.newDocument("TmmPlanLibrary")
        root = OUT / "plan_library" / "Tools"
        shutil.rmtree(root, ignore_errors=True)
        (root / "Bit").mkdir(parents=True)
        (root / "Library").mkdir()
        made = [tools.make_tool_bit(doc, "endmill", 8.0, label="flat8"),
                tools.make_tool_bit(doc, "ballend", 6.0, label="ball6"),
                tools.make_tool_bit(doc, "bullnose", 10.0, 1.0, label="bull10")]
        doc.recompute()
        entries = []
        for nr, bit in enumerate(made, 1):
            proxy = bit.Proxy
            attrs = proxy.templateAttrs(bit) if hasattr(proxy, "templateAttrs") else proxy.to_dict()
            (root / "Bit" / f"{bit.Label}.fctb").write_text(json.dumps(attrs, indent=2))
            entries.append({"nr": nr, "path": f"{bit.Label}.fctb"})
        (root / "Library" / "shop.fctl").write_text(json.dumps({"version": 1, "tools": entries}))
        got, skipped = read_library(root / "Library" / "shop.fctl")
        self.assertEqual(skipped, [])
        self.assertEqual([(t["name"], t["type"], t["diameter"]) for t in got],
                         [("T1 flat8", "flat", 8.0), ("T2 ball6", "ball", 6.0), ("T3 bull10", "bull", 10.0)])
        self.assertAlmostEqual(got[2]["corner_radius"], 1.0, places=6)
        for t, bit in zip(got, made):
            self.assertAlmostEqual(t["flute_length"], float(bit.CuttingEdgeHeight), places=6)
            self.assertAlmostEqual(t["length"], float(bit.Length), places=6)
            self.assertAlmostEqual(t["shank_diameter"], float(bit.ShankDiameter), places=6)
