"""FreeCAD ToolBits -> the core tool assembly: ShankDiameter, CuttingEdgeHeight (flute length), Length and a
neck read from bits made by TMM and from FreeCAD's shipped ball end mill, on 0.20, 1.0 and 1.1 alike; the
default stick-out; holders by name from the shipped library and a user's file."""
from __future__ import annotations

import json
import unittest

import FreeCAD

from fc_helpers import OUT, FreeCADTestCase, new_doc
from tmm_workbench.app import compat, tools
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools.cutter import Cutter


def close(actual, expected, test: unittest.TestCase) -> None:
    test.assertEqual(len(actual), len(expected), actual)
    for a, e in zip(actual, expected):
        for x, y in zip(a, e):
            test.assertAlmostEqual(x, y, places=6, msg=f"{a} != {e}")


class ShankFromToolBits(FreeCADTestCase):
    def test_made_end_mill(self) -> None:
        # a bit TMM makes: a shank of its diameter, flutes of 3 diameters, 50 mm long (tools.make_tool_bit)
        bit = tools.make_tool_bit(new_doc(), "endmill", 6.0)
        self.assertEqual([float(getattr(bit, p).Value) for p in ("ShankDiameter", "CuttingEdgeHeight", "Length")],
                         [6.0, 18.0, 50.0])
        a = tools.assembly_from_tool(bit, "ER11 nut", 35.0, holders_file=None)
        self.assertEqual((a.cutter.kind, a.flute_length, a.shank_diameter, a.overall_length), ("flat", 18, 6, 50))
        close(a.bodies(), [(18, 35, 3, 3, 1), (35, 46.5, 9.5, 9.5, 1)], self)
        # no stick-out: Length minus 3 shank diameters
        self.assertAlmostEqual(tools.assembly_from_tool(bit, holders_file=None).stick_out, 50 - 18)

    def test_shipped_ball_end_mill(self) -> None:
        bit = compat.toolbit_from_file(new_doc(), compat.stock_bit_file("6mm_Ball_End.fctb"))
        a = tools.assembly_from_tool(bit, "ER16 nut", 45.0, shank_clearance=0.5, holder_clearance=2.0,
                                     holders_file=None)
        self.assertEqual((a.cutter.kind, a.cutter.diameter), ("ball", 6.0))
        close(a.bodies(), [(40, 45, 1.5, 1.5, 0.5), (45, 62.5, 16, 16, 2)], self)
        with self.assertRaises(TmmError) as ctx:
            tools.assembly_from_tool(bit, "ER16 nut", 38.0, holders_file=None)
        self.assertIn("6mm Ball End", str(ctx.exception))
        self.assertIn("flute length 40", str(ctx.exception))

    def test_apt_bit_with_its_own_shank(self) -> None:
        # TMM's tmm_apt shape carries ShankDiameter and Length: a 90 deg V-bit D10 (cone 5 mm high) on an 8 mm shank
        bit = tools.make_apt_bit(new_doc(), Cutter.vbit(10, 90), length=40.0, shank_diameter=8.0)
        a = tools.assembly_from_tool(bit, "ER20 nut", 20.0, holders_file=None)
        self.assertAlmostEqual(a.flute_length, 5.0, places=9)
        close(a.bodies(), [(5, 20, 4, 4, 1), (20, 39, 17.5, 17.5, 1)], self)

    def test_neck_is_read_when_the_bit_has_one(self) -> None:
        # FreeCAD's thread-mill (NeckLength) and dovetail (NeckHeight) shapes carry a neck; a ball bit given one
        bit = tools.make_tool_bit(new_doc(), "ballend", 2.0)
        for prop, value in (("NeckDiameter", 1.9), ("NeckHeight", 10.0)):
            bit.addProperty("App::PropertyLength", prop, "Shape")
            setattr(bit, prop, value)
        bit.CuttingEdgeHeight = 3.0
        bit.ShankDiameter = 6.0
        a = tools.assembly_from_tool(bit, "HSK63A shrink 6x80", 30.0, shank_cone_deg=90, holders_file=None)
        close(a.bodies()[:2], [(3, 13, 0.95, 0.95, 1), (13, 30, 3, 3, 1)], self)
        self.assertEqual(a.holder.name, "HSK63A shrink 6x80")

    def test_user_holder_file(self) -> None:
        path = OUT / "TMM" / "holders.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"format": "tmm-holders 1", "holders": [
            {"name": "Spindle 80 ER11", "kind": "nut", "shank": [1, 7], "stack": [[11.5, 16, 16], [60, 80, 80]]}]}))
        bit = tools.make_tool_bit(new_doc(), "ballend", 3.0)
        a = tools.assembly_from_tool(bit, "spindle 80 er11", 42.0, holders_file=path)
        close(a.bodies()[1:], [(42, 53.5, 8, 8, 1), (53.5, 113.5, 40, 40, 1)], self)
        with self.assertRaises(TmmError) as ctx:
            tools.assembly_from_tool(bit, "Spindle 80 ER1", 42.0, holders_file=path)
        self.assertIn("'Spindle 80 ER11'", str(ctx.exception))
        default = tools.user_holders_file()
        self.assertEqual(default.parent.parent.resolve(), __import__("pathlib").Path(
            FreeCAD.getUserAppDataDir()).resolve())
        self.assertEqual(default.name, "holders.json")
