"""The whole tool in the 5-axis Multipoint op (app.tool_assembly, core.strategies.multipoint_holder): a D10 R3
bull-nose in an ER32 collet nut on a short stick-out finishing a floor beside an 80 mm wall (a B-spline face of
two Bézier patches), through run_multipoint and the op's properties. The op tilts the tool away where the holder
would come closer than its clearance, leaves out what no tilt clears and says so in HolderReport; the finished
path is checked by core.verify.holder_clearance against the face; without a holder the op computes what it did
before; bad values are refused by name; documents save and reopen with it."""
from __future__ import annotations

import numpy as np

import FreeCAD
import Part

from fc_helpers import FreeCADTestCase, reopened
from tmm_workbench.app import tool_assembly
from tmm_workbench.app.api import run_multipoint
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

HOLDER = "ER32 nut"
WALL = 80.0
FAST = dict(Ro=2.0, Ri=3.0, tool_shape="bull_nose", side_step=15.0, forward_step=5.0, pass_spacing="even",
            feed_angle_deg=0.0, progress=False, posts=())


def wall_poles() -> np.ndarray:
    """A flat floor (x 0..50) into a fillet and a vertical wall at x = 60: 7 x 4 poles, two cubic spans in u."""
    xs, zs = [0, 20, 40, 50, 60, 60, 60], [0, 0, 0, 0, 0, WALL / 2, WALL]
    ys = np.linspace(0.0, 60.0, 4)
    X, Y = np.meshgrid(np.asarray(xs, float), ys, indexing="ij")
    return np.stack([X, Y, np.repeat(np.asarray(zs, float)[:, None], 4, 1)], -1)


def wall_surface() -> Part.BSplineSurface:
    poles = wall_poles()
    s = Part.BSplineSurface()
    s.buildFromPolesMultsKnots([[FreeCAD.Vector(*map(float, p)) for p in row] for row in poles],
                               [4, 3, 4], [4, 4], [0.0, 1.0, 2.0], [0.0, 1.0], False, False, 3, 3)
    return s


def face_mesh():
    poles = wall_poles()
    face = BezierFace([poles[:4], poles[3:]], 2, 1)
    from tmm_workbench.core.strategies.multipoint_holder import face_mesh as mesh_of
    return mesh_of(face, 0.5)[0]


class HolderInTheMultipoint(FreeCADTestCase):
    def test_the_op_tilts_away_and_says_what_it_left(self) -> None:
        r = run_multipoint(wall_surface(), holder=HOLDER, stick_out=32.0, tilt_limit_deg=45.0, doc_name="TmmMpHolder",
                           **FAST)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertEqual((op.Holder, op.HolderCollision, op.StickOut.Value), (HOLDER, "Tilt", 32.0))
        assembly = tool_assembly.assembly_of(op)
        self.assertEqual(assembly.holder.name, HOLDER)
        self.assertIn("tilted away", op.HolderReport)
        self.assertEqual(op.getEditorMode("HolderReport"), ["ReadOnly"])
        check = check_holder_clearance(face_mesh(), assembly, r.toolpath, sample_step=0.25, surface_step=0.2,
                                       tolerance=0.05)
        self.assertTrue(check.ok, check.summary())
        # the same op without its holder drives the holder into the wall
        bare = run_multipoint(wall_surface(), tilt_limit_deg=45.0, doc_name="TmmMpBare", **FAST)
        self.assertEqual(bare.op.HolderReport, "")
        self.assertEqual(tool_assembly.holder_of(bare.op)[0], "None")   # (FromToolController: none set)
        self.assertFalse(check_holder_clearance(face_mesh(), assembly, bare.toolpath, surface_step=0.2).ok)
        # leave out: nothing tilted, the places left out are reported, the path clear
        left = run_multipoint(wall_surface(), holder=HOLDER, stick_out=32.0, tilt_limit_deg=45.0,
                              holder_collision="leave_out", doc_name="TmmMpLeave", **FAST)
        self.assertEqual(left.op.HolderCollision, "LeaveOut")
        self.assertIn("unreachable (left out)", left.op.HolderReport)
        self.assertNotIn("tilted away", left.op.HolderReport)
        self.assertTrue(check_holder_clearance(face_mesh(), assembly, left.toolpath, sample_step=0.25,
                                               surface_step=0.2, tolerance=0.05).ok)
        # saved and reopened, the op keeps its holder and computes the same path
        again = reopened(r.doc, op, "mp_holder.FCStd")
        self.assertEqual((again.Holder, again.HolderCollision), (HOLDER, "Tilt"))
        gcode = again.Path.toGCode()
        again.Document.recompute()
        self.assertTrue(again.isValid(), again.getStatusString())
        self.assertEqual(again.Path.toGCode(), gcode)

    def test_bad_values_are_refused_by_name(self) -> None:
        with self.assertRaisesRegex(TmmError, r"holder_collision must be 'tilt' or 'leave_out', got 'lift'"):
            run_multipoint(wall_surface(), holder=HOLDER, holder_collision="lift", doc_name="TmmMpBad", **FAST)
        with self.assertRaisesRegex(TmmError, "stick_out is used with a holder only"):
            run_multipoint(wall_surface(), stick_out=32.0, doc_name="TmmMpBad2", **FAST)
        with self.assertRaisesRegex(TmmError, "shank_clearance"):
            run_multipoint(wall_surface(), holder=HOLDER, shank_clearance=-1.0, doc_name="TmmMpBad3", **FAST)

    def test_the_bezier_net_is_the_face(self) -> None:
        """The test's two patches are the B-spline's spans (so the mesh checked is the face machined)."""
        s = wall_surface()
        face = BezierFace([wall_poles()[:4], wall_poles()[3:]], 2, 1)
        uv = np.array([[0.3, 0.4], [1.5, 0.2], [1.9, 0.9]])
        ours = face.evaluate(uv)["S"]
        theirs = np.array([tuple(s.value(float(u), float(v))) for u, v in uv])
        self.assertLess(float(np.abs(ours - theirs).max()), 1e-9)
