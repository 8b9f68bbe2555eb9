"""The whole tool in the 3-axis Surface op (app.tool_assembly, core.strategies.holder_guard): a ball D4 on a 20 mm
stick-out in an ER32 collet chuck finishing a 40 mm deep cavity, through run_surface and the op's properties. The
op keeps the shank and holder their clearance from the model (checked along every move by
core.verify.holder_clearance), says in HolderReport what it left and the stick-out that would cut it; with the
holder ignored the same path drives the holder into the part; bad values are refused by name; documents save
and reopen with it, and older ones restore without a holder."""
from __future__ import annotations

import FreeCAD

from fc_helpers import OUT, FreeCADTestCase, core_work, reopened, write_ascii_stl
from tests.core.cavity import cavity_mesh
from tmm_workbench.app import tool_assembly
from tmm_workbench.app.api import run_surface
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

HOLDER = "SK40 ER32x70"
FAST = dict(tool="ballend", diameter=4.0, stepover=4.0, sample_step=0.5, boundary="model", margin=-5.0,
            progress=False)


def cavity_stl() -> str:
    mesh = cavity_mesh()
    tris = [tuple(tuple(map(float, mesh.vertices[i])) for i in f) for f in mesh.triangles]
    return str(write_ascii_stl(OUT / "cavity.stl", tris, "cavity"))


