"""State that tells the truth and what FreeCAD's 3D Surface users expect (issue 15 items 5 and 6), headless:
a new op's heights come from the Job's stock before any compute (every TMM op); a new Job posts with linuxcnc
(tarus when its first op is 5-axis; a default post set in the preferences is kept); the Surface op's % step-over
is the mm step-over it stands for; finishing passes leave the stated stock (simulated: the finish's stock is the
single pass's, the earlier passes never below it); the start point picks the first pass; a final depth holds
every tip; CycleTime is set on every TMM op after compute; a document from before these properties restores
and computes the same path. (The stand-in box staying hidden is the GUI's: tests/gui/test_gui_state.py.)"""
from __future__ import annotations

import math

import FreeCAD

from fc_helpers import OUT, FreeCADTestCase, bump_stl, job_with_op, moves, new_doc
from tmm_workbench.app import job as jobs
from tmm_workbench.app import registry, stages, surface_passes, tools
from tmm_workbench.app.api import run_multipoint, run_roughing, run_waterline, simulate
from tmm_workbench.app.compat import PathPreferences
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.shared_data import benchmark_file

FAST = {"StepOver": 1.0, "SampleStep": 0.5, "BoundaryShape": "Model"}


def cycle_seconds(text: str) -> int:
    h, m, s = (int(v) for v in text.split(":"))
    return 3600 * h + 60 * m + s


def first_cut(op) -> tuple[float, float]:
    for name, p in moves(op):
        if name == "G1":
            return p["X"], p["Y"]
    raise AssertionError("no cutting move")


class NewOpState(FreeCADTestCase):
    def test_heights_from_the_stock_before_any_compute(self) -> None:
        doc = new_doc("TmmHeights")
        jm = jobs.prepare_model(doc, str(bump_stl()))
        doc.recompute()
        job = jobs.create_job(doc, jm.job_base)
        jobs.set_tool(job, tools.make_tool_bit(doc, "ballend", 4.0), 20.0, 5.0, 10000)
        top = job.Stock.Shape.BoundBox.ZMax
        self.assertGreater(top, 5.0)
        for name in ("TMM_Surface", "TMM_Roughing", "TMM_Waterline"):
            op = registry.create(name, job, {"StlFile": jm.stl_file})
            # FreeCAD's SetupSheet: safe 3 mm, clearance 5 mm over the stock (was 3 / 5 mm: over 0)
            self.assertAlmostEqual(op.SafeHeight.Value, top + 3.0, places=6, msg=name)
            self.assertAlmostEqual(op.ClearanceHeight.Value, top + 5.0, places=6, msg=name)


class JobPost(FreeCADTestCase):
    def test_new_job_posts_with_linuxcnc(self) -> None:
        doc = new_doc("TmmPost")
        jm = jobs.prepare_model(doc, str(bump_stl()))
        doc.recompute()
        job = jobs.create_job(doc, jm.job_base)
        offered = job.getEnumerationsOfProperty("PostProcessor")
        self.assertNotEqual(offered[0], "linuxcnc")  # FreeCAD's choice would be this one
        self.assertEqual(job.PostProcessor, "linuxcnc")
        self.assertIn("--precision 4", job.PostProcessorArgs)

    def test_a_default_post_in_the_preferences_is_kept(self) -> None:
        prefs = PathPreferences.preferences()
        old = prefs.GetString(PathPreferences.PostProcessorDefault, "")
        prefs.SetString(PathPreferences.PostProcessorDefault, "grbl")
        try:
            doc = new_doc("TmmPostPref")
            jm = jobs.prepare_model(doc, str(bump_stl()))
            doc.recompute()
            job = jobs.create_job(doc, jm.job_base)
            self.assertEqual(job.PostProcessor, "grbl")
        finally:
            prefs.SetString(PathPreferences.PostProcessorDefault, old)

    def test_five_axis_first_op_posts_with_tarus(self) -> None:
        net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
        r = run_multipoint(net, side_step=18.0, forward_step=4.0, progress=False, posts=(), pass_spacing="even")
        self.assertEqual(r.job.PostProcessor, "tarus")
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertGreater(cycle_seconds(r.op.CycleTime), 0)


