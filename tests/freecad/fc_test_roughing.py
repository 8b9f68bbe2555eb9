"""The TMM Roughing op in a Path Job: on a real STL (sphere_on_plate) and on a Part box with a pocket; the Job's
stock as the stock, feeds from the tool controller, heights above the stock, save/reopen, every bad input a
message on the op and an empty path, work above the limit refused, and the Job simulated (app.simulation /
api.simulate): no gouge below 1e-3 mm, the stated material left on the flat faces, no rapid through stock."""
from __future__ import annotations

import math
import unittest
from typing import Any, Optional

import FreeCAD
import numpy as np
import Part

from fc_helpers import OUT, BadInputCase, SPHERE_ON_PLATE, FreeCADTestCase, close_all, moves, new_doc
from tmm_workbench.app import job as jobs
from tmm_workbench.app import op_roughing, registry, tools, work_estimate
from tmm_workbench.app.api import run_roughing, simulate
from tmm_workbench.core.errors import TmmError

H_FEED, V_FEED = 1200.0, 240.0  # mm/min, as the tool controller gets them
GOUGE_MM = 1e-3
# the Part model: a 40 x 30 x 10 block with a 20 x 12 pocket 5 mm deep; the Job's stock is its box + 1 mm
BLOCK = (40.0, 30.0, 10.0)
POCKET = (10.0, 9.0, 30.0, 21.0)   # xmin, ymin, xmax, ymax
POCKET_FLOOR = 5.0


def pocket_block(doc: Any) -> Any:
    block = Part.makeBox(*BLOCK)
    x0, y0, x1, y1 = POCKET
    pocket = Part.makeBox(x1 - x0, y1 - y0, BLOCK[2], FreeCAD.Vector(x0, y0, POCKET_FLOOR))
    obj = doc.addObject("Part::Feature", "PocketBlock")
    obj.Shape = block.cut(pocket)
    doc.recompute()
    return obj


def job_with(doc: Any, model: Any, op_name: str, shape: str = "endmill", diameter: float = 6.0,
             corner_radius: float = 0.0, values: Optional[dict] = None) -> tuple[Any, Any, Any]:
    """(job, tool controller, op) of type `op_name` for `model` (STL path or Part object), recomputed."""
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    job = jobs.create_job(doc, jm.job_base)
    bit = tools.make_tool_bit(doc, shape, diameter, corner_radius)
    tc = jobs.set_tool(job, bit, H_FEED / 60, V_FEED / 60, 12000)
    vals = {"StlFile": jm.stl_file} if jm.stl_file else {"Model": jm.link}
    vals.update(values or {})
    op = registry.create(op_name, job, vals)
    op.Proxy.progress_enabled = False
    doc.recompute()
    return job, tc, op


def check_feeds_and_heights(test: unittest.TestCase, job: Any, op: Any) -> list:
    """The op's moves: G0 without F at or above the safe height but for the straight rapids down to just above
    the material and the hops just over it between pieces (the Job simulations see none cut), G1 at the tool controller's feeds, the safe and clearance
    heights above the stock (FreeCAD's SetupSheet defaults), the path ending at the clearance."""
    mv = moves(op)
    test.assertGreater(len(mv), 20)
    top = job.Stock.Shape.BoundBox.ZMax
    safe, clear = op.SafeHeight.Value, op.ClearanceHeight.Value
    test.assertGreater(safe, top)
    test.assertGreaterEqual(clear, safe)
    here: dict = {}
    for n, p in mv:
        if n == "G0":
            test.assertNotIn("F", p)
            if p["Z"] < safe - 1e-9:   # straight down, or a low hop: straight up, then across at its height
                xy = (p.get("X", here["X"]), p.get("Y", here["Y"]))
                if xy != (here["X"], here["Y"]):
                    test.assertEqual(p["Z"], here["Z"])
        else:
            test.assertIn(round(p["F"] * 60, 6), (H_FEED, V_FEED))
        here.update({k: p[k] for k in ("X", "Y", "Z") if k in p})
    test.assertIn(H_FEED, {round(p["F"] * 60, 6) for n, p in mv if n == "G1"})
    test.assertAlmostEqual(mv[-1][1]["Z"], clear, places=6)
    test.assertEqual(len(op.Proxy.toolpath), len(mv) - 2)  # + the Z-only start, ObjectOp's final G0
    test.assertTrue(op.CycleTime and op.CycleTime != "00:00:00")
    return mv


