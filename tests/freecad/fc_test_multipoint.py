"""The 'TMM 5-axis Multipoint' op (seed 001) inside a Path Job: the seed's convex patch as a Bézier face and
as a B-spline face, tip + axis words against the core, placement, save/reopen, the tarus and apt_cl posts,
bad faces and tools, cancel. Coarse footprint (side step 18 mm, forward step 4 mm) to keep it quick."""
from __future__ import annotations

import math
import re
import unittest

import FreeCAD
import Part
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, close_all, core_work, new_doc, seed_net
from tmm_workbench.app.api import run_multipoint
from tmm_workbench.app import tools
from tmm_workbench.app.compat import load_post
from tmm_workbench.app.op_multipoint import ObjectTmmMultipoint
from tmm_workbench.core import path5
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.multipoint import STATUS_TWO
from tmm_workbench.core.shared_data import benchmark_file

SEED = benchmark_file("seed_surfaces.json")
# even spacing: these cases test positioning, posts and documents, not the scallop rule (the API's default)
FAST = dict(side_step=18.0, forward_step=4.0, progress=False, pass_spacing="even")
DRD = dict(side_step=37.5, forward_step=10.0, progress=False, method="drd", pass_spacing="even")  # DRD is ~20x slower than VCRF
_DRD_TIPS: list = []


def drd_bezier_tips() -> np.ndarray:
    """The G1 tips of DRD (the footprint's positions only, gouge_tolerance 0) on the seed's Bézier face, computed
    once for the two tests that compare a path with it (its own document, closed: a read-only array)."""
    if not _DRD_TIPS:
        r = run_multipoint(seed_net(), doc_name="MpBez", **DRD, gouge_tolerance=0.0)
        _DRD_TIPS.append(g1_tips(r.op))
        FreeCAD.closeDocument(r.doc.Name)
    return _DRD_TIPS[0]



def bezier_surface(net: np.ndarray) -> Part.BezierSurface:
    s = Part.BezierSurface()
    s.increase(net.shape[0] - 1, net.shape[1] - 1)
    for i in range(net.shape[0]):
        for j in range(net.shape[1]):
            s.setPole(i + 1, j + 1, FreeCAD.Vector(*map(float, net[i, j])))
    return s


def commands(op) -> list[tuple[str, dict]]:
    return [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]


def g1_tips(op) -> np.ndarray:
    return np.array([m.tip for m in path5.decode_commands(commands(op)) if m.name == "G1"]).reshape(-1, 3)