class SurfaceExpectations(FreeCADTestCase):
    def test_percent_stepover_is_the_mm_stepover(self) -> None:
        doc = new_doc("TmmPercent")
        _, _, mm = job_with_op(doc, str(bump_stl()), values=dict(FAST, StepOver=2.0))
        _, _, pc = job_with_op(doc, str(bump_stl()), values=dict(FAST, StepOverUnit="%", StepOverPercent=50.0))
        self.assertTrue(pc.isValid(), pc.getStatusString())
        self.assertEqual(moves(pc), moves(mm))  # 50 % of the 4 mm ball: 2 mm
        pc.StepOverPercent = 25.0
        doc.recompute()
        self.assertGreater(len(moves(pc)), 1.5 * len(moves(mm)))
        pc.StepOverPercent = 0.0
        doc.recompute()
        self.assertFalse(pc.isValid())
        self.assertIn("step-over must be in (0, 100] %, got 0", pc.getStatusString())

    def test_finishing_passes_leave_the_stated_stock_simulated(self) -> None:
        doc = new_doc("TmmPasses")
        values = dict(FAST, StockToLeave=0.2)
        _, _, one = job_with_op(doc, str(bump_stl()), values=values)
        _, _, three = job_with_op(doc, str(bump_stl()), values=dict(values, FinishPasses=3, StepDown=0.5))
        self.assertTrue(three.isValid(), three.getStatusString())
        z = [p["Z"] for name, p in moves(three) if name == "G1"]
        flat = sorted({round(v, 6) for v in z if v < 0.8})  # tips over the bump's flat rim: at its floor + stock
        # three pass sets (raster_refine adds its own points per stock level)
        ratio = len(three.Proxy.toolpath.cutting_points()) / len(one.Proxy.toolpath.cutting_points())
        self.assertAlmostEqual(ratio, 3.0, delta=0.1)
        s_one = simulate(one, cell=0.1, progress=False)
        s_three = simulate(three, cell=0.1, progress=False)
        # the finish leaves the stated stock: the last pass set is the single pass's, the earlier ones above it
        self.assertAlmostEqual(s_three.min_deviation, s_one.min_deviation, places=6)
        self.assertAlmostEqual(s_three.max_left, s_one.max_left, places=6)
        self.assertGreater(s_three.min_deviation, 0.2 - 0.01)
        self.assertFalse(s_three.gouged)
        self.assertTrue(flat, z[:5])
        # the semi-finish alone (two passes over 0.7 mm) leaves at least 0.5 mm more everywhere
        _, _, semi = job_with_op(doc, str(bump_stl()), values=dict(FAST, StockToLeave=0.7, FinishPasses=2,
                                                                   StepDown=0.5))
        s_semi = simulate(semi, cell=0.1, progress=False)
        self.assertGreater(s_semi.min_deviation, s_one.min_deviation + 0.5 - 0.01)

    def test_start_point_and_final_depth(self) -> None:
        doc = new_doc("TmmStart")
        _, _, op = job_with_op(doc, str(bump_stl()), values=dict(FAST, Pattern="OneWay"))
        x0, y0 = first_cut(op)
        lo, hi = op.Proxy.mesh.bounds
        far = FreeCAD.Vector(float(hi[0]), float(hi[1]), 0)
        op.UseStartPoint, op.StartPoint = True, far
        doc.recompute()
        x, y = first_cut(op)
        self.assertLess(math.hypot(x - far.x, y - far.y), 1e-6)  # one-way passes: any corner
        self.assertGreater(math.hypot(x0 - far.x, y0 - far.y), 20.0)
        op.UseFinalDepth, op.FinalDepth = True, 2.0
        doc.recompute()
        cut_z = [p["Z"] for name, p in moves(op) if name == "G1"]
        self.assertAlmostEqual(min(cut_z), 2.0, places=6)
        self.assertGreater(max(cut_z), 4.0)  # the bump's top still followed
        op.FinishPasses = 0
        doc.recompute()
        self.assertIn("finishing passes must be a whole number in [1, 50], got 0", op.getStatusString())

    def test_run_surface_takes_the_depths_and_start_point(self) -> None:
        """The headless API sets what the panel's Depths group sets; a bad value is named by its argument."""
        from tmm_workbench.app.api import run_surface
        from tmm_workbench.core.errors import TmmError

        lo_x, lo_y = -30.0, -30.0
        r = run_surface(str(bump_stl()), diameter=4.0, stepover_percent=50.0, sample_step=0.5,
                        boundary="model", pattern="oneway", stock_to_leave=0.2, final_depth=0.5, finish_passes=2,
                        finish_step_down=0.3, start_point=(lo_x, lo_y), doc_name="TmmApiDepths", progress=False)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual((op.StepOverUnit, op.StepOverPercent, op.FinishPasses), ("%", 50.0, 2))
        self.assertEqual((op.UseFinalDepth, op.FinalDepth.Value, op.StepDown.Value), (True, 0.5, 0.3))
        self.assertEqual((op.UseStartPoint, op.StartPoint.x, op.StartPoint.y), (True, lo_x, lo_y))
        doc = r.doc
        _, _, ref = job_with_op(doc, str(bump_stl()), values=dict(FAST, StepOver=2.0, Pattern="OneWay",
                                                                  StockToLeave=0.2))
        ratio = len(op.Proxy.toolpath.cutting_points()) / len(ref.Proxy.toolpath.cutting_points())
        self.assertAlmostEqual(ratio, 2.0, delta=0.1)  # 50 % of D4 = 2 mm, two pass sets
        cut_z = [p["Z"] for name, p in moves(op) if name == "G1"]
        self.assertGreaterEqual(min(cut_z), 0.5 - 1e-6)
        x, y = first_cut(op)
        lo, _ = op.Proxy.mesh.bounds
        self.assertLess(math.hypot(x - float(lo[0]), y - float(lo[1])), 1e-6)  # the corner nearest the point
        for kwargs, fragment in (({"stepover_percent": 0.0}, "stepover_percent must be in (0, 100] %, got 0"),
                                 ({"finish_passes": 0}, "finish_passes must be a whole number in [1, 50], got 0"),
                                 ({"finish_step_down": -1.0}, "finish_step_down must be"),
                                 ({"start_point": (1.0,)}, "start_point must be two numbers (x, y)"),
                                 ({"start_point": (1.0, float("nan"))}, "start_point (x, y) must be finite")):
            with self.assertRaises(TmmError) as ctx:
                run_surface(str(bump_stl()), progress=False, doc_name="TmmApiBad", **kwargs)
            self.assertIn(fragment, str(ctx.exception))