def levels(mv: list) -> list[float]:
    """The distinct heights of the feed moves that run level (layers, loops; not the entries), highest first."""
    zs = set()
    for (_, a), (n, b) in zip(mv, mv[1:]):
        if n == "G1" and "Z" in a and abs(a["Z"] - b["Z"]) < 1e-9:
            zs.add(round(b["Z"], 6))
    return sorted(zs, reverse=True)


def feed_length(op: Any) -> float:
    """mm of the op's G1 moves."""
    here, total = None, 0.0
    for n, p in moves(op):
        nxt = dict(here or {}, **{k: p[k] for k in ("X", "Y", "Z") if k in p})
        if n == "G1" and here is not None and len(here) == 3:
            total += math.dist([here[k] for k in "XYZ"], [nxt[k] for k in "XYZ"])
        here = nxt
    return total


def cells_inside(sim: Any, box: tuple[float, float, float, float], inset: float) -> np.ndarray:
    """The simulated heights of the cells whose centres lie `inset` inside the XY box."""
    g = sim.grid
    X, Y = np.meshgrid(g.xs(), g.ys())
    x0, y0, x1, y1 = box
    mask = (X > x0 + inset) & (X < x1 - inset) & (Y > y0 + inset) & (Y < y1 - inset)
    return sim.result.heights[mask]