class MultipointOp(FreeCADTestCase):
    def test_bezier_face_path_and_posts(self) -> None:
        r = run_multipoint(seed_net(), out_dir=OUT, name="mp_bezier", **FAST)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertIsInstance(op.Proxy, ObjectTmmMultipoint)
        self.assertIn(op, r.job.Operations.Group)
        self.assertEqual(op.Base[0][1], ("Face1",))
        self.assertIs(op.Base[0][0], r.job.Model.Group[0])  # the Job's model clone, as FreeCAD's face ops
        counts = r.results.counts()
        self.assertGreater(counts["two"], 0)
        self.assertEqual(sum(counts.values()), len(r.results))
        self.assertIn(f"{counts['two']} two-contact", op.ContactSummary)

        cmds = commands(op)
        motion = [(n, p) for n, p in cmds if path5.is_motion(n)]
        # U V W on every motion command but ObjectOp's closing "G0 Z<clearance>" (modal: vertical by then)
        for n, p in motion[:-1]:
            self.assertTrue(all(w in p for w in "UVW"), (n, p))
            self.assertAlmostEqual(math.sqrt(p["U"] ** 2 + p["V"] ** 2 + p["W"] ** 2), 1.0, places=12)
        decoded = path5.decode_commands(cmds)
        self.assertEqual(decoded[0].axis, (0.0, 0.0, 1.0))   # starts upright at the clearance height
        self.assertEqual(decoded[-1].axis, (0.0, 0.0, 1.0))  # and ends upright
        self.assertAlmostEqual(decoded[0].tip[2], op.ClearanceHeight.Value, places=9)

        # the cut moves are the strategy's cut segments, tip and axis, within 1e-6 (linked once)
        cut_tips = np.vstack([s.tips for s in r.segments])
        cut_axes = np.vstack([s.axes for s in r.segments])
        # G1: the cut moves, and the approaches and exits along the axis below the safe height (fed)
        on_face = {tuple(np.round(t, 6)) for t in cut_tips}
        cut_path = [m for m in decoded if m.name == "G1" and tuple(np.round(m.tip, 6)) in on_face]
        self.assertEqual(len(cut_path), len(cut_tips))
        approach = [m for m in decoded if m.name == "G1" and tuple(np.round(m.tip, 6)) not in on_face]
        self.assertEqual(len(approach), 2 * len(r.segments) - 2 * sum(bool(s.joined) for s in r.segments))
        np.testing.assert_allclose([m.tip for m in cut_path], cut_tips, atol=1e-6)
        np.testing.assert_allclose([m.axis for m in cut_path], cut_axes, atol=1e-9)
        # tilted where the core reports two contacts
        two = r.results.status == STATUS_TWO
        tips = r.results["tip"][two]
        for tip, axis in zip(tips, r.results["axis"][two]):
            k = int(np.argmin(np.linalg.norm(np.array([m.tip for m in cut_path]) - tip, axis=1)))
            self.assertLess(np.linalg.norm(np.array(cut_path[k].tip) - tip), 1e-6)
            self.assertLess(cut_path[k].axis[2], 1 - 1e-6)
            np.testing.assert_allclose(cut_path[k].axis, axis, atol=1e-9)
        # feeds: plunge at the vertical, cutting at the horizontal feed (mm/s); rapids carry no F
        self.assertEqual({round(m.params["F"] * 60, 6) for m in cut_path if "F" in m.params}, {1000.0, 300.0})
        self.assertTrue(all("F" not in p for n, p in motion if n == "G0"))
        # in and out along the tool axis, fed (G1) below the safe height: each exit leaves a cut along its
        # last axis, each entry reaches the face along its first, AxisRetract long; rapids only above
        def faced(m) -> bool:
            return m.name == "G1" and tuple(np.round(m.tip, 6)) in on_face
        exits = 0
        for a, b in zip(decoded, decoded[1:]):
            if faced(a) != faced(b) and a.name == b.name == "G1":
                d = np.subtract(b.tip, a.tip) * (1 if faced(a) else -1)
                np.testing.assert_allclose(d / np.linalg.norm(d), (a if faced(a) else b).axis, atol=1e-9)
                self.assertAlmostEqual(float(np.linalg.norm(d)), op.AxisRetract.Value, places=9)
                exits += faced(a)
        self.assertGreater(exits, 0)

        # posts (through compat.load_post): tarus -> A and C words, apt_cl -> GOTO/x,y,z,i,j,k
        tarus = r.gcode["tarus"]
        self.assertTrue(re.search(r"\bA-?\d", tarus) and re.search(r"\bC\d", tarus))
        self.assertTrue(r.files["tarus"].is_file())
        gotos = np.array([[float(v) for v in ln[5:].split(",")] for ln in r.gcode["apt_cl"].splitlines()
                          if ln.startswith("GOTO/")])
        self.assertEqual(gotos.shape[1], 6)
        np.testing.assert_allclose(np.linalg.norm(gotos[:, 3:], axis=1), 1.0, atol=1e-5)
        self.assertGreaterEqual(len(gotos), len(cut_path))
        self.assertTrue(r.files["apt_cl"].is_file())
        processor = load_post("tarus")
        text = processor.export([r.job.Tools.Group[0], op], str(OUT / "mp_direct.ngc"), "--no-show-editor")
        self.assertIn(" A", text if isinstance(text, str) else (OUT / "mp_direct.ngc").read_text())

    @core_work  # the op's properties to the core: the same on every FreeCAD (the other tests read the op there)
    def test_surface_extension_and_tip_anchor(self) -> None:
        """The op's SurfaceExtension and FootprintAnchor reach the core: on the concave patch the passes on
        the rims touch the continued bowl, and the tilted tips lie on the footprint points."""
        net = bezier.load_seed_patch(SEED, "concave")
        r = run_multipoint(net, out_dir=OUT, name="mp_extend", surface_extension=12.7, footprint_anchor="tip",
                           posts=("apt_cl",), **FAST)
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertAlmostEqual(op.SurfaceExtension.Value, 12.7)
        self.assertEqual(op.FootprintAnchor, "Tip")
        res = r.results
        self.assertEqual(res.counts()["failed"], 0)
        self.assertGreater(int((res["on_extension"] > 0).sum()), 0)
        self.assertLessEqual(float(res["penetration_real"].max()), 1e-3)
        np.testing.assert_allclose(res["tip"][:, :2], res.xy, atol=5e-3)
        with self.assertRaises(TmmError):
            run_multipoint(net, footprint_anchor="contact", **FAST)

    @core_work  # the core's positions at the seed's footprint, read through the op
    def test_fixed_pass_spacing_machines_the_seeds_footprint(self) -> None:
        """PassSpacing Fixed, 18 / 2 mm: the op positions the tool at the seed's 760 footprint points
        (x = 0, 18, ..., 144, 150), with the same contacts as the core at that footprint."""
        from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams, position_points
        from benchmarks.seed.experiment import RI, RO, seed_footprint
        r = run_multipoint(seed_net(), side_step=18.0, forward_step=2.0, pass_spacing="fixed", posts=(),
                           progress=False)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertEqual(r.op.PassSpacing, "Fixed")
        self.assertEqual(r.op.getEnumerationsOfProperty("PassSpacing"), ["Even", "Fixed", "Scallop"])
        seed = np.vstack(seed_footprint())
        n = len(seed)  # the footprint's positions come first, those inserted between them after
        np.testing.assert_allclose(r.results.xy[:n], seed, atol=1e-6)
        core = position_points(BezierFace.from_net(seed_net()), RO, RI, seed, MultipointParams())
        np.testing.assert_array_equal(r.results.status[:n], core.status)
        np.testing.assert_allclose(r.results["tip"][:n], core["tip"], atol=1e-6)
        self.assertGreater(len(r.results), n)  # the corners' moves cut 0.05 mm deep: positions inserted
        with self.assertRaises(TmmError):
            run_multipoint(seed_net(), **{**FAST, "pass_spacing": "tight"})

    def test_bspline_face_gives_the_same_path(self) -> None:
        """DRD: the same tips within 1e-6. VCRF: the kernel's surface samples follow the patches (4 after the
        knot insertion instead of 1), so a few positions land elsewhere within the search's resolution
        (up to ~0.03 mm at the default sample spacing); the rest agree within 1e-6."""
        net = seed_net()
        bs = bezier_surface(net).toBSpline()
        bs.insertUKnot(0.37, 1, 1e-9)
        bs.insertVKnot(0.61, 1, 1e-9)
        doc = new_doc("MpBspline")
        obj = doc.addObject("Part::Feature", "Spline")
        obj.Shape = bs.toShape()
        doc.recompute()
        for method, opts in (("drd", DRD), ("vcrf", FAST)):
            opts = dict(opts, gouge_tolerance=0.0)  # the footprint's positions only: the same on both faces
            ref = drd_bezier_tips() if method == "drd" else g1_tips(run_multipoint(net, doc_name="MpBez", **opts).op)
            r = run_multipoint((obj, "Face1"), **opts)
            self.assertTrue(r.op.isValid(), r.op.getStatusString())
            self.assertEqual(type(r.face[0].Shape.Faces[0].Surface).__name__, "BSplineSurface")
            got = g1_tips(r.op)
            self.assertEqual(got.shape, ref.shape)
            d = np.linalg.norm(got - ref, axis=1)
            if method == "drd":
                self.assertLess(d.max(), 1e-6)
            else:
                self.assertLess(d.max(), 0.05)
                self.assertGreater(np.mean(d < 1e-6), 0.95)

    def test_placement_moves_the_path(self) -> None:
        net = seed_net()
        ref = drd_bezier_tips()  # the footprint's positions (gouge_tolerance 0): the placement moves them all
        doc = new_doc("MpPlaced")
        obj = doc.addObject("Part::Feature", "Patch")
        obj.Shape = bezier_surface(net).toShape()
        obj.Placement.Base = FreeCAD.Vector(100, -50, 7)
        doc.recompute()
        r = run_multipoint((obj, "Face1"), **DRD, gouge_tolerance=0.0)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        np.testing.assert_allclose(g1_tips(r.op), ref + [100, -50, 7], atol=1e-6)

    def test_save_and_reopen(self) -> None:
        path = OUT / "multipoint_reopen.FCStd"
        r = run_multipoint(seed_net(), fcstd_path=path, doc_name="MpSave", **{**DRD, "pass_spacing": "fixed"})
        op = r.op
        self.assertTrue(op.isValid(), op.getStatusString())
        before = commands(op)
        name, summary = op.Name, op.ContactSummary
        close_all()
        doc = FreeCAD.openDocument(str(path))
        op = doc.getObject(name)
        self.assertIsInstance(op.Proxy, ObjectTmmMultipoint)
        self.assertEqual(op.Method, "DRD")
        self.assertAlmostEqual(op.ForwardStep.Value, 10.0)
        self.assertEqual(op.PassSpacing, "Fixed")
        self.assertEqual(op.Base[0][1], ("Face1",))
        self.assertEqual(op.ContactSummary, summary)
        self.assertSamePath(commands(op), before, 1e-5)  # a saved Path keeps 6 decimals
        op.Proxy.progress_enabled = False
        op.touch()
        doc.recompute()
        self.assertTrue(op.isValid(), op.getStatusString())
        self.assertSamePath(commands(op), before, 1e-9)

    def assertSamePath(self, got, want, tol) -> None:
        self.assertEqual([n for n, _ in got], [n for n, _ in want])
        for (_, a), (_, b) in zip(got, want):
            self.assertEqual(set(a), set(b))
            for k in a:
                self.assertAlmostEqual(a[k], b[k], delta=tol)


