"""The holder chosen on the tool controller (app.tool_assembly: TmmHolder, TmmStickOut; api.set_holder) and the
places the holder left drawn from the op (HolderRegions): a ball D4 in an ER32 collet chuck over the 40 mm deep
cavity of tests/core/cavity.py. A new op follows its tool controller's holder (FromToolController); an op's own
holder wins over it; the tool controller's holder saves and reopens; the shortest stick-out is told for it."""
from __future__ import annotations

import FreeCAD

from fc_helpers import FreeCADTestCase, reopened
from fc_test_holder import FAST, HOLDER, cavity_stl
from tmm_workbench.app import tool_assembly
from tmm_workbench.app.api import minimum_stick_out, run_surface, set_holder
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance


def recompute(op) -> None:
    op.Proxy.progress_enabled = False
    op.touch()
    op.Document.recompute()


class HolderOnTheToolController(FreeCADTestCase):
    def test_a_new_op_follows_its_tool_controllers_holder(self) -> None:
        r = run_surface(cavity_stl(), doc_name="TmmTcHolder", **FAST)
        self.assertEqual(r.op.Holder, tool_assembly.FROM_TC)   # the default of a new op
        self.assertEqual(list(r.op.HolderRegions), [])         # the tool controller has no holder yet
        plain = [(c.Name, dict(c.Parameters)) for c in r.op.Path.Commands]
        set_holder(r, HOLDER, 20.0)
        tc = r.op.ToolController
        self.assertEqual((tc.TmmHolder, tc.TmmStickOut.Value), (HOLDER, 20.0))
        recompute(r.op)
        self.assertIn("points raised", r.op.HolderReport)
        regions = list(r.op.HolderRegions)
        self.assertGreater(len(regions), 10)
        self.assertTrue(all(-35.0 <= p.x <= 35.0 for p in regions), f"a region outside the pocket: {min(p.x for p in regions)}..{max(p.x for p in regions)}, {r.op.HolderReport}")
        check = check_holder_clearance(r.op.Proxy.mesh, tool_assembly.assembly_of(r.op), r.op.Proxy.toolpath,
                                       sample_step=0.5, tolerance=0.05)
        self.assertTrue(check.ok, check.summary())
        self.assertNotEqual([(c.Name, dict(c.Parameters)) for c in r.op.Path.Commands], plain)
        told = minimum_stick_out(r.job)   # the tool controller's holder is the op's
        self.assertGreater(told[r.op.Label].stick_out, 30.0)

        r.op.Holder = "None"   # the op's own choice wins
        recompute(r.op)
        self.assertEqual(([(c.Name, dict(c.Parameters)) for c in r.op.Path.Commands], list(r.op.HolderRegions)),
                         (plain, []))

    def test_the_tool_controllers_holder_saves_and_reopens(self) -> None:
        r = run_surface(cavity_stl(), doc_name="TmmTcHolderSave", **FAST)
        set_holder(r, HOLDER, 22.5)
        recompute(r.op)
        regions = len(r.op.HolderRegions)
        op = reopened(r.doc, r.op, "holder_tc.FCStd")
        tc = op.ToolController
        self.assertEqual((tc.TmmHolder, tc.TmmStickOut.Value, len(op.HolderRegions)), (HOLDER, 22.5, regions))
        self.assertEqual(tool_assembly.holder_of(op), (HOLDER, 22.5))

    def test_bad_values_are_refused_by_name(self) -> None:
        r = run_surface(cavity_stl(), doc_name="TmmTcHolderBad", **FAST)
        with self.assertRaises(TmmError) as ctx:
            set_holder(r, "ER99 collet")
        self.assertIn("holder must be one of None, ER11", str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            set_holder(r, HOLDER, -3.0)
        self.assertIn("stick_out must be in [0, 1000] mm, got -3", str(ctx.exception))
        self.assertEqual(r.op.ToolController.TmmHolder, "None")   # nothing half set
        FreeCAD.closeDocument(r.doc.Name)
