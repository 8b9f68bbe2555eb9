"""Lean passes in FreeCAD (issue 14 item 2): the Surface op's ForwardStep "Tolerance" (the default of new ops and
run_surface since the fit is in the kernel; lines and arcs from the kernel) writes fewer
G-code lines than "SampleStep" and posts with linuxcnc; ArcFitting writes G18/G19 + G2/G3 with K that the
grbl post passes and TMM's simulation reads (no gouge beyond the tolerance against the model); with the
linuxcnc post (no K) the op writes lines; documents from before keep their sampled passes."""
from __future__ import annotations

import re
import unittest


from fc_helpers import SPHERE_ON_PLATE, FreeCADTestCase, close_all, job_with_op, new_doc, reopened
from tmm_workbench.app.api import run_surface, simulate

SETTINGS = dict(tool="ballend", diameter=6.0, stepover=2.0, sample_step=0.25, margin=-20.0, progress=False)


def motion_lines(gcode: str) -> list[str]:
    return [ln for ln in gcode.splitlines() if re.match(r"^(N\d+\s+)?G[0123]\b", ln.strip())]


class LeanPasses(FreeCADTestCase):
    def test_fewer_lines_with_linuxcnc(self) -> None:
        before = run_surface(str(SPHERE_ON_PLATE), forward_step="sample", doc_name="LeanBefore", **SETTINGS)
        after = run_surface(str(SPHERE_ON_PLATE), forward_step="tolerance", doc_name="LeanAfter", **SETTINGS)
        self.assertEqual(after.op.ForwardStep, "Tolerance")
        self.assertEqual(before.op.ForwardStep, "SampleStep")
        n0, n1 = len(motion_lines(before.gcode)), len(motion_lines(after.gcode))
        self.assertLess(n1, 0.8 * n0, (n0, n1))
        self.assertNotRegex(after.gcode, r"\bG[23]\b")
        close_all()

    def test_arcs_with_grbl_and_simulated(self) -> None:
        r = run_surface(str(SPHERE_ON_PLATE), forward_step="tolerance", arcs=True, post="grbl", doc_name="LeanArcs",
                        **SETTINGS)
        names = [c.Name for c in r.op.Path.Commands]
        self.assertIn("G18", names)               # passes along X: arcs in XZ
        arcs = [c for c in r.op.Path.Commands if c.Name in ("G2", "G3")]
        self.assertEqual(len(arcs), len(r.toolpath.arcs))
        self.assertGreater(len(arcs), 10)
        self.assertTrue(all("K" in c.Parameters for c in arcs))
        last_arc = max(i for i, n in enumerate(names) if n in ("G2", "G3"))
        self.assertIn("G17", names[last_arc:])    # the XY plane back after the arcs
        arc_lines = [ln for ln in r.gcode.splitlines() if re.match(r"^G[23]\s", ln.strip())]
        self.assertEqual(len(arc_lines), len(arcs))
        self.assertTrue(all(" K" in ln for ln in arc_lines), arc_lines[:3])
        self.assertRegex(r.gcode, r"(?m)^G18\b")
        s = simulate(r, cell=0.1, tolerance=0.002, progress=False)
        self.assertGreaterEqual(s.min_deviation, -0.002, s.min_deviation)  # the band (0.001) + the z-map's cells
        self.assertFalse(s.gouged)
        close_all()

    def test_linuxcnc_drops_k_so_lines(self) -> None:
        r = run_surface(str(SPHERE_ON_PLATE), forward_step="tolerance", arcs=True, post="linuxcnc",
                        doc_name="LeanNoK", **SETTINGS)
        self.assertTrue(r.op.ArcFitting)
        self.assertFalse([c for c in r.op.Path.Commands if c.Name in ("G2", "G3", "G18", "G19")])
        self.assertNotRegex(r.gcode, r"\bG[23]\b")
        close_all()

    def test_new_ops_default_to_tolerance(self) -> None:
        r = run_surface(str(SPHERE_ON_PLATE), doc_name="LeanDefault", **SETTINGS)
        self.assertEqual(r.op.ForwardStep, "Tolerance")
        self.assertFalse(r.toolpath.arcs)
        doc = new_doc("TmmLeanNew")
        _, _, op = job_with_op(doc, str(SPHERE_ON_PLATE), diameter=6.0, values={"SampleStep": 0.25, "StepOver": 4.0})
        self.assertEqual(op.ForwardStep, "Tolerance")
        close_all()

    def test_old_document_keeps_sampled_passes(self) -> None:
        doc = new_doc("TmmLeanOld")
        _, _, op = job_with_op(doc, str(SPHERE_ON_PLATE), diameter=6.0, values={"SampleStep": 0.25, "StepOver": 4.0,
                                                                                       "ForwardStep": "Tolerance"})
        self.assertEqual(op.ForwardStep, "Tolerance")
        lean = len(op.Path.Commands)
        op.removeProperty("ForwardStep")            # as saved by an older TMM
        op.removeProperty("ArcFitting")
        op = reopened(doc, op, "old_forward_step.FCStd")
        doc = op.Document
        self.assertEqual(op.ForwardStep, "SampleStep")
        self.assertFalse(op.ArcFitting)
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertGreater(len(op.Path.Commands), lean)
        close_all()


if __name__ == "__main__":
    unittest.main()