class HolderInTheSurface(FreeCADTestCase):
    def test_the_op_keeps_the_holder_clear_and_says_what_it_left(self) -> None:
        r = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmHolder", **FAST)
        assembly = tool_assembly.assembly_of(r.op)
        self.assertEqual(assembly.stick_out, 20.0)
        check = check_holder_clearance(r.mesh, assembly, r.toolpath, sample_step=0.25, tolerance=0.05)
        self.assertTrue(check.ok, check.summary())
        self.assertIn("points raised where the shank or holder would come closer", r.op.HolderReport)
        self.assertIn("stick-out", r.op.HolderReport)
        self.assertEqual(r.op.getEditorMode("HolderReport"), ["ReadOnly"])
        ignored = run_surface(cavity_stl(), doc_name="TmmNoHolder", **FAST)   # the same job, the holder ignored
        self.assertFalse(check_holder_clearance(ignored.mesh, assembly, ignored.toolpath).ok)
        left = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, holder_collision="leave_out",
                           doc_name="TmmLeaveOut", **FAST)
        self.assertEqual(left.op.HolderCollision, "LeaveOut")
        self.assertTrue(check_holder_clearance(left.mesh, assembly, left.toolpath, sample_step=0.25,
                                               tolerance=0.05).ok)
        self.assertIn("points left out", left.op.HolderReport)

    # the core's holder check on the simulated Job (the same Jobs simulated with a holder: fc_test_sim_holder)
    @core_work
    def test_the_simulation_shows_the_holder_hitting_a_job_computed_without_it(self) -> None:
        from tmm_workbench.app.api import simulate

        ignored = run_surface(cavity_stl(), doc_name="TmmSimNoHolder", **FAST)
        report = simulate(ignored, cell=0.5, progress=False, holder=HOLDER, stick_out=20.0)
        ((label, check),) = report.holder_collisions
        self.assertEqual(label, ignored.op.Label)
        self.assertGreater(check.per_piece.get("holder", 0), 0)
        self.assertLess(float(check.tip[:, 2].min()), -20.0)   # down in the cavity
        with self.assertRaises(TmmError) as ctx:
            simulate(ignored, cell=0.5, progress=False, holder=HOLDER, stick_out=20.0, fail_on_gouge=True)
        self.assertIn("holder", str(ctx.exception))
        safe = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmSimHolder", **FAST)
        report = simulate(safe, cell=0.5, progress=False)
        self.assertEqual(report.holder_collisions, [])
        self.assertTrue(report.simulation.ops[0].holder.ok)   # checked with the op's own holder
        with self.assertRaises(TmmError) as ctx:
            simulate(safe, progress=False, stick_out=20.0)
        self.assertIn("stick_out is used with a holder only", str(ctx.exception))

    def test_waterline_keeps_the_holder_clear(self) -> None:
        from tmm_workbench.app.api import run_waterline

        common = dict(tool="ballend", diameter=4.0, step_down=8.0, progress=False)
        r = run_waterline(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmWlHolder", **common)
        assembly = tool_assembly.assembly_of(r.op)
        check = check_holder_clearance(r.mesh, assembly, r.toolpath, sample_step=0.25, tolerance=0.05)
        self.assertTrue(check.ok, check.summary())
        self.assertIn("points raised", r.op.HolderReport)
        ignored = run_waterline(cavity_stl(), doc_name="TmmWlNoHolder", **common)
        self.assertFalse(check_holder_clearance(ignored.mesh, assembly, ignored.toolpath).ok)
        with self.assertRaises(TmmError) as ctx:
            run_waterline(cavity_stl(), stick_out=20.0, doc_name="TmmWlBad", **common)
        self.assertIn("stick_out is used with a holder only", str(ctx.exception))

    def test_roughing_keeps_the_holder_clear_either_way(self) -> None:
        from tmm_workbench.app.api import run_roughing

        common = dict(tool="endmill", diameter=6.0, step_down=10.0, stepover_percent=45.0, stock_to_leave=0.5,
                      progress=False)
        for mode in ("lift", "leave_out"):
            with self.subTest(mode=mode):
                r = run_roughing(cavity_stl(), holder="ER32 nut", stick_out=25.0, holder_collision=mode,
                                 doc_name=f"TmmRoughHolder_{mode}", **common)
                check = check_holder_clearance(r.mesh, tool_assembly.assembly_of(r.op), r.toolpath,
                                               sample_step=0.25, tolerance=0.05)
                self.assertTrue(check.ok, check.summary())
                self.assertIn("points raised" if mode == "lift" else "points left out", r.op.HolderReport)

    def test_the_shortest_stick_out_per_op_of_a_job(self) -> None:
        from tmm_workbench.app.api import minimum_stick_out, run_waterline

        ignored = run_surface(cavity_stl(), doc_name="TmmStickOut", **FAST)
        run_waterline(job=ignored.job, tool="ballend", diameter=4.0, step_down=8.0, progress=False)
        told = minimum_stick_out(ignored.job, holder=HOLDER)
        self.assertEqual(len(told), 2)
        for label, stick_out in told.items():
            with self.subTest(op=label):
                self.assertGreater(stick_out.stick_out, 30.0)   # a 40 mm deep pocket under a D50 collet nut
        surface_needs = told[ignored.op.Label].stick_out
        longer = run_surface(cavity_stl(), holder=HOLDER, stick_out=surface_needs + 0.01, doc_name="TmmStickLong",
                             **FAST)
        self.assertNotIn("holder", longer.op.HolderReport.split("(")[1].split(";")[0])  # only the shank lifts
        with self.assertRaises(TmmError) as ctx:
            minimum_stick_out(ignored.job)   # no op has a holder
        self.assertIn("no 3-axis op with a holder", str(ctx.exception))

    def test_it_saves_and_reopens_and_an_older_document_has_no_holder(self) -> None:
        r = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmHolderSave", **FAST)
        before = [(c.Name, dict(c.Parameters)) for c in r.op.Path.Commands]
        op = reopened(r.doc, r.op, "holder.FCStd")
        self.assertEqual((op.Holder, op.StickOut.Value), (HOLDER, 20.0))
        op.Proxy.progress_enabled = False
        op.touch()
        op.Document.recompute()
        self.assertEqual([(c.Name, dict(c.Parameters)) for c in op.Path.Commands], before)
        for name in ("Holder", "StickOut", "ShankClearance", "HolderClearance", "HolderCollision"):
            op.removeProperty(name)
        op = reopened(op.Document, op, "holder_old.FCStd")
        self.assertEqual(op.Holder, "None")   # as computed before the holder existed

    def test_bad_values_are_refused_by_name(self) -> None:
        cases = [(dict(holder="ER99 collet"), "holder must be one of none, er11 nut"),
                 (dict(stick_out=30.0), "stick_out is used with a holder only"),
                 (dict(holder=HOLDER, stick_out=-1.0), "stick_out must be in [0, 1000] mm, got -1"),
                 (dict(holder=HOLDER, holder_clearance=-0.5), "holder_clearance must be in [0, 100] mm, got -0.5"),
                 (dict(holder=HOLDER, holder_collision="dodge"), "holder_collision must be 'lift' or 'leave_out'")]
        before = set(FreeCAD.listDocuments())
        for kwargs, said in cases:
            with self.subTest(kwargs=kwargs), self.assertRaises(TmmError) as ctx:
                run_surface(cavity_stl(), doc_name="TmmHolderBad", **{**FAST, **kwargs})
            self.assertIn(said, str(ctx.exception))
        self.assertEqual(set(FreeCAD.listDocuments()), before)
        with self.assertRaises(TmmError) as ctx:   # shorter than the flutes: the op fails and says why
            run_surface(cavity_stl(), holder=HOLDER, stick_out=8.0, doc_name="TmmHolderShort", **FAST)
        self.assertIn("stick-out", str(ctx.exception))
