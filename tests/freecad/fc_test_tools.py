"""FreeCAD ToolBits -> core cutters: endmill, ballend, bullnose (0.20's FlatRadius), chamfer and v-bit
(cones), others refused."""
from __future__ import annotations

import unittest
from pathlib import Path

import Path as FCPath

from fc_helpers import FreeCADTestCase, bump_stl, job_with_op, new_doc
from tmm_workbench.app import tools
from tmm_workbench.app import compat
from tmm_workbench.app.tools import cutter_from_tool, shape_name
from tmm_workbench.core.errors import TmmError

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

if __name__ == "__main__":
    unittest.main()
