"""The Surface op's 3D offset spacing (StepOverMode Offset3D, issue 14 item 1) in a Path Job: closed loops
from the boundary inward, save and reopen, a document saved before the choice existed, run_surface, and bad
input (a cusp above the tool radius): a clear message on the op and no path."""
from __future__ import annotations

import FreeCAD

from fc_helpers import FreeCADTestCase, bump_stl, close_all, core_work, job_with_op, moves, new_doc, reopened
from tmm_workbench.app.api import run_surface
from tmm_workbench.core.errors import TmmError


def cut_xy(op):
    return [(round(p["X"], 6), round(p["Y"], 6)) for n, p in moves(op) if n == "G1" and "X" in p and "Y" in p]


class Offset3D(FreeCADTestCase):
    def test_loops_save_and_reopen(self) -> None:
        doc = new_doc("TmmOffset3D")
        _, _, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.5, "BoundaryShape": "Model"})
        self.assertIn("Offset3D", op.getEnumerationsOfProperty("StepOverMode"))
        raster = cut_xy(op)
        op.StepOverMode, op.CuspHeight = "Offset3D", 0.02
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        loops = cut_xy(op)
        self.assertNotEqual(loops, raster)
        xs, ys = [p[0] for p in loops], [p[1] for p in loops]
        # the first loop runs round the model's box (the bump: 20 x 20 mm about the origin), the tool centre on it
        self.assertAlmostEqual(min(xs), -10.0, delta=1e-6)
        self.assertAlmostEqual(max(xs), 10.0, delta=1e-6)
        self.assertAlmostEqual(min(ys), -10.0, delta=1e-6)
        self.assertAlmostEqual(max(ys), 10.0, delta=1e-6)
        # and it is closed: the tool comes back to where it started before it steps in
        first = loops[0]
        self.assertIn(first, loops[1:len(loops) // 2])
        commands = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        op = reopened(doc, op, "offset3d.FCStd")
        doc = op.Document
        self.assertEqual((op.StepOverMode, round(op.CuspHeight.Value, 9)), ("Offset3D", 0.02))
        doc.recompute()
        self.assertEqual(len(op.Path.Commands), len(commands))
        op.CuspHeight = 50.0                                           # above the tool radius
        doc.recompute()
        self.assertFalse(op.isValid())
        self.assertIn("cusp height must be in [0.0001, 2] mm (a machine's resolution to the tool radius), got 50", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        close_all()

    def test_a_document_from_before_the_choice_keeps_its_mode_and_offers_it(self) -> None:
        doc = new_doc("TmmOldOffset3D")
        _, _, op = job_with_op(doc, str(bump_stl()))
        op.StepOverMode = ["StepOver", "Cusp", "Adaptive"]            # as saved by an older TMM
        op.StepOverMode = "Cusp"
        op = reopened(doc, op, "old_offset3d.FCStd")
        self.assertEqual(op.StepOverMode, "Cusp")
        self.assertIn("Offset3D", op.getEnumerationsOfProperty("StepOverMode"))
        close_all()

    @core_work  # the API's keywords to the core's loops; the op's Offset3D in a Job: test_loops_save_and_reopen
    def test_run_surface(self) -> None:
        r = run_surface(bump_stl(), sample_step=0.5, stepover_mode="offset3d", cusp=0.02,
                        progress=False, doc_name="TmmApiOffset3D")
        self.assertEqual(r.op.StepOverMode, "Offset3D")
        pts = r.toolpath.cutting_points()
        self.assertGreater(len(pts), 100)
        self.assertIn("G1", r.gcode)
        FreeCAD.closeDocument(r.doc.Name)
        with self.assertRaises(TmmError) as ctx:
            run_surface(bump_stl(), stepover_mode="offset3d", cusp=10.0, progress=False, doc_name="TmmApiBad3D")
        self.assertIn("cusp height must be in [0.0001, 3] mm", str(ctx.exception))

    def test_the_op_reports_the_cells_above_the_cusp(self) -> None:
        """CheckCusp (Auto by default: on small regions): the op's read-only CuspReport says what the core's check
        measures on the same passes (cells above CuspHeight and where, or held), and a warning suggests VerifyCusp;
        off, it is empty."""
        from tmm_workbench.app.tools import cutter_from_tool
        from tmm_workbench.core.strategies import raster_drop

        r = run_surface(bump_stl(), sample_step=0.5, stepover_mode="offset3d", cusp=0.02, progress=False,
                        doc_name="TmmCuspReport")
        self.assertEqual(r.op.CheckCusp, "Auto")   # on: the bump is a small region
        self.assertEqual(r.op.getEditorMode("CuspReport"), ["ReadOnly"])
        from tmm_workbench.core.strategies.surface.forward_step import FORWARD_STEPS

        params = r.op.Proxy.params_from(r.op, boundary=r.op.Proxy.boundary(r.op, r.mesh),
                                        forward_step=FORWARD_STEPS[r.op.ForwardStep])  # as the op computes it
        result = raster_drop.compute(r.mesh, cutter_from_tool(r.op.ToolController.Tool), params)
        said = result.diagnostics["cusp_check"]
        self.assertGreater(said["exceeding"], 0)   # the coarse bump's slopes: the 3D offset overshoots here
        self.assertIn(f"{said['exceeding']} of {said['measured']} measured {said['cell']:.3g} mm cells above it",
                      r.op.CuspReport)
        self.assertIn("VerifyCusp adds partial passes there", r.op.CuspReport)
        x, y, _, _ = said["places"][0]
        self.assertIn(f"({x:.1f}, {y:.1f})", r.op.CuspReport)
        r.op.CheckCusp = "Off"
        r.doc.recompute()
        self.assertEqual(r.op.CuspReport, "")
        FreeCAD.closeDocument(r.doc.Name)


def line_sketch(doc, a, b, name="Start"):
    """An open sketch: one line from a to b (XY)."""
    import Part

    sk = doc.addObject("Sketcher::SketchObject", name)
    sk.addGeometry(Part.LineSegment(FreeCAD.Vector(a[0], a[1], 0), FreeCAD.Vector(b[0], b[1], 0)))
    doc.recompute()
    return sk


def on_line(p, a, b) -> float:
    """XY distance of p from the infinite line through a and b."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    return abs((p[0] - a[0]) * dy - (p[1] - a[1]) * dx) / (dx * dx + dy * dy) ** 0.5


class Offset3DFromCurve(FreeCADTestCase):
    """OffsetStart Curve (issue 14 item 1): the passes offset from an open sketch line to both sides."""

    def test_start_curve_save_reopen_and_bad_input(self) -> None:
        doc = new_doc("TmmOffsetCurve")
        _, _, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.5, "BoundaryShape": "Model"})
        self.assertEqual(op.OffsetStart, "Boundary")                     # a new op: from the boundary, as before
        a, b = (-10.0, -4.0), (10.0, 4.0)
        sk = line_sketch(doc, a, b)
        op.StepOverMode, op.CuspHeight, op.OffsetStart, op.OffsetCurve = "Offset3D", 0.02, "Curve", sk
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        pts = cut_xy(op)
        # the first pass is the line (its drop), across the whole box; the passes go to both sides of it
        first = [p for p in pts[:200] if on_line(p, a, b) < 1e-6]
        self.assertGreater(len(first), 20)
        side = [((p[0] - a[0]) * (b[1] - a[1]) - (p[1] - a[1]) * (b[0] - a[0])) for p in pts]
        self.assertTrue(min(side) < -50 and max(side) > 50, (min(side), max(side)))
        # the next pass lies about one step from the line (the flat step at 0.02 mm with the 4 mm ball is 0.56
        # mm; smaller on the bump's slopes)
        dists = sorted({round(on_line(p, a, b), 3) for p in pts if on_line(p, a, b) > 1e-3})
        self.assertTrue(0.15 < dists[0] < 0.6, dists[:5])
        commands = len(op.Path.Commands)
        op = reopened(doc, op, "offset3d_curve.FCStd")
        doc = op.Document
        self.assertEqual((op.OffsetStart, op.OffsetCurve.Name), ("Curve", "Start"))
        doc.recompute()
        self.assertEqual(len(op.Path.Commands), commands)
        # bad input: a message naming the property, no path
        far = line_sketch(doc, (100.0, 100.0), (120.0, 100.0), "Far")
        for value, fragment in ((far, "start curve: it lies outside the machining region"),
                                (None, "OffsetStart 'Curve': no curve chosen (OffsetCurve is empty)")):
            op.OffsetCurve = value
            doc.recompute()
            self.assertFalse(op.isValid())
            self.assertIn(fragment, op.getStatusString())
            self.assertEqual(len(op.Path.Commands), 0)
        point = doc.addObject("Part::Feature", "Point")
        import Part

        point.Shape = Part.Vertex(FreeCAD.Vector(0, 0, 0))
        op.OffsetCurve = point
        doc.recompute()
        self.assertIn("OffsetStart 'Curve': 'Point' has no edges", op.getStatusString())
        op.OffsetCurve, op.StepOverMode = doc.getObject("Start"), "Cusp"
        doc.recompute()
        self.assertIn("OffsetStart 'Curve' needs StepOverMode 'Offset3D'", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        close_all()

    def test_a_document_from_before_the_start_choice_restores_from_the_boundary(self) -> None:
        doc = new_doc("TmmOldOffsetStart")
        _, _, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.5, "BoundaryShape": "Model",
                                                             "StepOverMode": "Offset3D", "CuspHeight": 0.02})
        self.assertTrue(op.isValid(), op.getStatusString())
        before = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        for prop in ("OffsetStart", "OffsetCurve"):                  # as saved by an older TMM
            op.removeProperty(prop)
        op = reopened(doc, op, "old_offset_start.FCStd")
        self.assertEqual(op.OffsetStart, "Boundary")
        op.Document.recompute()
        # the same path (to the 6 decimals a saved Path keeps)
        after = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        self.assertEqual([(n, sorted(p)) for n, p in after], [(n, sorted(p)) for n, p in before])
        self.assertLess(max(abs(p[k] - q[k]) for (_, p), (_, q) in zip(after, before) for k in p), 2e-6)
        close_all()

    def test_run_surface_offset_from(self) -> None:
        import Mesh

        doc = new_doc("TmmApiOffsetCurve")
        mesh = doc.addObject("Mesh::Feature", "Bump")
        mesh.Mesh = Mesh.Mesh(str(bump_stl()))
        sk = line_sketch(doc, (-10.0, 0.0), (10.0, 0.0))
        r = run_surface(mesh, sample_step=0.5, stepover_mode="offset3d", cusp=0.02, offset_from=sk, progress=False)
        self.assertEqual((r.op.OffsetStart, r.op.OffsetCurve.Name), ("Curve", sk.Name))
        ys = [p[1] for p in r.toolpath.cutting_points()]
        self.assertTrue(min(ys) < -9 and max(ys) > 9)
        with self.assertRaises(TmmError) as ctx:
            run_surface(mesh, stepover_mode="cusp", offset_from=sk, progress=False)
        self.assertIn("offset_from needs stepover_mode 'offset3d', got 'cusp'", str(ctx.exception))
        close_all()


class Offset3DEstimate(FreeCADTestCase):
    @core_work  # the estimate against the core's computation (the op and its Job: the tests above)
    def test_estimate_is_what_the_op_computes(self) -> None:
        """The panel's estimate for StepOverMode Offset3D (not the raster's): the passes' points and cutting time
        within 0.5-2x of what the op computes."""
        from tmm_workbench.app import work_estimate
        from tmm_workbench.app.simulation import toolpath_and_feeds
        from tmm_workbench.app.tools import cutter_from_tool
        from tmm_workbench.core.sim.cycle_time import three_axis_time
        from tmm_workbench.core.strategies import raster_drop

        doc = new_doc("TmmOffsetEstimate")
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.4, "BoundaryShape": "Model",
                                                              "StepOverMode": "Offset3D", "CuspHeight": 0.02})
        self.assertTrue(op.isValid(), op.getStatusString())
        est = work_estimate.estimate(op)
        mesh = op.Proxy.mesh
        params = op.Proxy.params_from(op, boundary=op.Proxy.boundary(op, mesh))
        result = raster_drop.compute(mesh, cutter_from_tool(tc.Tool), params)
        points = result.diagnostics["points"]
        # the count holds the cusp check's measurement too (CheckCusp Auto runs on this small region: its dense
        # raster at most)
        from tmm_workbench.core.strategies.surface import variable_step

        check = variable_step.estimate_params(cutter_from_tool(tc.Tool), params)
        self.assertIn("cusp check", est.note)
        self.assertTrue(0.5 * points <= est.count - check <= 2.0 * points, (est.count, check, points))
        tp, feeds = toolpath_and_feeds(op)
        cutting = three_axis_time(tp.points(), feeds, tc.HorizRapid.Value, tc.VertRapid.Value).cutting_seconds
        self.assertTrue(0.5 * cutting < est.cutting_seconds < 2.0 * cutting, (est.cutting_seconds, cutting))
        self.assertTrue(0.5 * result.diagnostics["levels"] <= est.passes <= 2.0 * result.diagnostics["levels"],
                        (est.passes, result.diagnostics["levels"]))
        close_all()
