"""FreeCAD ToolBits -> core cutters: endmill, ballend, bullnose (0.20's FlatRadius), chamfer and v-bit
(cones), TMM's tmm_apt shape (the generalized APT cutter: made, read from a .fctb, drawn to the kernel's
profile, saved and reopened, cutting), others refused."""
from __future__ import annotations

import unittest
from pathlib import Path

import Path as FCPath

import FreeCAD
import Part

from fc_helpers import OUT, FreeCADTestCase, bump_stl, close_all, job_with_op, new_doc
from tmm_workbench.app import tools
from tmm_workbench.app import compat
from tmm_workbench.app.tools import cutter_from_tool, shape_name
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools.cutter import Cutter

APT_BIT_FILE = tools.APT_SHAPE_FILE.parents[1] / "Bit" / "tmm_apt_10mm_r2_taper3.fctb"


def stock_bit(doc, file_name: str):
    """One of the ToolBits FreeCAD ships (Mod/Path/Tools/Bit/*.fctb on 0.20, Mod/CAM/... from 1.0)."""
    return compat.toolbit_from_file(doc, compat.stock_bit_file(file_name))


class ToolMapping(FreeCADTestCase):
    def test_stock_bits(self) -> None:
        doc = new_doc()
        flat = cutter_from_tool(stock_bit(doc, "5mm_Endmill.fctb"))
        self.assertEqual((flat.kind, flat.diameter, flat.corner_radius), ("flat", 5.0, 0.0))
        ball = cutter_from_tool(stock_bit(doc, "6mm_Ball_End.fctb"))
        self.assertEqual((ball.kind, ball.diameter, ball.corner_radius), ("ball", 6.0, 3.0))
        # 0.20's bullnose stores the flat bottom's radius (1.5 of 3): the corner radius is 3 - 1.5
        bull = cutter_from_tool(stock_bit(doc, "6mm_Bullnose.fctb"))
        self.assertEqual((bull.kind, bull.diameter, bull.corner_radius), ("bull", 6.0, 1.5))
        # Cones: included angle from a flat tip; the profile rises (D - tip)/2 / tan(angle/2) to the rim.
        import math
        for file_name, d, angle, tip in (("60degree_Vbit.fctb", 10.0, 60.0, 1.0),
                                         ("45degree_chamfer.fctb", 12.3323, 45.0, 5.0)):
            bit = stock_bit(doc, file_name)
            if compat.toolbits_are_assets():  # 1.1 ships another tip for the 60-degree V-bit
                tip = float(bit.TipDiameter.Value)
            self.assertAlmostEqual(float(bit.TipDiameter.Value), tip, places=9)
            c = cutter_from_tool(bit)
            self.assertEqual(c.kind, "general")
            self.assertAlmostEqual(c.diameter, d, places=4)
            self.assertAlmostEqual(c.taper_angle_deg, angle / 2, places=9)
            n = c.native
            self.assertAlmostEqual(float(n.height(tip / 2)), 0.0, places=9)
            rise = (d - tip) / 2 / math.tan(math.radians(angle / 2))
            self.assertAlmostEqual(float(n.height(d / 2)), rise, places=6)

    def test_made_bits(self) -> None:
        doc = new_doc()
        bit = tools.make_tool_bit(doc, "bullnose", 10.0, 2.0)
        self.assertEqual(shape_name(bit), "bullnose")
        if compat.toolbits_are_assets():  # 1.1 stores the corner radius itself
            self.assertAlmostEqual(bit.CornerRadius.Value, 2.0)
        else:                             # 0.20 and 1.0: the flat bottom's radius
            self.assertAlmostEqual(bit.FlatRadius.Value, 3.0)
        c = cutter_from_tool(bit)
        self.assertEqual((c.kind, c.diameter, c.corner_radius), ("bull", 10.0, 2.0))
        c = cutter_from_tool(tools.make_tool_bit(doc, "endmill", 3.175))
        self.assertEqual((c.kind, c.diameter), ("flat", 3.175))

    def test_other_shapes_are_refused_by_name(self) -> None:
        doc = new_doc()
        for file_name, shape in (("5mm_Drill.fctb", "drill"), ("probe.fctb", "probe"),
                                 ("slittingsaw.fctb", "slittingsaw")):
            with self.assertRaises(TmmError) as ctx:
                cutter_from_tool(stock_bit(doc, file_name))
            self.assertIn(f"'{shape}'", str(ctx.exception))
            self.assertIn("ballend", str(ctx.exception))

    def test_legacy_tools(self) -> None:
        if not isinstance(getattr(FCPath, "Tool", None), type):  # 1.0 removed the legacy tools (Path.Tool is a package)
            self.assertGreaterEqual(compat.freecad_version(), (1, 0))
            return
        t = FCPath.Tool()
        t.Diameter, t.ToolType = 8.0, "BallEndMill"
        self.assertEqual(cutter_from_tool(t).kind, "ball")
        t.ToolType, t.CornerRadius = "EndMill", 1.0
        c = cutter_from_tool(t)
        self.assertEqual((c.kind, c.corner_radius), ("bull", 1.0))
        t.ToolType = "Drill"
        self.assertRaises(TmmError, cutter_from_tool, t)

    def test_op_with_a_vbit_cuts_and_one_with_a_drill_fails_clearly(self) -> None:
        doc = new_doc()
        job, tc, op = job_with_op(doc, str(bump_stl()))
        self.assertTrue(op.isValid(), op.getStatusString())
        vbit = stock_bit(doc, "60degree_Vbit.fctb")
        self.assertTrue(op.Proxy.isToolSupported(op, vbit))
        tc.Tool = vbit
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertGreater(len(op.Path.Commands), 10)
        drill = stock_bit(doc, "5mm_Drill.fctb")
        self.assertFalse(op.Proxy.isToolSupported(op, drill))
        tc.Tool = drill
        op.touch()
        doc.recompute()
        self.assertFalse(op.isValid())
        self.assertIn("'drill'", op.getStatusString())
        self.assertEqual(len(op.Path.Commands), 0)

