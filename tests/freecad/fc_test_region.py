"""The TMM Surface op's machining region, spiral and slope range in a Path Job (issue 14 item 3): faces
selected on a Part model, a sketch with a hole, the spiral, save/reopen, a document from before the region,
run_surface, and bad input (an open sketch, faces of another object, a region off the model, no reachable
point): a clear message on the op and no path."""
from __future__ import annotations

import math

import FreeCAD
import Part

from fc_helpers import FreeCADTestCase, job_with_op, moves, new_doc, reopened

V = FreeCAD.Vector
CENTRE, RADIUS = (20.0, 20.0), 8.0


def part_model(doc):
    """A 60 x 40 x 10 block with a cylinder (r 8 about (20, 20)) standing 8 mm on it."""
    block = Part.makeBox(60, 40, 10)
    post = Part.makeCylinder(RADIUS, 8, V(CENTRE[0], CENTRE[1], 10))
    obj = doc.addObject("Part::Feature", "Block")
    obj.Shape = block.fuse(post).removeSplitter()
    doc.recompute()
    return obj


def face_at(obj, z):
    """Name of the planar horizontal face at height z."""
    for k, f in enumerate(obj.Shape.Faces, 1):
        bb = f.BoundBox
        if abs(bb.ZMin - z) < 1e-6 and abs(bb.ZMax - z) < 1e-6:
            return f"Face{k}"
    raise AssertionError(f"no face at z {z}")


def sketch(doc, points, circle=None, closed=True, name="Region"):
    sk = doc.addObject("Sketcher::SketchObject", name)
    n = len(points)
    for i in range(n if closed else n - 1):
        a, b = points[i], points[(i + 1) % n]
        sk.addGeometry(Part.LineSegment(V(a[0], a[1], 0), V(b[0], b[1], 0)))
    if circle is not None:
        sk.addGeometry(Part.Circle(V(circle[0], circle[1], 0), V(0, 0, 1), circle[2]))
    doc.recompute()
    return sk


def cut_xy(op):
    """XY of the op's cutting moves (G1 below the safe height)."""
    safe = op.SafeHeight.Value
    return [(p["X"], p["Y"]) for n, p in moves(op) if n == "G1" and p["Z"] < safe - 1e-6]


def dist(p, c=CENTRE):
    return math.hypot(p[0] - c[0], p[1] - c[1])


class RegionFromFaces(FreeCADTestCase):
    def test_selected_faces_bound_the_tool_centre(self) -> None:
        doc = new_doc("TmmRegionFaces")
        model = part_model(doc)
        top = face_at(model, 18.0)          # the cylinder's top: a disc
        job, _, op = job_with_op(doc, model, values={"Region": "Faces", "RegionFaces": [(model, (top,))],
                                                     "StepOver": 1.0, "SampleStep": 0.5})
        self.assertTrue(op.isValid(), op.getStatusString())
        pts = cut_xy(op)
        self.assertGreater(len(pts), 30)   # flat: each pass a few long moves (ChordTolerance)
        self.assertLessEqual(max(dist(p) for p in pts), RADIUS + 0.011)    # within the disc (+ tolerance)
        self.assertGreater(max(dist(p) for p in pts), RADIUS - 1.0)        # out to its edge
        op.BoundaryMargin = -2.0                                           # shrunk as the box would be
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertLessEqual(max(dist(p) for p in cut_xy(op)), RADIUS - 2.0 + 0.011)
        op.BoundaryMargin = -9.0
        doc.recompute()
        self.assertIn("Region 'Faces' shrunk by BoundaryMargin -9 mm leaves nothing", op.getStatusString())
        op.BoundaryMargin = 0.0
        # the block's top face: the rectangle with the post's hole; the tool centre never in the hole
        ring = face_at(model, 10.0)
        op.RegionFaces = [(model, (ring,))]
        op.Pattern = "ZigZag"
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        pts = cut_xy(op)
        self.assertGreaterEqual(min(dist(p) for p in pts), RADIUS - 0.011)
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]
        self.assertAlmostEqual(min(xs), 0.0, places=3)
        self.assertAlmostEqual(max(ys), 40.0, places=3)
        self.assertGreater(sum(1 for n, _ in moves(op) if n == "G0"), 4)  # jumps over the post
        # in the GUI one selects the faces of the Job's model clone: the same region
        clone = job.Model.Group[0]
        self.assertIsNot(clone, model)
        count = len(op.Path.Commands)
        op.RegionFaces = [(clone, (ring,))]
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(len(op.Path.Commands), count)

    def test_faces_of_another_object_are_refused(self) -> None:
        doc = new_doc("TmmRegionOther")
        model = part_model(doc)
        other = doc.addObject("Part::Feature", "Other")
        other.Shape = Part.makeBox(10, 10, 10)
        doc.recompute()
        _, _, op = job_with_op(doc, model, values={"Region": "Faces", "RegionFaces": [(other, ("Face6",))]})
        self.assertFalse(op.isValid())
        self.assertIn("Region 'Faces': the faces belong to 'Other', which is not the model", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)

    def test_run_surface_with_face_names_spiral_and_slope_range(self) -> None:
        from tmm_workbench.app.api import run_surface

        doc = new_doc("TmmRegionApi")
        model = part_model(doc)
        ring = face_at(model, 10.0)
        r = run_surface(model, diameter=4, stepover=1.5, sample_step=0.5, region=ring, pattern="spiral",
                        slope_range=(0, 30), progress=False)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertEqual((r.op.Region, r.op.Pattern), ("Faces", "Spiral"))
        self.assertAlmostEqual(r.op.SlopeMax.Value, 30.0)
        self.assertIn("G1", r.gcode)
        pts = cut_xy(r.op)
        self.assertGreaterEqual(min(dist(p) for p in pts), RADIUS - 0.011)
        with self.assertRaisesRegex(Exception, r"slope_max must be .*got 120"):
            run_surface(model, diameter=4, region=ring, slope_range=(0, 120), progress=False)
        with self.assertRaisesRegex(Exception, r"region_tolerance must be .*got 0"):
            run_surface(model, diameter=4, region=ring, region_tolerance=0.0, progress=False)
        with self.assertRaisesRegex(Exception, r"region must be None \(the box\), 'rest', a sketch, face names"):
            run_surface(model, diameter=4, region=[3.5], progress=False)
        other = sketch(new_doc("TmmRegionElsewhere"), [(5, 5), (50, 5), (50, 35)])
        with self.assertRaisesRegex(Exception, r"region 'Region' must be in the model's document"):
            run_surface(model, diameter=4, region=other, progress=False)


