"""The Surface op's VerifyCusp (issue 14 item 4): off in a new op and in a document from before it (the path
unchanged); on, partial passes are added and the op's path, simulated again independently on finer cells, keeps
the cusp within CuspHeight; it saves and reopens; run_surface(verify_cusp=True) does the same."""
from __future__ import annotations

import unittest


from fc_helpers import FreeCADTestCase, bump_stl, close_all, core_work, job_with_op, moves, new_doc, reopened
from tmm_workbench.app.api import run_surface
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.surface.reference import cusp_field
from tmm_workbench.core.tools.cutter import Cutter

TOL = 0.01
# the planar step-over for 0.01 mm with a ball D4 (2 sqrt(2 R h)): the bump's slopes (to 34 deg) exceed it
VALUES = {"StepOver": 0.4, "SampleStep": 0.5, "CuspHeight": TOL, "BoundaryShape": "Model"}


_FIELDS: dict = {}


def simulated_max_cusp(op) -> float:
    """The op's tool path cut into a z-map of 0.03 mm cells (the verification used 0.05) against a dense raster.
    The field (the dense raster's envelope: most of the time) depends on the mesh and the boundary only, not on the
    path: made once for each, every path measured against it (CuspField.cut starts from a fresh stock)."""
    mesh = op.Proxy.mesh
    boundary = tuple(float(v) for v in op.Proxy.boundary(op, mesh))
    key = (mesh.vertices.tobytes(), mesh.triangles.tobytes(), boundary)
    if key not in _FIELDS:
        _FIELDS[key] = cusp_field(mesh, Cutter.ball(4.0), boundary, TOL, 0.03, sample_step=0.03)
    field = _FIELDS[key]
    return field.max_cusp(field.cut(op.Proxy.toolpath, Cutter.ball(4.0)))


class VerifyCusp(FreeCADTestCase):
    def test_verify_cusp_adds_passes_keeps_the_tolerance_and_reopens(self) -> None:
        doc = new_doc("TmmVerify")
        _, _, op = job_with_op(doc, str(bump_stl()), values=VALUES)
        self.assertIs(op.VerifyCusp, False)                       # a new op: as before
        plain = moves(op)
        before = simulated_max_cusp(op)
        self.assertGreater(before, TOL)
        op.VerifyCusp = True
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        checked = moves(op)
        self.assertLessEqual(simulated_max_cusp(op), TOL)
        plunges = lambda mv: sum(1 for (n0, _), (n1, _) in zip(mv, mv[1:]) if n0 == "G0" and n1 == "G1")  # noqa
        self.assertGreater(plunges(checked), plunges(plain))      # partial passes, lifts between them
        op = reopened(doc, op, "verify.FCStd")
        doc = op.Document
        self.assertIs(op.VerifyCusp, True)
        self.assertEqual(len(moves(op)), len(checked))
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertEqual(moves(op), checked)
        close_all()

    def test_a_document_from_before_verify_cusp_keeps_its_path(self) -> None:
        doc = new_doc("TmmOldVerify")
        _, _, op = job_with_op(doc, str(bump_stl()), values=VALUES)
        plain = moves(op)
        op.removeProperty("VerifyCusp")                           # as saved by an older TMM
        op = reopened(doc, op, "old_verify.FCStd")
        doc = op.Document
        self.assertIs(op.VerifyCusp, False)
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(moves(op), plain)
        close_all()

    # the API's keyword and the core's verification: the op's VerifyCusp through FreeCAD is the first test's
    @core_work
    def test_run_surface_verify_cusp(self) -> None:
        kw = dict(diameter=4.0, stepover=0.4, sample_step=0.5, cusp=TOL, progress=False)
        plain = run_surface(str(bump_stl()), doc_name="TmmApiPlain", diameter=4.0, stepover=0.4, sample_step=0.5,
                            progress=False)  # a cusp without the verification would be refused: it is not read
        checked = run_surface(str(bump_stl()), doc_name="TmmApiVerify", verify_cusp=True, **kw)
        self.assertIs(checked.op.VerifyCusp, True)
        self.assertGreater(len(checked.toolpath), len(plain.toolpath))
        self.assertGreater(simulated_max_cusp(plain.op), TOL)
        self.assertLessEqual(simulated_max_cusp(checked.op), TOL)
        with self.assertRaisesRegex(TmmError, "verify_cusp must be True or False, got 'yes'"):
            run_surface(str(bump_stl()), doc_name="TmmApiBad", verify_cusp="yes", **kw)
        close_all()

    @core_work
    def test_run_surface_verify_cusp_on_the_3d_offset(self) -> None:
        """The 3D offset's loops verified (their gaps read from the arrival field): the op computes, the path holds
        the cusp, the report is in the diagnostics."""
        r = run_surface(str(bump_stl()), doc_name="TmmApiVerify3D", diameter=4.0, sample_step=0.5, cusp=TOL,
                        stepover_mode="offset3d", verify_cusp=True, progress=False)
        self.assertEqual(r.op.StepOverMode, "Offset3D")
        self.assertIs(r.op.VerifyCusp, True)
        self.assertLessEqual(simulated_max_cusp(r.op), TOL)
        close_all()


if __name__ == "__main__":
    unittest.main()
