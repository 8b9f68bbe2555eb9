"""The 5-axis op's side step from a scallop (issue 14 item 5, issue 15 item 4) inside FreeCAD: a new op's
defaults (Scallop, FromToolBit), the op against the core's placement, save and reopen, a document saved
before the Scallop property (its Fixed spacing and RoundInsert shape kept, the path unchanged), the warning
for a fixed side step wider than the tool cuts, bad scallops refused by name."""
from __future__ import annotations

import unittest

import FreeCAD
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, close_all, core_work, seed_net
from tmm_workbench.app import op_multipoint
from tmm_workbench.app.api import run_multipoint
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies import multipoint
from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams
from tmm_workbench.core.tools.cutter import Cutter

QUICK = dict(forward_step=10.0, progress=False, posts=())



def commands(op) -> list[tuple[str, dict]]:
    return [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]


class ScallopOp(FreeCADTestCase):
    def test_scallop_op_matches_the_core_and_reopens(self) -> None:
        path = OUT / "multipoint_scallop.FCStd"
        r = run_multipoint(seed_net(), scallop=0.5, fcstd_path=path, doc_name="MpScallop", **QUICK)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(op.PassSpacing, "Scallop")
        self.assertAlmostEqual(op.Scallop.Value, 0.5)
        self.assertIn("largest scallop", op.ContactSummary)
        # the same passes as the core's placement with the op's parameters
        core = multipoint.compute(BezierFace.from_net(seed_net()), Cutter.torus(6.7, 6.0),
                                  MultipointParams(pass_spacing="scallop", scallop=0.5, forward_step=10.0))
        np.testing.assert_allclose(r.results["tip"], core.diagnostics["results"]["tip"], atol=1e-9)
        passes = int(core.diagnostics["results"].passes.max()) + 1
        self.assertIn(f"{passes} passes", op.ContactSummary)
        self.assertLessEqual(core.diagnostics["scallop"].max_scallop, 0.5)
        before, name = commands(op), op.Name
        close_all()
        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        self.assertEqual(op.PassSpacing, "Scallop")
        self.assertAlmostEqual(op.Scallop.Value, 0.5)
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(len(commands(op)), len(before))

    def test_document_saved_before_the_scallop_keeps_its_fixed_step(self) -> None:
        path = OUT / "multipoint_old.FCStd"
        r = run_multipoint(seed_net(), side_step=37.5, pass_spacing="fixed", fcstd_path=None, doc_name="MpOld",
                           **QUICK)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        before, name = commands(op), op.Name
        # what a document of the previous version holds: no Scallop, the two-choice enumerations
        op.removeProperty("Scallop")
        op.PassSpacing = ["Even", "Fixed"]
        op.PassSpacing = "Fixed"
        op.ToolShape = ["RoundInsert", "BullNose"]
        op.ToolShape = "RoundInsert"
        r.doc.saveAs(str(path))
        close_all()
        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        self.assertEqual(op.PassSpacing, "Fixed")
        self.assertEqual(op.ToolShape, "RoundInsert")
        self.assertIn("Scallop", op.getEnumerationsOfProperty("PassSpacing"))
        self.assertIn("FromToolBit", op.getEnumerationsOfProperty("ToolShape"))
        self.assertTrue(hasattr(op, "Scallop"))
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        got = commands(op)
        self.assertEqual([n for n, _ in got], [n for n, _ in before])
        for (_, a), (_, b) in zip(got, before):
            for k in a:
                self.assertAlmostEqual(a[k], b[k], delta=1e-5)

    def test_new_op_defaults_to_the_scallop_and_the_toolbit_shape(self) -> None:
        r = run_multipoint(seed_net(), side_step=75.0, pass_spacing="even", doc_name="MpNew", **QUICK)
        op = op_multipoint.Create("TMM_Multipoint", parentJob=r.job,
                                  values={"Base": [(r.face[0], (r.face[1],))], "ForwardStep": 10.0, "Scallop": 0.6})
        op.Proxy.progress_enabled = False
        r.doc.recompute()
        self.assertEqual(op.PassSpacing, "Scallop")
        self.assertEqual(op.ToolShape, "FromToolBit")
        self.assertEqual(op_multipoint.tool_shape(op.ToolShape, op.ToolController.Tool), "bull_nose")
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertIn("largest scallop", op.ContactSummary)
        # the simulation and the panel's checks read the tool as the op computes it
        self.assertEqual(op.Proxy.params_from(op).shape, "bull_nose")
        from tmm_workbench.app.api import simulate
        from tmm_workbench.app.work_estimate import estimate

        self.assertIsNotNone(estimate(op))
        sim = simulate(op, cell=2.0, progress=False)
        self.assertTrue(sim.simulation.result.five_axis)

    @core_work  # the op's warning from the core's placement, the same on every FreeCAD
    def test_fixed_step_wider_than_the_tool_is_warned(self) -> None:
        r = run_multipoint(seed_net(), Ro=2.0, Ri=1.0, side_step=18.0, pass_spacing="fixed", doc_name="MpWide",
                           **QUICK)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertIn("leaves uncut strips for this tool (cutting width 6 mm)", r.op.ContactSummary)

    def test_bad_scallop_is_refused_by_name(self) -> None:
        for bad in (0.0, -1.0):
            with self.assertRaises(TmmError) as ctx:
                run_multipoint(seed_net(), scallop=bad, doc_name="MpBad", **QUICK)
            self.assertIn("scallop", str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            run_multipoint(seed_net(), scallop=7.0, doc_name="MpBad2", **QUICK)
        self.assertIn("corner radius 6 mm", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()


class ScallopDefaultAndDegrade(FreeCADTestCase):
    def test_api_default_is_the_scallop_rule(self) -> None:
        """run_multipoint without pass_spacing places passes by the scallop, as a new op does (README)."""
        net = np.zeros((4, 4, 3))
        net[..., 0], net[..., 1] = np.meshgrid(np.linspace(0, 12, 4), np.linspace(0, 12, 4), indexing="ij")
        net[..., 2] = 50.0 + 0.02 * (net[..., 0] - 6.0) ** 2
        r = run_multipoint(net, Ro=2.0, Ri=1.0, doc_name="MpDefault", **QUICK)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertEqual(r.op.PassSpacing, "Scallop")
        self.assertIn("largest scallop", r.op.ContactSummary)
        self.assertIsNotNone(r.op.Proxy.placement)

    def test_areas_not_held_are_warnings_not_failures(self) -> None:
        """The op's status names where the scallop is not held; the report view lists the areas."""
        from tmm_workbench.core.strategies.multipoint_scallop import NOT_REACHED, LeftArea, ScallopPlacement
        area = LeftArea(0.0, 3.1, (126.0, 142.0), np.array([[0, 126], [3.1, 126], [3.1, 142], [0, 142]], float),
                        0.032, (1.55, 136.0), 4, NOT_REACHED)
        placement = ScallopPlacement(offsets=[0.0, 3.1], scallops=[0.0, 0.009], unreached=[area] * 12)
        params = MultipointParams(pass_spacing="scallop", scallop=0.01)
        lines = op_multipoint.spacing_warnings(params, Cutter.torus(6.7, 6.0), placement)
        self.assertTrue(any("not held on 12 areas" in w and "x 0..3.1, y 126..142" in w for w in lines), lines)
        detail = op_multipoint.area_lines(placement)
        self.assertEqual(len(detail), op_multipoint.MAX_AREAS_LISTED + 1)
        self.assertIn("does not reach the face", detail[0])
