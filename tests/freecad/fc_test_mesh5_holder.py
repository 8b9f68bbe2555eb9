"""The whole tool in the 'TMM 5-axis Mesh' op (app.tool_assembly, core.strategies.mesh5.holder): a flat D 10
ToolBit in an ER16 nut at a 32 mm stick-out finishing a floor that ends at a 60 mm wall, through run_mesh5. The
shank and holder bound the op's C-space: the tool tilts away from the wall (HolderReport, HolderRegions), what no
posture reaches is marked for clean-up (CleanupRegions, Mesh5Summary); the Job's simulation checks the shank
and holder at every move, against the design and the stock, and finds them clear, with no gouge; the same op
without its holder drives the nut into the wall (found by the same check); a ball clean-up op after it takes most
of what it left beside the wall."""
from __future__ import annotations

import FreeCAD
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, write_ascii_stl
from tmm_workbench.app import work_estimate
from tmm_workbench.app.api import run_mesh5, simulate

HOLDER, STICK_OUT, WALL_Y, WALL_TOP = "ER16 nut", 32.0, 12.0, 60.0
ARGS = dict(diameter=10.0, tolerance=0.3, tilt_limit_deg=30.0, yaw_limit_deg=90.0, grid_step_deg=6.0,
            forward_step=5.0, stock=(-6.0, -7.0, -1.0, 6.0, WALL_Y, 1.0), progress=False)


def floor_and_wall_stl() -> str:
    """A floor z = 0 (x -5..5, y -6..12, 2.5 x 1.8 mm cells) and a vertical wall beyond its y = 12 edge, a little
    wider so that the STL's vertices stay apart (welded, the floor's edge would take the wall's normals)."""
    xs, ys = np.linspace(-5.0, 5.0, 5), np.linspace(-6.0, WALL_Y, 11)
    tris = []
    for x0, x1 in zip(xs, xs[1:]):
        for y0, y1 in zip(ys, ys[1:]):
            a, b, c, d = (x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)
            tris += [(a, b, c), (a, c, d)]
    w = [(-5.5, WALL_Y, 0.0), (5.5, WALL_Y, 0.0), (5.5, WALL_Y, WALL_TOP), (-5.5, WALL_Y, WALL_TOP)]
    tris += [(w[0], w[1], w[2]), (w[0], w[2], w[3])]
    return str(write_ascii_stl(OUT / "mesh5_wall.stl", tris, "floor_and_wall"))


class HolderInTheMesh5Op(FreeCADTestCase):
    # One run_mesh5 (the 5-axis op with its ball clean-up after it, posted) for both halves: the op's C-space
    # computed once (most of the time); the op alone and the Job (both ops) simulated once each.
    def test_the_op_tilts_away_its_holder_never_hits_and_a_ball_cleans_up_what_it_left(self) -> None:
        gcode = OUT / "mesh5_cleanup.tarus.ngc"
        r = run_mesh5(floor_and_wall_stl(), holder=HOLDER, stick_out=STICK_OUT, doc_name="TmmMesh5Holder",
                      cleanup_diameter=4.0, gcode_path=gcode, **ARGS)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual((op.Holder, op.StickOut.Value), (HOLDER, STICK_OUT))
        self.assertFalse(hasattr(op, "HolderCollision"))   # the C-space decides: tilt away or leave for clean-up
        self.assertIn("tool tilts away", op.HolderReport)
        self.assertGreater(len(op.HolderRegions), 0)
        self.assertIn("marked for clean-up", op.Mesh5Summary)
        marks = np.array([(p.x, p.y, p.z) for p in op.CleanupRegions])
        self.assertGreater(len(marks), 0)
        self.assertGreater(marks[:, 1].max(), WALL_Y - 5.0)   # beside the wall, where no posture finishes
        self.assertEqual(op.getEditorMode("CleanupRegions"), ["ReadOnly"])
        tilt_away = min(a[1] for s in op.Proxy.segments for a in s.axes)
        self.assertLess(tilt_away, -np.sin(np.radians(10.0)))
        # the ball clean-up op after it, reading it
        c = r.cleanup
        self.assertTrue(c.isValid(), c.getStatusString())
        self.assertEqual((c.Region, c.RestFrom), ("Rest", "EarlierOps"))
        self.assertAlmostEqual(c.RestTolerance.Value, ARGS["tolerance"])
        self.assertIn("rest", c.RestReport)
        ops = r.job.Operations.Group
        self.assertLess(ops.index(r.op), ops.index(c))               # after the 5-axis op, which it reads
        self.assertEqual(c.ToolController.Tool.Diameter.Value, 4.0)
        self.assertTrue(gcode.is_file())
        self.assertEqual(r.gcode.count("M6"), 2)                      # both ops, a tool change before each
        # the Job's simulation: the shank and holder along every move, against the design
        report = simulate(r.job, cell=0.25, tolerance=0.01, progress=False)
        self.assertEqual(report.holder_collisions, [])   # along every move, against the design
        self.assertEqual(report.stock_collisions, [])    # and against the stock as the cut leaves it
        self.assertEqual(report.collisions, [])
        self.assertGreaterEqual(report.min_deviation, -0.01)
        # the material the 5-axis op left beside the wall (simulated on the Job's stock) is taken by the ball
        alone = simulate(r.op, cell=0.25, tolerance=0.01, progress=False)
        self.assertGreater(alone.remaining_volume, 30.0)
        self.assertLess(report.remaining_volume, 0.3 * alone.remaining_volume)
        held = work_estimate.estimate(op)   # the estimate counts the holder's dearer C-spaces
        self.assertIn("shank and holder", held.note)
        # the same op without the holder: the path brings the nut into the wall
        op.Holder = "None"
        r.doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual(op.HolderReport, "")
        bare_estimate = work_estimate.estimate(op)
        self.assertNotIn("shank and holder", bare_estimate.note)
        self.assertLess(bare_estimate.compute_seconds, held.compute_seconds)
        self.assertLess(abs(min(a[1] for s in op.Proxy.segments for a in s.axes)), 1e-9)   # upright throughout
        bare = simulate(r.op, cell=0.25, tolerance=0.01, progress=False, holder=HOLDER, stick_out=STICK_OUT)
        self.assertTrue(bare.holder_collisions, "the bare path should drive the holder into the wall")
        FreeCAD.closeDocument(r.doc.Name)
