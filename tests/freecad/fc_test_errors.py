"""Bad input gives a clear error on the op, an empty Path (no partial path), and no crash."""
from __future__ import annotations

import unittest

import FreeCAD
import Part

from fc_helpers import OUT, BadInputCase, FreeCADTestCase, bump_stl, bump_triangles, job_with_op, new_doc, write_ascii_stl
from tmm_workbench.app import job as jobs
from tmm_workbench.app import compat, tools
from tmm_workbench.core.errors import TmmError


class BadInput(BadInputCase):
    def setUp(self) -> None:
        self.doc = new_doc("TmmErrors")
        self.job, self.tc, self.op = job_with_op(self.doc, str(bump_stl()), values={"BoundaryShape": "Model"})
        self.assertTrue(self.op.isValid(), self.op.getStatusString())
        self.assertGreater(len(self.op.Path.Commands), 10)

    def recovers(self) -> None:
        self.op.StlFile = str(bump_stl())
        self.doc.recompute()
        self.assertTrue(self.op.isValid(), self.op.getStatusString())
        self.assertGreater(len(self.op.Path.Commands), 10)

    def test_missing_stl(self) -> None:
        self.op.StlFile = str(OUT / "no_such_file.stl")
        self.assertFails("file not found", "no_such_file.stl")
        self.recovers()

    def test_empty_stl(self) -> None:
        empty = OUT / "empty.stl"
        empty.write_bytes(b"")
        self.op.StlFile = str(empty)
        self.assertFails("empty.stl")

    def test_malformed_stl(self) -> None:
        bad = OUT / "malformed.stl"
        bad.write_text("solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 1 2\n")
        self.op.StlFile = str(bad)
        self.assertFails("malformed.stl")

    def test_nan_coordinates(self) -> None:
        tris = bump_triangles(4)
        tris[3] = ((float("nan"), 0.0, 0.0), tris[3][1], tris[3][2])
        nan = write_ascii_stl(OUT / "nan.stl", tris)
        self.op.StlFile = str(nan)
        self.assertFails("nan.stl", "finite")

    def test_corner_radius_larger_than_radius(self) -> None:
        with self.assertRaises(TmmError) as ctx:  # TMM makes no such bit
            tools.make_tool_bit(self.doc, "bullnose", 4.0, 3.0)
        self.assertIn("corner radius 3 mm is larger than the tool radius 2 mm", str(ctx.exception))
        bit = tools.make_tool_bit(self.doc, "bullnose", 4.0, 1.0)  # a user edits it into one
        if compat.toolbits_are_assets():
            # 1.1: the bit's own shape sketch fails, so FreeCAD recomputes nothing that depends on it; the
            # map still refuses the bit
            bit.CornerRadius = 3.0
            with self.assertRaises(TmmError) as ctx:
                tools.cutter_from_tool(bit)
            self.assertIn("corner radius 3 mm is larger than the tool radius 2 mm", str(ctx.exception))
            return
        bit.FlatRadius = -1.0  # 0.20 and 1.0 store the flat bottom's radius: corner 3
        self.tc.Tool = bit
        self.assertFails("corner radius 3 mm is larger than the tool radius 2 mm")

    def test_stepover_not_positive(self) -> None:
        self.op.StepOver = 0.0
        self.assertFails("step", "must be a positive length, got 0")
        self.op.StepOver = -1.0
        self.assertFails("step", "must be a positive length, got -1")

    def test_sample_step_not_positive(self) -> None:
        self.op.SampleStep = 0.0
        self.assertFails("sampl", "must be a positive length, got 0")

    def test_boundary_outside_model(self) -> None:
        stock = self.job.Stock  # model box + 1 mm; moved 50 mm past the model's +X side
        stock.ExtXneg = -(20.0 + 50.0)
        stock.ExtXpos = 100.0
        self.op.BoundaryShape = "Stock"
        self.assertFails("outside the model")

    def test_boundary_shrunk_to_nothing(self) -> None:
        self.op.BoundaryMargin = -15.0
        self.assertFails("boundary is empty")

    def test_safe_height_below_model(self) -> None:
        self.op.setExpression("SafeHeight", None)
        self.op.SafeHeight = 1.0  # the bump is 5 mm high
        self.assertFails("safe height")

    def test_model_without_faces(self) -> None:
        wire = self.doc.addObject("Part::Feature", "Wire")
        wire.Shape = Part.makeLine(FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(10, 0, 0))
        self.op.StlFile = ""
        self.op.Model = wire
        self.assertFails("has no faces")

    def test_tool_diameter_zero(self) -> None:
        """FreeCAD's ObjectOp returned early here, keeping the old path and the op valid."""
        self.tc.Tool.Diameter = 0.0
        self.assertFails("diameter must be a length > 0 mm, got 0")

    def test_zero_feeds(self) -> None:
        """Tool controllers from FreeCAD's tool library have feed 0: G1 F0 must not reach a post."""
        self.tc.HorizFeed = 0.0
        self.assertFails("HorizFeed must be a feed > 0 mm/min, got 0 mm/min", "set the cutting feeds")
        self.tc.HorizFeed = 10.0
        self.tc.VertFeed = 0.0
        self.assertFails("VertFeed must be a feed > 0 mm/min, got 0 mm/min")
        self.tc.VertFeed = 4.0
        self.recovers()

    def test_tool_controller_removed(self) -> None:
        self.op.ToolController = None
        self.assertFails("no tool controller")

    def test_tiny_sample_step_is_refused_quickly(self) -> None:
        self.op.SampleStep = 1e-6
        self.assertFails("sample step 1e-06 mm", "CL points", seconds=2.0)

    def test_huge_boundary_margin_is_refused_quickly(self) -> None:
        self.op.BoundaryMargin = 5e4
        self.assertFails("mm boundary gives about", seconds=2.0)

    def test_nan_stepover(self) -> None:
        self.op.StepOver = float("nan")
        self.assertFails("step-over must be a positive length, got nan")

    def test_prepare_model_errors(self) -> None:
        with self.assertRaises(TmmError) as ctx:
            jobs.prepare_model(self.doc, OUT / "missing.stl")
        self.assertIn("file not found", str(ctx.exception))
        with self.assertRaises(TmmError):
            jobs.prepare_model(self.doc, 42)


if __name__ == "__main__":
    unittest.main()
