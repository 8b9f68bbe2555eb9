"""The work estimate of an op from its properties (app.work_estimate): an upper bound of what the strategy
really computes, refused above the limits before the op loads or tessellates its model; the ranges of the
properties that name no params field; the spindle speed a post needs; no message box hook headless."""
from __future__ import annotations

import time

import FreeCAD
import Part

from fc_helpers import FreeCADTestCase, bump_stl, job_with_op, new_doc
from tmm_workbench.app import hooks, work_estimate
from tmm_workbench.app.op_base import spindle_problem
from tmm_workbench.app.tools import cutter_from_tool
from tmm_workbench.core.errors import TmmError, WorkLimitError
from tmm_workbench.core.strategies import raster_drop


class WorkEstimate(FreeCADTestCase):
    def test_estimate_bounds_the_strategy_points(self) -> None:
        """The panel's number is an upper bound of the CL points the strategy drops, and not far above it."""
        doc = new_doc("TmmEstimate")
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "StepOver": 1.5,
                                                              "SampleStep": 0.4})
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        mesh = op.Proxy.mesh
        params = op.Proxy.params_from(op, boundary=op.Proxy.boundary(op, mesh))
        points = raster_drop.compute(mesh, cutter_from_tool(tc.Tool), params).diagnostics["points"]
        self.assertEqual(est.what, "CL points")
        self.assertGreaterEqual(est.count, points)
        self.assertLess(est.count, 3.0 * points, (est.count, points))
        # an override is what the panel asks before writing the value: the op is not changed
        finer = work_estimate.estimate(op, {"SampleStep": 0.2})
        self.assertGreater(finer.count, 1.8 * est.count)
        self.assertAlmostEqual(op.SampleStep.Value, 0.4)
        with self.assertRaises(WorkLimitError) as ctx:
            work_estimate.estimate(op, {"SampleStep": 1e-5})
        self.assertIn("sample step 1e-05 mm", str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            work_estimate.estimate(op, {"StepOver": -1.0})
        self.assertIn("step-over must be a positive length, got -1", str(ctx.exception))

    def test_estimate_of_the_cusp_modes_and_the_verification(self) -> None:
        """Cusp mode: an upper bound of the points the section rule's raster drops; VerifyCusp adds its dense
        raster (known before it runs) and says that its partial passes are not counted (issue 14)."""
        doc = new_doc("TmmEstimateVerify")
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "SampleStep": 0.4,
                                                              "StepOverMode": "Cusp", "CuspHeight": 0.01})
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        mesh = op.Proxy.mesh
        params = op.Proxy.params_from(op, boundary=op.Proxy.boundary(op, mesh))
        points = raster_drop.compute(mesh, cutter_from_tool(tc.Tool), params).diagnostics["points"]
        self.assertGreaterEqual(est.count, points)
        self.assertIn("cusp check", est.note)  # CheckCusp's measurement, on by default, is counted and said
        checked = work_estimate.estimate(op, {"VerifyCusp": True})
        self.assertGreaterEqual(checked.count, est.count)  # the same measurement as the check's (it replaces it)
        self.assertIn("up to 4 rounds of partial passes", checked.text())
        self.assertIs(op.VerifyCusp, False)  # an override only
        # the 3D offset's loops are verified too: its estimate gets the same dense raster
        op.StepOverMode = "Offset3D"
        loops = work_estimate.estimate(op)
        loops_checked = work_estimate.estimate(op, {"VerifyCusp": True})
        self.assertAlmostEqual(loops_checked.count - loops.count, checked.count - est.count, delta=1.0)
        self.assertIn("up to 4 rounds of partial passes", loops_checked.text())

    def test_estimate_tells_the_cutting_time(self) -> None:
        """The status line's time: the cut length the boxes and the spacing imply at the tool controller's
        feed, near the cutting time of the path the op then computes; none without a feed."""
        from tmm_workbench.app.simulation import toolpath_and_feeds
        from tmm_workbench.core.sim.cycle_time import three_axis_time

        doc = new_doc("TmmEstimateTime")
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "StepOver": 1.5,
                                                              "SampleStep": 0.4})
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        tp, feeds = toolpath_and_feeds(op)
        cutting = three_axis_time(tp.points(), feeds, tc.HorizRapid.Value, tc.VertRapid.Value).cutting_seconds
        self.assertGreater(cutting, 0.0)
        self.assertAlmostEqual(est.feed, tc.HorizFeed.Value)
        self.assertTrue(0.6 * cutting < est.cutting_seconds < 1.6 * cutting, (est.cutting_seconds, cutting))
        self.assertIn("cutting about 00:", est.text())
        slower = work_estimate.estimate(op, {"StepOver": 0.75})  # half the spacing, twice the passes' length
        self.assertAlmostEqual(slower.cutting_seconds, 2.0 * est.cutting_seconds, delta=1e-6)
        tc.HorizFeed = 0.0  # no feed: no time, the rest of the estimate stays
        self.assertIsNone(work_estimate.estimate(op).cutting_seconds)
        self.assertNotIn("cutting", work_estimate.estimate(op).text())

    def test_estimate_counts_the_region_and_the_slopes(self) -> None:
        """A cusp finish inside a sketch circle: the time told counts the circle (not the model's box) and, the STL
        at hand, the slopes its passes climb and the spacing the cusp takes there; near the computed path's."""
        from tmm_workbench.app.simulation import toolpath_and_feeds
        from tmm_workbench.core.sim.cycle_time import three_axis_time

        doc = new_doc("TmmEstimateRegion")
        circle = doc.addObject("Sketcher::SketchObject", "Circle")
        circle.addGeometry(Part.Circle(FreeCAD.Vector(2, 1, 0), FreeCAD.Vector(0, 0, 1), 5.0))
        doc.recompute()
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.4, "StepOverMode": "Adaptive",
                                                              "CuspHeight": 0.01})
        whole = work_estimate.estimate(op)
        op.Region, op.RegionSketch = "Sketch", circle
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        self.assertLess(est.cutting_seconds, 0.4 * whole.cutting_seconds)   # pi 5^2 of the bump's 20 x 20
        tp, feeds = toolpath_and_feeds(op)
        cutting = three_axis_time(tp.points(), feeds, tc.HorizRapid.Value, tc.VertRapid.Value).cutting_seconds
        self.assertTrue(0.6 * cutting < est.cutting_seconds < 1.6 * cutting, (est.cutting_seconds, cutting))
        self.assertTrue(est.climbs)   # the STL was at hand: the sample's slopes are in it

    def test_estimate_tells_the_compute_time(self) -> None:
        """The count at the strategy's measured pace (benchmarks/compute_estimate.py compares it with real runs):
        a quick op says nothing of it; values that would compute for minutes say so in the status line, and the
        op announces it before it starts (est.long)."""
        doc = new_doc("TmmEstimateCompute")
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "StepOver": 1.5,
                                                              "SampleStep": 0.4})
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        self.assertAlmostEqual(est.compute_seconds, est.count * work_estimate.PACE["surface"])
        self.assertFalse(est.long)
        self.assertNotIn("computing", est.text())
        fine = work_estimate.estimate(op, {"StepOver": 0.02, "SampleStep": 0.01})
        self.assertGreater(fine.compute_seconds, work_estimate.LONG_COMPUTE_S, fine.text())
        self.assertTrue(fine.long)
        self.assertIn("computing about 00:", fine.text())
        # the cusp check's (or the verification's) dense raster adds its time at its own pace
        plain = work_estimate.estimate(op, {"StepOverMode": "cusp", "CuspHeight": 0.01, "CheckCusp": "off"})
        checked = work_estimate.estimate(op, {"StepOverMode": "cusp", "CuspHeight": 0.01, "CheckCusp": "on"})
        self.assertGreater(checked.compute_seconds, plain.compute_seconds)
        self.assertAlmostEqual(checked.compute_seconds - plain.compute_seconds,
                               (checked.count - plain.count) * work_estimate.PACE["verify"])

    def test_part_model_refused_before_tessellation(self) -> None:
        """A Part model with a tessellation tolerance below the range, or a raster above the limit: the op fails
        at once, from the bounding boxes, without tessellating the sphere."""
        doc = new_doc("TmmEstimatePart")
        ball = doc.addObject("Part::Feature", "Ball")
        ball.Shape = Part.makeSphere(200.0)
        doc.recompute()
        job, _, op = job_with_op(doc, ball, diameter=6.0,   # valid with a coarse tessellation (seconds, not 30)
                                 values={"StepOver": 5.0, "SampleStep": 5.0, "BoundaryShape": "Model",
                                         "LinearDeflection": 0.5})
        self.assertTrue(op.isValid(), op.getStatusString())
        for prop, value, fragment in (("LinearDeflection", 1e-6, "tessellation tolerance must be in [0.001, 10] mm"),
                                      ("SampleStep", 1e-4, "CL points")):
            old = getattr(op, prop).Value
            setattr(op, prop, value)
            t0 = time.perf_counter()
            op.touch()
            doc.recompute()
            self.assertLess(time.perf_counter() - t0, 2.0)
            self.assertFalse(op.isValid())
            self.assertIn(fragment, op.getStatusString())
            self.assertEqual(len(op.Path.Commands), 0)
            setattr(op, prop, old)
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())

    def test_spindle_speed_needed_by_the_post(self) -> None:
        doc = new_doc("TmmSpindle")
        job, tc, op = job_with_op(doc, str(bump_stl()))
        job.PostProcessor = "linuxcnc"
        self.assertEqual(spindle_problem(op), "")
        tc.SpindleSpeed = 0.0
        self.assertIn("SpindleSpeed is 0 rpm", spindle_problem(op))
        self.assertIn("'linuxcnc'", spindle_problem(op))
        job.PostProcessor = "apt_cl"  # cutter location data: no spindle words
        self.assertEqual(spindle_problem(op), "")
        job.PostProcessor = "linuxcnc"
        tc.SpindleDir = "None"
        self.assertEqual(spindle_problem(op), "")
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())  # reported, not refused

    def test_no_failure_box_headless(self) -> None:
        seen = []
        hooks.failure_hooks.append(lambda obj, message: seen.append(message))
        try:
            hooks.report_failure(None, "x")
        finally:
            hooks.failure_hooks.pop()
        self.assertFalse(FreeCAD.GuiUp)
        self.assertEqual(seen, [])
