"""The TMM Surface op inside a Path Job: moves, feeds, heights, boundary, pattern, inputs, save/reopen."""
from __future__ import annotations

import math
import unittest

import FreeCAD
import Part

from fc_helpers import (OUT, SPHERE_ON_PLATE, FreeCADTestCase, bump_stl, bump_triangles, close_all,
                        job_with_op, mesh_feature, moves, new_doc, reopened)
from tmm_workbench.app import model_proxy
from tmm_workbench.app.op_surface import ObjectTmmSurface

H_FEED, V_FEED = 1200.0, 240.0  # mm/min, as the tool controller gets them


def plunges(mv: list) -> list:
    """The G1 moves at the vertical feed (plunges) among `moves(op)`."""
    return [p for n, p in mv if n == "G1" and round(p["F"] * 60, 6) == V_FEED]


class OpInJob(FreeCADTestCase):
    def test_moves_feeds_and_heights(self) -> None:
        doc = new_doc()
        job, tc, op = job_with_op(doc, str(SPHERE_ON_PLATE), values={"StepOver": 3.0, "SampleStep": 1.5})
        self.assertTrue(op.isValid(), op.getStatusString())
        mv = moves(op)
        self.assertGreater(len(mv), 50)
        self.assertEqual({n for n, _ in mv}, {"G0", "G1"})
        safe, clear = op.SafeHeight.Value, op.ClearanceHeight.Value
        self.assertLess(safe, clear)
        source = model_proxy.source_of(job.Model.Group[0])  # the STL the stand-in box stands for
        self.assertEqual(source, str(SPHERE_ON_PLATE))
        # starts with a Z-only rapid to the clearance height (after the tool change: up before X/Y), ends there
        self.assertEqual(mv[0], ("G0", {"Z": mv[0][1]["Z"]}))
        self.assertAlmostEqual(mv[0][1]["Z"], clear, places=6)
        self.assertEqual(mv[-1][0], "G0")
        self.assertAlmostEqual(mv[-1][1]["Z"], clear, places=6)
        feeds = {round(p["F"] * 60, 6) for n, p in mv if n == "G1"}
        self.assertEqual(feeds, {H_FEED, V_FEED})
        # entries rapid straight down to 1 mm (LinkPolicy.entry_clearance) above the stock and feed from there
        feed_from = min(safe, job.Stock.Shape.BoundBox.ZMax + 1.0)
        for (n0, p0), (n, p) in zip([mv[0]] + mv, mv):
            if n == "G0":
                self.assertNotIn("F", p)
                self.assertGreaterEqual(p["Z"], feed_from - 1e-6)
                if p["Z"] < safe - 1e-9:  # below the safe height only straight down
                    self.assertAlmostEqual((p.get("X", p0.get("X")), p.get("Y", p0.get("Y"))),
                                           (p0.get("X"), p0.get("Y")))
            else:
                self.assertLess(p["Z"], safe)
        # the vertical feed for every plunge (straight down from the safe height) and for every cutting move
        # down more steeply than the op's PlungeAngle (45 deg); the horizontal feed for everything else
        self.assertAlmostEqual(op.PlungeAngle.Value, 45.0)
        tan = math.tan(math.radians(op.PlungeAngle.Value))
        steep = 0
        for (n0, p0), (n1, p1) in zip(mv, mv[1:]):
            if n1 != "G1":
                continue
            slow = round(p1["F"] * 60, 6) == V_FEED
            if n0 == "G0":
                self.assertTrue(slow)
                self.assertAlmostEqual(p0["Z"], feed_from, places=6)
                self.assertAlmostEqual((p0["X"], p0["Y"]), (p1["X"], p1["Y"]))
                continue
            down = p0["Z"] - p1["Z"] > math.hypot(p1["X"] - p0["X"], p1["Y"] - p0["Y"]) * tan
            self.assertEqual(slow, down, (p0, p1))
            steep += down
        self.assertGreater(steep, 0)  # the sphere's far side
        # the toolpath the op keeps for the API matches the Path
        self.assertEqual(len(op.Proxy.toolpath), len(mv) - 2)  # + the Z-only start, ObjectOp's final G0
        self.assertTrue(op.CycleTime and op.CycleTime != "00:00:00")
        self.assertIn(op, job.Operations.Group)

    def test_boundary_stock_vs_model(self) -> None:
        doc = new_doc()
        stl = bump_stl()  # x, y in -10..10
        _, _, op = job_with_op(doc, str(stl), values={"BoundaryShape": "Model"})
        self.assertTrue(op.isValid(), op.getStatusString())

        def xy_range(o):
            pts = [p for n, p in moves(o) if n == "G1"]
            return (min(p["X"] for p in pts), max(p["X"] for p in pts),
                    min(p["Y"] for p in pts), max(p["Y"] for p in pts))

        for got, want in zip(xy_range(op), (-10, 10, -10, 10)):
            self.assertAlmostEqual(got, want, places=5)
        op.BoundaryMargin = 2.0
        doc.recompute()
        for got, want in zip(xy_range(op), (-12, 12, -12, 12)):
            self.assertAlmostEqual(got, want, places=5)
        op.BoundaryMargin = 0.0
        op.BoundaryShape = "Stock"  # the Job's stock: the model's box + 1 mm all round
        doc.recompute()
        bb = op.Proxy.stock.Shape.BoundBox
        for got, want in zip(xy_range(op), (bb.XMin, bb.XMax, bb.YMin, bb.YMax)):
            self.assertAlmostEqual(got, want, places=5)
        self.assertAlmostEqual(bb.XMin, -11, places=5)

    def test_oneway_retracts(self) -> None:
        doc = new_doc()
        stl = str(bump_stl())
        _, _, op = job_with_op(doc, stl, values={"BoundaryShape": "Model", "Pattern": "ZigZag"})
        zig = moves(op)
        op.Pattern = "OneWay"
        doc.recompute()
        one = moves(op)
        self.assertTrue(op.isValid(), op.getStatusString())
        passes = 11  # 20 mm / 2 mm step-over + 1
        self.assertEqual(len(plunges(zig)), 1)
        self.assertEqual(len(plunges(one)), passes)
        # a lift after every pass (a hop just over the stock, below the safe height) and back down
        lifts = [p1 for (n0, p0), (n1, p1) in zip(one, one[1:]) if n1 == "G0" and "Z" in p1 and "Z" in p0
                 and p1["Z"] > p0["Z"] + 1e-6 and p1.get("X", p0.get("X")) == p0.get("X")]
        self.assertGreaterEqual(len(lifts), passes - 1)
        # one-way: every pass runs the same direction (+X at angle 0)
        xs = []
        for (n0, p0), (n1, p1) in zip(one, one[1:]):
            if n1 == "G1" and n0 == "G1" and round(p1["F"] * 60, 6) == H_FEED:
                xs.append(p1["X"] - p0["X"])
        self.assertTrue(all(dx >= -1e-9 for dx in xs))

    def test_off_model_skip_lifts_over_the_gap(self) -> None:
        """Two bumps 10 mm apart, no base: Floor runs the ball along the lowest point between them, Skip
        lifts over the gap and plunges again (one more plunge than passes, zig-zag)."""
        doc = new_doc()
        tris = [tuple((x + dx, y, z) for x, y, z in t) for dx in (-15.0, 15.0) for t in bump_triangles()]
        _, _, op = job_with_op(doc, mesh_feature(doc, tris, "TwoBumps"), values={"BoundaryShape": "Model"})
        self.assertEqual(op.OffModel, "Floor")
        self.assertEqual(op.getEnumerationsOfProperty("OffModel"), ["Floor", "Skip"])
        in_gap = lambda mv: [b for (_, a), (n, b) in zip(mv, mv[1:])  # noqa: E731  (G1 over |x| < 2.5)
                             if n == "G1" and min(a["X"], b["X"]) < 2.5 and max(a["X"], b["X"]) > -2.5]
        floor = moves(op)
        self.assertEqual(len(plunges(floor)), 1)
        self.assertTrue(in_gap(floor))
        op.OffModel = "Skip"
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        skip = moves(op)
        passes = 11  # 20 mm / 2 mm step-over + 1
        self.assertEqual(len(plunges(skip)), passes + 1)
        self.assertEqual(in_gap(skip), [])

    def test_raster_angle(self) -> None:
        doc = new_doc()
        _, _, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "RasterAngle": 90.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        mv = [p for n, p in moves(op) if n == "G1"]
        # passes along Y: consecutive cutting moves mostly keep X
        same_x = sum(1 for a, b in zip(mv, mv[1:]) if abs(a["X"] - b["X"]) < 1e-9)
        self.assertGreater(same_x, 0.8 * len(mv))

    def test_mesh_object_input(self) -> None:
        doc = new_doc()
        mesh = mesh_feature(doc, bump_triangles())
        mesh.Placement.Base = FreeCAD.Vector(100, 50, 3)  # the op machines the placed mesh
        doc.recompute()
        job, _, op = job_with_op(doc, mesh, values={"BoundaryShape": "Model"})
        self.assertTrue(op.isValid(), op.getStatusString())
        base = job.Model.Group[0]
        self.assertIs(model_proxy.source_of(base), mesh)
        self.assertAlmostEqual(base.Shape.BoundBox.XMin, 90, places=5)
        pts = [p for n, p in moves(op) if n == "G1"]
        self.assertAlmostEqual(min(p["X"] for p in pts), 90, places=5)
        self.assertAlmostEqual(max(p["Y"] for p in pts), 60, places=5)
        self.assertAlmostEqual(max(p["Z"] for p in pts), 8, delta=0.05)  # bump top 5 mm + 3 mm
        # an empty Model link falls back to the Job's model: the stand-in box gives back the mesh
        op.Model = None
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(len(op.Proxy.mesh), len(bump_triangles()))

    def test_part_input(self) -> None:
        doc = new_doc()
        plate = Part.makeBox(40, 30, 5, FreeCAD.Vector(-20, -15, -5))
        dome = Part.makeSphere(8, FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 0, 1), 0, 90, 360)
        part = doc.addObject("Part::Feature", "DomePlate")
        part.Shape = plate.fuse(dome).removeSplitter()
        part.Placement.Base = FreeCAD.Vector(0, 0, 10)
        doc.recompute()
        job, _, op = job_with_op(doc, part, values={"BoundaryShape": "Model", "StepOver": 4.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertIs(job.Proxy.baseObject(job, job.Model.Group[0]), part)  # a solid: the Job's own model
        pts = [p for n, p in moves(op) if n == "G1"]
        self.assertAlmostEqual(max(p["Z"] for p in pts), 18.0, delta=0.05)  # dome top 8 + placement 10
        self.assertAlmostEqual(min(p["Z"] for p in pts), 10.0, delta=1e-3)  # plate top
        # without a Model link the Job's model clone is tessellated instead
        n = len(pts)
        op.Model = None
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(len([1 for n_, _ in moves(op) if n_ == "G1"]), n)


class CuspSpacing(FreeCADTestCase):
    def test_spacing_by_a_cusp_height_saves_and_reopens(self) -> None:
        doc = new_doc("TmmCusp")
        _, _, op = job_with_op(doc, str(bump_stl()), values={"SampleStep": 0.5})
        self.assertEqual(op.StepOverMode, "StepOver")                  # a new op: the step-over, as before
        self.assertEqual(op.getEnumerationsOfProperty("StepOverMode"), ["StepOver", "Cusp", "Adaptive", "Offset3D"])
        ys = lambda: sorted({round(p["Y"], 6) for n, p in moves(op) if n == "G1"})  # noqa: E731
        fixed = ys()
        for mode in ("Cusp", "Adaptive"):
            op.StepOverMode, op.CuspHeight = mode, 0.02
            doc.recompute()
            self.assertTrue(op.isValid(), op.getStatusString())
            self.assertNotEqual(ys(), fixed)
        adaptive = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        op = reopened(doc, op, "cusp.FCStd")
        doc = op.Document
        self.assertEqual((op.StepOverMode, round(op.CuspHeight.Value, 9)), ("Adaptive", 0.02))
        self.assertEqual(len(op.Path.Commands), len(adaptive))
        op.CuspHeight = 50.0                                           # above the tool radius
        doc.recompute()
        self.assertFalse(op.isValid())
        self.assertIn("cusp height must be in [0.0001, 2] mm (a machine's resolution to the tool radius), got 50", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        close_all()

    def test_a_document_from_before_the_cusp_spacing_keeps_the_step_over(self) -> None:
        doc = new_doc("TmmOldCusp")
        _, _, op = job_with_op(doc, str(bump_stl()))
        for prop in ("StepOverMode", "CuspHeight", "CuspSlopeLimit"):
            op.removeProperty(prop)                                    # as saved by an older TMM
        op = reopened(doc, op, "old_cusp.FCStd")
        self.assertEqual(op.StepOverMode, "StepOver")
        self.assertAlmostEqual(op.CuspHeight.Value, 0.01)
        close_all()


class SaveAndReopen(FreeCADTestCase):
    def test_a_document_from_before_the_chord_tolerance_keeps_every_point(self) -> None:
        doc = new_doc("TmmOld")
        _, _, op = job_with_op(doc, str(bump_stl()))
        self.assertAlmostEqual(op.ChordTolerance.Value, 0.001)   # a new op: longer moves where they fit
        lean = len(op.Path.Commands)
        op.removeProperty("ChordTolerance")                      # as saved by an older TMM
        op = reopened(doc, op, "old_chord.FCStd")
        doc = op.Document
        self.assertEqual(op.ChordTolerance.Value, 0.0)           # what it was computed with
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertGreater(len(op.Path.Commands), lean)
        close_all()

    def test_save_reopen_keeps_op_properties_and_path(self) -> None:
        doc = new_doc("TmmSave")
        values = {"StepOver": 2.5, "SampleStep": 0.8, "Pattern": "OneWay", "RasterAngle": 30.0,
                  "StockToLeave": 0.2, "BoundaryShape": "Model", "BoundaryMargin": 1.0, "OffModel": "Skip"}
        _, _, op = job_with_op(doc, str(bump_stl()), values=values)
        self.assertTrue(op.isValid(), op.getStatusString())
        before = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
        path = OUT / "reopen.FCStd"
        doc.saveAs(str(path))
        name = op.Name
        close_all()

        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        self.assertIsInstance(op.Proxy, ObjectTmmSurface)
        for prop, value in values.items():
            got = getattr(op, prop)
            self.assertAlmostEqual(got.Value, value) if hasattr(got, "Value") else self.assertEqual(got, value)
        self.assertEqual(op.StlFile, str(bump_stl().resolve()))
        self.assertSamePath([(c.Name, dict(c.Parameters)) for c in op.Path.Commands], before)
        # and it still computes after reopening
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertSamePath([(c.Name, dict(c.Parameters)) for c in op.Path.Commands], before)

    def assertSamePath(self, got, want) -> None:
        """Same commands; values within 1e-5 (a saved Path keeps 6 decimals)."""
        self.assertEqual([n for n, _ in got], [n for n, _ in want])
        for (_, a), (_, b) in zip(got, want):
            self.assertEqual(set(a), set(b))
            for k in a:
                self.assertAlmostEqual(a[k], b[k], delta=1e-5)


if __name__ == "__main__":
    unittest.main()
