"""The Surface op's 3D offset spacing (StepOverMode Offset3D, issue 14 item 1) in a Path Job: closed loops
from the boundary inward, save and reopen, a document saved before the choice existed, run_surface, and bad
input (a cusp above the tool radius): a clear message on the op and no path."""
from __future__ import annotations

import FreeCAD

from fc_helpers import FreeCADTestCase, bump_stl, close_all, job_with_op, moves, new_doc, reopened
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
        self.assertIn("cusp height must be in (0, 2] mm (the tool radius), got 50", op.getStatusString())
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

    def test_run_surface(self) -> None:
        r = run_surface(bump_stl(), stepover=2.0, sample_step=0.5, stepover_mode="offset3d", cusp=0.02,
                        progress=False, doc_name="TmmApiOffset3D")
        self.assertEqual(r.op.StepOverMode, "Offset3D")
        pts = r.toolpath.cutting_points()
        self.assertGreater(len(pts), 100)
        self.assertIn("G1", r.gcode)
        FreeCAD.closeDocument(r.doc.Name)
        with self.assertRaises(TmmError) as ctx:
            run_surface(bump_stl(), stepover_mode="offset3d", cusp=10.0, progress=False, doc_name="TmmApiBad3D")
        self.assertIn("cusp height must be in (0, 3] mm", str(ctx.exception))