def profile_error(shape, cutter: Cutter) -> float:
    """Largest |z - h(rho)| between the drawn tool's lowest point at distance rho from its axis (a vertical
    line through the solid) and the kernel's profile h, for rho across the lower profile."""
    box = shape.BoundBox
    x0, y0 = (box.XMin + box.XMax) / 2, (box.YMin + box.YMax) / 2
    n, worst = cutter.native, 0.0
    for i in range(1, 60):
        rho = n.max_radius * i / 60
        line = Part.LineSegment(FreeCAD.Vector(x0 + rho, y0, box.ZMin - 1), FreeCAD.Vector(x0 + rho, y0, box.ZMax + 1))
        hits = shape.section(line.toShape()).Vertexes
        if not hits:
            return float("inf")
        worst = max(worst, abs(min(v.Point.z for v in hits) - box.ZMin - float(n.height(rho))))
    return worst


class AptBits(FreeCADTestCase):
    """The generalized APT cutter from TMM's own ToolBit shape, on every version."""

    def test_made_bit_maps_back_and_is_drawn_to_the_kernel_profile(self) -> None:
        doc = new_doc()
        for cutter in (Cutter(10.0, 2.0, 5.0, 3.0, 20.0), Cutter(12.0, 3.0, 10.0, -4.0, 20.0),
                       Cutter(10.0, 0.0, 0.0, 10.0, 15.0)):
            bit = tools.make_apt_bit(doc, cutter)
            self.assertEqual(shape_name(bit), "tmm_apt")
            self.assertEqual(cutter_from_tool(bit), cutter)
            self.assertTrue(bit.Shape.isValid() and bit.Shape.Volume > 0, cutter.describe())
            self.assertLess(profile_error(bit.Shape, cutter), 1e-4, cutter.describe())
        # a plain cutter through bit_for_cutter keeps FreeCAD's shapes; a cone gets TMM's
        self.assertEqual(shape_name(tools.bit_for_cutter(doc, Cutter.ball(6.0))), "ballend")
        self.assertEqual(shape_name(tools.bit_for_cutter(doc, Cutter.vbit(10.0, 60.0, 1.0))), "tmm_apt")

    def test_shipped_shape_is_what_the_generator_makes(self) -> None:
        import os
        import runpy

        out = OUT / "tmm_apt_regenerated.fcstd"
        os.environ["TMM_SHAPE_OUT"] = str(out)
        try:
            runpy.run_path(str(tools.APT_SHAPE_FILE.parents[3] / "scripts" / "make_tool_shape.py"))
        finally:
            del os.environ["TMM_SHAPE_OUT"]

        def summary(path: Path) -> tuple:
            doc = FreeCAD.openDocument(str(path))
            try:
                bag = next(o for o in doc.Objects if o.Label == "Attributes")
                props = sorted((p, bag.getTypeIdOfProperty(p), bag.getGroupOfProperty(p), str(bag.getPropertyByName(p)))
                               for p in bag.PropertiesList if bag.getGroupOfProperty(p) in ("Shape", "Attributes"))
                sketch = doc.getObject("Sketch")
                return (doc.getObject("Body").Label, props, sorted(sketch.ExpressionEngine), len(sketch.Constraints))
            finally:
                FreeCAD.closeDocument(doc.Name)

        self.assertEqual(summary(tools.APT_SHAPE_FILE), summary(out),
                         "resources/tools/Shape/tmm_apt.fcstd is stale: run freecadcmd scripts/make_tool_shape.py")

    def test_impossible_bit_is_refused_by_name(self) -> None:
        doc = new_doc()
        bit = tools.make_apt_bit(doc, Cutter(10.0, 2.0, 0.0, 3.0, 20.0), label="Taper3")
        bit.CornerRadius = 6.0  # the arc centre would cross the axis
        with self.assertRaises(TmmError) as ctx:
            cutter_from_tool(bit)
        self.assertIn("'Taper3'", str(ctx.exception))
        self.assertIn("corner radius", str(ctx.exception))
        with self.assertRaises(TmmError):
            tools.make_apt_bit(doc, Cutter(10.0, 2.0, 0.0, 3.0, 20.0), length=10.0)

    def test_shipped_bit_file(self) -> None:
        doc = new_doc()
        c = cutter_from_tool(compat.toolbit_from_file(doc, str(APT_BIT_FILE)))
        self.assertEqual(c, Cutter(10.0, 2.0, 0.0, 3.0, 20.0))
        self.assertEqual(c.kind, "general")

    def test_saved_bit_reopens_as_the_same_cutter(self) -> None:
        doc = new_doc("TmmApt")
        cutter = Cutter(8.0, 1.5, 2.0, 4.0, 16.0)
        name = tools.make_apt_bit(doc, cutter).Name
        path = OUT / "apt_bit.FCStd"
        doc.saveAs(str(path))
        close_all()
        doc = FreeCAD.openDocument(str(path))
        bit = doc.getObject(name)
        self.assertEqual(cutter_from_tool(bit), cutter)
        bit.TaperAngle = 6.0  # edited after reopening: the cutter follows
        doc.recompute()
        self.assertEqual(cutter_from_tool(bit).taper_angle_deg, 6.0)
        close_all()

    def test_op_with_an_apt_bit_cuts(self) -> None:
        doc = new_doc()
        job, tc, op = job_with_op(doc, str(bump_stl()))
        cutter = Cutter(6.0, 1.0, 5.0, 3.0, 15.0)
        bit = tools.make_apt_bit(doc, cutter)
        self.assertTrue(op.Proxy.isToolSupported(op, bit))
        tc.Tool = bit
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertGreater(len(op.Path.Commands), 10)

    def test_api_takes_a_core_cutter(self) -> None:
        from tmm_workbench.app.api import run_surface

        cutter = Cutter(6.0, 1.0, 5.0, 3.0, 15.0)
        r = run_surface(str(bump_stl()), tool=cutter, stepover=2.0, sample_step=1.0, progress=False,
                        doc_name="TmmAptApi")
        self.assertEqual(cutter_from_tool(r.op.ToolController.Tool), cutter)
        self.assertEqual(shape_name(r.op.ToolController.Tool), "tmm_apt")
        self.assertGreater(sum(line.startswith("G1") for line in r.gcode.splitlines()), 10)
        close_all()


if __name__ == "__main__":
    unittest.main()