class RegionFromSketch(FreeCADTestCase):
    def test_sketch_with_a_hole_saves_and_reopens(self) -> None:
        doc = new_doc("TmmRegionSketch")
        model = part_model(doc)
        sk = sketch(doc, [(5, 5), (50, 5), (50, 35), (5, 35)], circle=(CENTRE[0], CENTRE[1], 10.0))
        _, _, op = job_with_op(doc, model, values={"Region": "Sketch", "RegionSketch": sk, "StepOver": 1.5,
                                                   "SampleStep": 0.5, "RasterAngle": 30.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        pts = cut_xy(op)
        for x, y in pts:
            self.assertTrue(5 - 1e-3 <= x <= 50 + 1e-3 and 5 - 1e-3 <= y <= 35 + 1e-3, (x, y))
        self.assertGreaterEqual(min(dist(p) for p in pts), 10.0 - 0.011)    # the inner loop is a hole
        count = len(op.Path.Commands)
        op = reopened(doc, op, "region_sketch.FCStd")
        doc = op.Document
        self.assertEqual(op.Region, "Sketch")
        self.assertEqual(op.RegionSketch.Name, "Region")
        self.assertIn("Spiral", op.getEnumerationsOfProperty("Pattern"))
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(len(op.Path.Commands), count)

    def test_bad_regions_fail_the_op_with_a_clear_message(self) -> None:
        doc = new_doc("TmmRegionBad")
        model = part_model(doc)
        open_sk = sketch(doc, [(5, 5), (50, 5), (50, 35)], closed=False, name="Open")
        _, _, op = job_with_op(doc, model, values={"Region": "Sketch", "RegionSketch": open_sk})
        self.assertFalse(op.isValid())
        self.assertIn("Region 'Sketch': 'Open' is not closed", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        far = sketch(doc, [(200, 200), (240, 200), (240, 230)], name="Far")
        op.RegionSketch = far
        doc.recompute()
        self.assertFalse(op.isValid())
        self.assertIn("machining region (x 200..240, y 200..230) does not overlap the model", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        op.Region = "Box"
        op.SlopeMin = 60.0                       # the block and the post's top are flat, its side vertical
        op.SlopeMax = 80.0
        op.Pattern = "OneWay"
        doc.recompute()
        self.assertFalse(op.isValid())
        self.assertIn("no reachable point", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)
        op.Region = "Sketch"
        op.RegionTolerance = 0.0
        op.SlopeMin = 0.0
        doc.recompute()
        self.assertIn("region tolerance must be in [0.001, 10] mm, got 0", op.getStatusString())
        op.RegionTolerance = 0.01
        op.RegionSketch = None
        op.SlopeMin = 0.0
        op.SlopeMax = 90.0
        doc.recompute()
        self.assertIn("Region 'Sketch': no sketch chosen", op.getStatusString())

    def test_a_document_from_before_the_region_restores_todays_path(self) -> None:
        doc = new_doc("TmmRegionOld")
        model = part_model(doc)
        _, _, op = job_with_op(doc, model, values={"Pattern": "OneWay"})
        self.assertTrue(op.isValid(), op.getStatusString())
        before = [c.toGCode() for c in op.Path.Commands]
        for prop in ("Region", "RegionFaces", "RegionSketch", "RegionTolerance", "SpiralDirection", "SlopeMin",
                     "SlopeMax"):
            op.removeProperty(prop)                                    # as saved by an older TMM
        op.Pattern = ["ZigZag", "OneWay"]                              # its enumeration then
        op.Pattern = "OneWay"
        op = reopened(doc, op, "old_region.FCStd")
        doc = op.Document
        self.assertEqual(op.Region, "Box")
        self.assertEqual((op.SlopeMin.Value, op.SlopeMax.Value), (0.0, 90.0))
        self.assertEqual(op.Pattern, "OneWay")
        self.assertIn("Spiral", op.getEnumerationsOfProperty("Pattern"))
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual([c.toGCode() for c in op.Path.Commands], before)