class BadInput(FreeCADTestCase):
    def test_plane_face_is_refused(self) -> None:
        doc = new_doc("MpPlane")
        box = doc.addObject("Part::Box", "Block")
        doc.recompute()
        with self.assertRaises(TmmError) as ctx:
            run_multipoint((box, "Face6"), **FAST)
        self.assertIn("Bézier or B-spline", str(ctx.exception))
        self.assertIn("Plane", str(ctx.exception))
        op = [o for o in doc.Objects if isinstance(getattr(o, "Proxy", None), ObjectTmmMultipoint)][0]
        self.assertFalse(op.isValid())
        self.assertEqual(len(op.Path.Commands), 0)

    def test_endmill_is_refused_by_the_core(self) -> None:
        with self.assertRaises(TmmError) as ctx:
            run_multipoint(seed_net(), Ro=6.0, Ri=0.0, **FAST)
        self.assertIn("flat end mill (Ri = 0)", str(ctx.exception))
        self.assertEqual(list(FreeCAD.listDocuments()), [])  # the call's own document is closed

    def test_ball_end_mill_is_accepted(self) -> None:
        r = run_multipoint(seed_net(), Ro=0.0, Ri=6.0, posts=(), **FAST)
        self.assertTrue(r.op.isValid(), r.op.getStatusString())
        self.assertEqual(tools.shape_name(r.op.ToolController.Tool), "ballend")
        self.assertEqual(r.op.Proxy.radii, (0.0, 6.0))

    def test_cancel(self) -> None:
        calls = []

        def cancel(fraction: float) -> bool:
            calls.append(fraction)
            return False

        with self.assertRaises(TmmError) as ctx:
            run_multipoint(seed_net(), **{**FAST, "progress": cancel})
        self.assertIn("cancelled", str(ctx.exception))
        self.assertTrue(calls)


if __name__ == "__main__":
    unittest.main()