class CycleTime(FreeCADTestCase):
    def test_every_tmm_op_has_its_cycle_time(self) -> None:
        stl = str(bump_stl())
        ro = run_roughing(stl, tool="endmill", diameter=4, step_down=2.0, stepover_percent=45, progress=False)
        wl = run_waterline(job=ro, tool="ballend", diameter=4, step_down=1.0, progress=False)
        doc = new_doc("TmmCycle")
        _, _, su = job_with_op(doc, stl, values=FAST)
        for op in (ro.op, wl.op, su):
            self.assertTrue(op.isValid(), op.getStatusString())
            self.assertGreater(cycle_seconds(op.CycleTime), 0, op.Label)
        # the 5-axis op: JobPost.test_five_axis_first_op_posts_with_tarus


class OldDocument(FreeCADTestCase):
    def test_a_document_without_the_new_properties_computes_the_same_path(self) -> None:
        doc = new_doc("TmmOld")
        _, _, op = job_with_op(doc, str(bump_stl()), values=FAST)
        before, name = moves(op), op.Name
        for field in surface_passes.STAGE.fields:
            op.removeProperty(field.prop)
        path = OUT / "old_surface.FCStd"
        doc.saveAs(str(path))
        FreeCAD.closeDocument(doc.Name)
        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        for prop, value in stages.defaults((surface_passes.STAGE,)).items():
            self.assertEqual(getattr(op, prop), value, prop)
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(moves(op), before)