class RoughingInJob(FreeCADTestCase):
    def test_stl_model(self) -> None:
        doc = new_doc("TmmRoughStl")
        job, tc, op = job_with(doc, str(SPHERE_ON_PLATE), "TMM_Roughing", diameter=10.0,
                               values={"StepDown": 6.0, "StepOver": 50.0, "StockToLeave": 1.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertIsInstance(op.Proxy, op_roughing.ObjectTmmRoughing)
        mv = check_feeds_and_heights(self, job, op)
        # the stock is the Job's stock solid (box): its bounding box is the strategy's stock_box
        bb = job.Stock.Shape.BoundBox
        self.assertEqual(op.Proxy.params.stock_box, (bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax, bb.ZMax))
        self.assertIsNone(op.Proxy.params.stock_heights)
        self.assertEqual(op.Proxy.params.stock_to_leave_axial, 1.0)  # follows the radial value (expression)
        self.assertAlmostEqual(levels(mv)[0], bb.ZMax - 6.0, places=5)  # the first layer a step-down into the stock
        r = simulate(job, cell=0.5, tolerance=GOUGE_MM, progress=False)
        self.assertGreater(r.min_deviation, -GOUGE_MM, r.gouge_cells)
        self.assertEqual(r.collisions, [])
        self.assertGreater(r.removed_volume, 0)
        # the plate round the sphere (flat, the model's full width) keeps the axial stock to leave, 1 mm
        sim = r.simulation
        X, Y = np.meshgrid(sim.grid.xs(), sim.grid.ys())
        corner = (X < 10) & (Y < 10) & (X > 1) & (Y > 1)
        np.testing.assert_allclose(sim.result.heights[corner], sim.design[corner] + 1.0, atol=GOUGE_MM)

    def test_part_pocket_leaves_the_stock_to_leave(self) -> None:
        doc = new_doc("TmmRoughPart")
        job, tc, op = job_with(doc, pocket_block(doc), "TMM_Roughing", diameter=6.0,
                               values={"StepDown": 2.0, "StockToLeave": 0.5})
        self.assertTrue(op.isValid(), op.getStatusString())
        check_feeds_and_heights(self, job, op)
        r = simulate(job, cell=0.1, tolerance=GOUGE_MM, progress=False)
        self.assertGreater(r.min_deviation, -GOUGE_MM, (r.min_deviation, r.gouge_cells))
        self.assertEqual(r.collisions, [])
        # the stated material left: 0.5 mm on the pocket floor and on the block's top (flat: axial stock)
        r_tool = 3.0
        floor = cells_inside(r.simulation, POCKET, r_tool + 0.5 + 0.2)
        self.assertGreater(len(floor), 100)
        np.testing.assert_allclose(floor, POCKET_FLOOR + 0.5, atol=GOUGE_MM)
        top = cells_inside(r.simulation, (0.0, 0.0, 10.0, 30.0), 1.0)   # the strip left of the pocket
        np.testing.assert_allclose(top, BLOCK[2] + 0.5, atol=GOUGE_MM)

    def test_a_cylinder_stock_is_cut_as_heights(self) -> None:
        """A stock that is not a box: its top as heights on a grid (stock_heights) besides its box."""
        from tmm_workbench.app.compat import PathStock

        doc = new_doc("TmmRoughCyl")
        job, tc, op = job_with(doc, pocket_block(doc), "TMM_Roughing", values={"StepDown": 3.0})
        old = job.Stock
        job.Stock = PathStock.CreateCylinder(job, 26.0, 11.0)
        job.Stock.Placement.Base = FreeCAD.Vector(20.0, 15.0, 0.0)
        doc.removeObject(old.Name)
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        grid, heights = op.Proxy.params.stock_heights
        self.assertAlmostEqual(float(np.nanmax(heights)), 11.0, places=6)
        self.assertLess(float(np.nanmin(heights)), 11.0)  # the box corners lie outside the cylinder

    def test_save_reopen_keeps_the_op_and_its_values(self) -> None:
        doc = new_doc("TmmRoughSave")
        values = {"StepDown": 2.5, "StepOver": 45.0, "Pattern": "ZigZag", "Direction": "Conventional",
                  "Entry": "Ramp", "RampAngle": 5.0, "StockToLeave": 0.3, "AxialStockToLeave": 0.2,
                  "KeepToolDown": False}
        job, tc, op = job_with(doc, pocket_block(doc), "TMM_Roughing", values=values)
        self.assertTrue(op.isValid(), op.getStatusString())
        before = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        path = OUT / "roughing_reopen.FCStd"
        doc.saveAs(str(path))
        name, tc_name = op.Name, tc.Name
        close_all()
        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        self.assertIsInstance(op.Proxy, op_roughing.ObjectTmmRoughing)
        for prop, value in values.items():
            got = getattr(op, prop)
            self.assertAlmostEqual(got.Value, value) if hasattr(got, "Value") else self.assertEqual(got, value)
        self.assertEqual(op.ToolController.Name, tc_name)
        self.assertNotIn("AxialStockToLeave", [e[0] for e in op.ExpressionEngine])  # a given value replaced it
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        after = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        self.assertEqual([n for n, _ in after], [n for n, _ in before])
        for (_, a), (_, b) in zip(after, before):
            for k in a:
                self.assertAlmostEqual(a[k], b[k], delta=1e-5)


class RoughingBadInput(BadInputCase):
    def setUp(self) -> None:
        self.doc = new_doc("TmmRoughBad")
        self.job, self.tc, self.op = job_with(self.doc, pocket_block(self.doc), "TMM_Roughing",
                                              values={"StepDown": 3.0})
        self.assertTrue(self.op.isValid(), self.op.getStatusString())
        self.assertGreater(len(self.op.Path.Commands), 10)

    FAIL_SECONDS = 10.0

    def test_step_down(self) -> None:
        for bad, text in ((0.0, "got 0"), (-1.0, "got -1"), (math.nan, "got nan")):
            self.op.StepDown = bad
            self.assertFails("step-down", text)
        edge = float(self.tc.Tool.CuttingEdgeHeight.Value)
        self.op.StepDown = edge + 1.0
        self.assertFails("step-down", "cutting edge height", f"{edge:g} mm")

    def test_step_over(self) -> None:
        for bad in (0.0, -5.0, 100.0, 120.0):
            self.op.StepOver = bad
            self.assertFails("step-over", f"got {bad:g}")

    def test_stock_to_leave(self) -> None:
        self.op.StockToLeave = -0.5
        self.assertFails("stock to leave", "got -0.5")
        self.op.StockToLeave = 10.0  # the tool is 6 mm
        self.assertFails("stock to leave 10 mm is larger than the tool")

    def test_ramp_angle_zero(self) -> None:
        self.op.Entry = "Ramp"
        self.op.RampAngle = 0.0
        self.assertFails("ramp angle", "got 0")

    def test_stock_not_above_the_model(self) -> None:
        self.job.Stock.ExtZpos = -2.0  # the stock's top 2 mm below the model's
        self.assertFails("stock is not above the model", "top 8 mm")

    def test_model_outside_the_stock(self) -> None:
        stock = self.job.Stock  # moved 60 mm past the model's +X side
        stock.ExtXneg = -(BLOCK[0] + 60.0)
        stock.ExtXpos = 100.0
        self.assertFails("lies outside the stock", "x 100..140")

    def test_work_above_the_limit_is_refused(self) -> None:
        group = FreeCAD.ParamGet(work_estimate.PREFERENCES)
        group.SetInt("MaxPoints", 1000)
        try:
            self.op.StepDown = 0.01
            self.op.StepOver = 1.0
            self.assertFails("more than this machine's limit", seconds=2.0)
        finally:
            group.RemInt("MaxPoints")
        self.op.StepDown = 3.0
        self.op.StepOver = 40.0
        self.doc.recompute()
        self.assertTrue(self.op.isValid(), self.op.getStatusString())


class RoughingApi(FreeCADTestCase):
    def test_run_roughing_then_waterline_in_the_same_job(self) -> None:
        """Headless: a block roughed to the STL model, its walls finished by waterline with a second tool in
        the same Job; the Job simulated: no gouge, less left than after the roughing alone."""
        from tmm_workbench.app.api import run_waterline

        gcode = OUT / "rough.ngc"
        r = run_roughing(SPHERE_ON_PLATE, tool="endmill", diameter=10.0, step_down=6.0, stepover_percent=50.0,
                         stock_to_leave=1.0, stock_margin=2.0, stock_above=3.0, gcode_path=gcode,
                         progress=False, doc_name="TmmRoughApi")
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        bb = r.job.Stock.Shape.BoundBox
        self.assertAlmostEqual(bb.XMin, -2.0, places=6)
        self.assertAlmostEqual(bb.ZMax, 30.8718 + 3.0, places=3)
        self.assertTrue(gcode.is_file() and "G1" in r.gcode)
        self.assertEqual(len(r.toolpath), len(moves(r.op)) - 2)
        self.assertGreater(r.op.SafeHeight.Value, bb.ZMax)
        rough = simulate(r.job, cell=0.5, tolerance=GOUGE_MM, progress=False)
        self.assertGreater(rough.min_deviation, -GOUGE_MM)

        w = run_waterline(job=r, tool="ballend", diameter=6.0, step_down=2.0, chord_tolerance=0.0002,
                          progress=False)  # fine chords: see fc_test_waterline.test_stl_model
        self.assertIs(w.job, r.job)
        self.assertTrue(w.op.isValid(), w.op.getStatusString())
        self.assertEqual(len(r.job.Tools.Group), 2)
        self.assertIsNot(w.op.ToolController, r.op.ToolController)
        both = simulate(r.job, cell=0.5, tolerance=GOUGE_MM, progress=False)
        self.assertEqual([o.label for o in both.ops], [r.op.Label, w.op.Label])
        self.assertGreater(both.min_deviation, -GOUGE_MM)
        self.assertEqual(both.collisions, [])
        self.assertLess(both.remaining_volume, rough.remaining_volume)

    def test_a_second_roughing_cuts_only_what_the_first_left(self) -> None:
        """The pocket block roughed with a 10 mm end mill, then with a 4 mm one in the same Job: the second cuts
        the corners the first could not reach (its stock is what the first left, app.simulation.rest_stock), a
        fraction of what the 4 mm tool cuts from the full stock; the Job simulated: no gouge, no rapid into
        stock, less left than after the first."""
        from tmm_workbench.app.api_run import add_tool as _add_tool

        doc = new_doc("TmmRestRough")
        values = {"StepDown": 2.5, "StockToLeave": 0.3}
        job, tc, first = job_with(doc, pocket_block(doc), "TMM_Roughing", diameter=10.0, values=values)
        self.assertTrue(first.isValid(), first.getStatusString())
        alone = simulate(job, cell=0.1, tolerance=GOUGE_MM, progress=False)
        tc2 = _add_tool(job, tools.make_tool_bit(doc, "endmill", 4.0), H_FEED / 60, V_FEED / 60, 12000)
        rest = registry.create("TMM_Roughing", job, {"Model": first.Model, "ToolController": tc2, **values})
        rest.Proxy.progress_enabled = False
        doc.recompute()
        self.assertTrue(rest.isValid(), rest.getStatusString())
        both = simulate(job, cell=0.1, tolerance=GOUGE_MM, progress=False)
        self.assertGreater(both.min_deviation, -GOUGE_MM, (both.min_deviation, both.gouge_cells))
        self.assertEqual(both.collisions, [])
        self.assertLess(both.remaining_volume, alone.remaining_volume - 1.0)  # the pocket's corners

        doc2 = new_doc("TmmFullRough")
        _, _, full = job_with(doc2, pocket_block(doc2), "TMM_Roughing", diameter=4.0, values=values)
        self.assertTrue(full.isValid(), full.getStatusString())
        cut_rest, cut_full = feed_length(rest), feed_length(full)
        self.assertLess(cut_rest, 0.25 * cut_full, (cut_rest, cut_full))

    def test_cancel(self) -> None:
        """A progress callback returning False cancels: the op's message, no document left behind."""
        seen = []

        def cancel(fraction: float) -> bool:
            seen.append(fraction)
            return False
        with self.assertRaises(TmmError) as ctx:
            run_roughing(SPHERE_ON_PLATE, diameter=10.0, step_down=6.0, progress=cancel, doc_name="TmmRoughCancel")
        self.assertIn("cancelled", str(ctx.exception))
        self.assertTrue(seen)
        self.assertNotIn("TmmRoughCancel", FreeCAD.listDocuments())

    def test_bad_arguments_are_refused_by_name(self) -> None:
        for kwargs, fragment in ((dict(step_down=math.nan), "step_down"),
                                 (dict(step_down=0.0), "step_down must be a positive length, got 0"),
                                 (dict(stepover_percent=100.0), "stepover_percent must be in (0, 100) %, got 100"),
                                 (dict(stock_to_leave=-1.0), "stock_to_leave"),
                                 (dict(entry="spiral"), "entry must be"),
                                 (dict(pattern="raster"), "pattern must be"),
                                 (dict(stock=(0, 0, 0, 1, 1)), "stock must be"),
                                 (dict(stock_margin=math.inf), "stock_margin")):
            with self.subTest(**{k: str(v) for k, v in kwargs.items()}):
                with self.assertRaises(TmmError) as ctx:
                    run_roughing(SPHERE_ON_PLATE, progress=False, **kwargs)
                self.assertIn(fragment, str(ctx.exception))
        self.assertEqual([d for d in FreeCAD.listDocuments() if d.startswith("TMM")], [])


class WithoutKernel(FreeCADTestCase):
    def test_a_document_with_both_ops_keeps_them_without_the_kernel(self) -> None:
        """Saved with a roughing and a waterline op, opened by a copy of the add-on without its kernel: both
        restore with their proxies, fail with the kernel's message and an empty path, and the saved copy
        computes again once the kernel is back (as fc_test_hardening does for the Surface op)."""
        import json
        import shutil
        import subprocess

        import fc_test_hardening as hardening  # the module, not its test cases

        doc = new_doc("TmmNkZ")
        job, tc, rough = job_with(doc, pocket_block(doc), "TMM_Roughing", values={"StepDown": 3.0})
        water = registry.create("TMM_Waterline", job, {"Model": rough.Model, "StepDown": 2.0})
        water.Proxy.progress_enabled = False
        doc.recompute()
        self.assertTrue(rough.isValid() and water.isValid(), (rough.getStatusString(), water.getStatusString()))
        original, saved, result = OUT / "nkz_original.FCStd", OUT / "nkz_saved.FCStd", OUT / "nkz_result.json"
        doc.saveAs(str(original))
        close_all()
        copy = OUT / "nokernel_z"
        shutil.rmtree(copy, ignore_errors=True)
        shutil.copytree(hardening.ROOT / "tmm_workbench", copy / "tmm_workbench",
                        ignore=shutil.ignore_patterns("_native*", "__pycache__"))
        script = OUT / "nkz_child.py"
        script.write_text(hardening.CHILD.format(copy=str(copy), doc=str(original), saved=str(saved),
                                                 result=str(result)))
        freecadcmd = shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
        proc = subprocess.run([freecadcmd, str(script)], cwd=OUT, capture_output=True, text=True, timeout=300)
        self.assertTrue(result.exists(), proc.stdout + proc.stderr)
        child = json.loads(result.read_text())
        self.assertFalse(child["kernel"], "the copy must not find a kernel")
        self.assertEqual(child["ops"], ["TMM_Roughing", "TMM_Waterline"], child)
        self.assertEqual(child["valid"], [False, False])
        self.assertTrue(all("native kernel" in s for s in child["status"]), child["status"])
        self.assertEqual(child["commands"], [0, 0])   # no stale path
        doc = FreeCAD.openDocument(str(saved))       # the kernel is back
        ops = [doc.getObject("TMM_Roughing"), doc.getObject("TMM_Waterline")]
        for op in ops:
            op.Proxy.progress_enabled = False
            op.touch()
        doc.recompute()
        for op in ops:
            self.assertTrue(op.isValid(), op.getStatusString())
            self.assertGreater(len(op.Path.Commands), 10)


if __name__ == "__main__":
    unittest.main()
