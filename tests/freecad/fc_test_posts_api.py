"""Posts (stock linuxcnc and grbl) and the headless API, end to end: STL -> Job -> op -> G-code."""
from __future__ import annotations

import math
import os
import unittest
from pathlib import Path

import FreeCAD

from fc_helpers import (OUT, SPHERE_ON_PLATE, FreeCADTestCase, bump_stl, bump_triangles, job_with_op,
                        mesh_feature, new_doc, parse_gcode)
from tmm_workbench.app import posts
from tmm_workbench.app import tools
from tmm_workbench.app.api import SurfaceResult, run_surface
from tmm_workbench.app.compat import PathPreferences
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import MoveKind

TOL = 1.5e-3  # posts print 3 decimals


def op_positions(op):
    """(G, x, y, z) of the op's moves, with modal coordinates carried like a controller would."""
    pos = {"X": math.nan, "Y": math.nan, "Z": math.nan}
    out = []
    for c in op.Path.Commands:
        if c.Name in ("G0", "G1"):
            pos.update({k: v for k, v in c.Parameters.items() if k in pos})
            out.append((c.Name, pos["X"], pos["Y"], pos["Z"]))
    return out


def dedupe(seq):
    """Drop moves that do not change the position (posts may print or skip them)."""
    out = []
    for m in seq:
        if not out or any(abs(a - b) > TOL for a, b in zip(m[1:4], out[-1][1:4]) if not math.isnan(a)):
            out.append(m)
    return out


ADDON_LINK = Path(FreeCAD.getUserAppDataDir()) / "Mod" / "TMM"  # versioned from 1.1 (v1-1/Mod)
DUMMY_POST = '''"""TMM self-test post: one line per motion command."""
TOOLTIP = "TMM self-test"


def export(objectslist, filename, argstring):
    lines = []
    for obj in objectslist:
        for c in obj.Path.Commands:
            if c.Name in ("G0", "G1"):
                lines.append(c.toGCode())
    text = "\\n".join(lines) + "\\n"
    if filename != "-":
        with open(filename, "w") as f:
            f.write(text)
    return text
'''


class Posts(FreeCADTestCase):
    def test_init_py_registers_the_post_dir(self) -> None:
        self.assertTrue(ADDON_LINK.exists(), f"the add-on is not linked into FreeCAD's Mod folder ({ADDON_LINK}): "
                        "run scripts/setup.sh")
        self.assertEqual(os.environ.get("TMM_FC_INIT_WRAPPED_POSTS"), "1")

    def test_post_dir_is_searched(self) -> None:
        self.assertIn(posts.POST_DIR, PathPreferences.searchPathsPost())
        saved = posts.POST_DIR
        folder = OUT / "posts"
        folder.mkdir(exist_ok=True)
        (folder / "tmmselftest_post.py").write_text(DUMMY_POST)
        posts.POST_DIR = str(folder)  # the wrapper reads it at call time
        try:
            self.assertIn("tmmselftest", PathPreferences.allAvailablePostProcessors())
            doc = new_doc()
            job, tc, op = job_with_op(doc, str(bump_stl()), values={"StepOver": 4.0})
            self.assertIn("tmmselftest", job.getEnumerationsOfProperty("PostProcessor"))
            text = posts.export("tmmselftest", [tc, op])
            self.assertEqual(text.count("\n"), len([c for c in op.Path.Commands if c.Name in ("G0", "G1")]))
        finally:
            posts.POST_DIR = saved

    def check_post(self, post: str) -> None:
        doc = new_doc()
        job, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "StepOver": 4.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        path = OUT / f"bump_{post}.nc"
        text = posts.export(post, [tc, op], path)
        self.assertEqual(path.read_text(), text)
        self.assertIn("M6 T1", text.upper().replace("M06", "M6"))
        got = dedupe([m for m in parse_gcode(text) if not math.isnan(m[1])])
        want = dedupe([(n, x, y, z, None) for n, x, y, z in op_positions(op) if not math.isnan(x)])
        self.assertEqual(len(got), len(want))
        for g, w in zip(got, want):
            self.assertEqual(g[0], w[0])
            for a, b in zip(g[1:4], w[1:4]):
                self.assertAlmostEqual(a, b, delta=TOL)
        feeds = {round(m[4]) for m in parse_gcode(text) if m[0] == "G1"}
        self.assertEqual(feeds, {1200, 240})  # mm/min back from FreeCAD's mm/s

    def test_linuxcnc(self) -> None:
        self.check_post("linuxcnc")

    def test_grbl(self) -> None:
        self.check_post("grbl")

    def test_unknown_post(self) -> None:
        doc = new_doc()
        _, tc, op = job_with_op(doc, str(bump_stl()), values={"StepOver": 4.0})
        with self.assertRaises(TmmError) as ctx:
            posts.export("no_such_machine", [tc, op])
        self.assertIn("no_such_machine", str(ctx.exception))


class Api(FreeCADTestCase):
    def test_stl_to_gcode_and_fcstd(self) -> None:
        gcode_path, fcstd_path = OUT / "api_sphere.ngc", OUT / "api_sphere.FCStd"
        for p in (gcode_path, fcstd_path):
            p.unlink(missing_ok=True)
        r = run_surface(SPHERE_ON_PLATE, tool="ballend", diameter=6.0, stepover=3.0, sample_step=1.5,
                        post="linuxcnc", gcode_path=gcode_path, fcstd_path=fcstd_path, doc_name="TmmApi",
                        progress=False)
        self.assertIsInstance(r, SurfaceResult)
        self.assertTrue(gcode_path.is_file() and fcstd_path.is_file())
        self.assertEqual(gcode_path.read_text(), r.gcode)
        self.assertEqual(r.job.PostProcessor, "linuxcnc")
        self.assertEqual(len(r.mesh), 7570)
        # heights from the higher of the model's and the Job stock's top (the stock is 1 mm above the model)
        top = max(float(r.mesh.bounds[1][2]), r.job.Stock.Shape.BoundBox.ZMax)
        self.assertGreater(top, float(r.mesh.bounds[1][2]))
        self.assertAlmostEqual(r.op.SafeHeight.Value, top + 5, places=6)
        self.assertAlmostEqual(r.op.ClearanceHeight.Value, top + 10, places=6)
        lo, hi = r.mesh.bounds
        cut = r.toolpath.cutting_points()
        self.assertAlmostEqual(cut[:, 0].min(), lo[0], places=6)  # boundary 'model'
        self.assertAlmostEqual(cut[:, 1].max(), hi[1], places=6)
        kinds = {m.kind for m in r.toolpath}
        self.assertEqual(kinds, {MoveKind.RAPID, MoveKind.PLUNGE, MoveKind.FEED})
        g1 = [m for m in parse_gcode(r.gcode) if m[0] == "G1"]
        self.assertEqual(len(g1), len(cut))
        self.assertEqual({round(m[4]) for m in g1}, {1000, 300})
        self.assertIn("S10000", r.gcode)

    def test_mesh_object_grbl_bullnose_oneway(self) -> None:
        doc = new_doc("TmmApiMesh")
        mesh = mesh_feature(doc, bump_triangles())
        r = run_surface(mesh, tool="bullnose", diameter=6.0, corner_radius=1.0, stepover=2.0, sample_step=1.0,
                        pattern="oneway", boundary="stock", margin=-1.0, post="grbl", progress=False,
                        horiz_feed=900, vert_feed=150, safe_height=12, clearance_height=20)
        self.assertIs(r.doc, doc)
        self.assertEqual(r.op.Pattern, "OneWay")
        self.assertIs(r.op.Model, mesh)
        self.assertEqual((r.op.SafeHeight.Value, r.op.ClearanceHeight.Value), (12.0, 20.0))
        self.assertEqual(tools.shape_name(r.job.Tools.Group[0].Tool), "bullnose")
        g = parse_gcode(r.gcode)
        self.assertEqual({round(m[4]) for m in g if m[0] == "G1"}, {900, 150})
        self.assertAlmostEqual(max(m[3] for m in g), 20.0, places=3)
        cut = r.toolpath.cutting_points()  # stock = model + 1 mm; margin -1 gives the model's box
        self.assertAlmostEqual(cut[:, 0].min(), -10.0, places=6)
        self.assertAlmostEqual(cut[:, 0].max(), 10.0, places=6)

    def test_part_object(self) -> None:
        doc = new_doc("TmmApiPart")
        box = doc.addObject("Part::Box", "Block")
        box.Length, box.Width, box.Height = 30, 20, 10
        box.Placement.Base = FreeCAD.Vector(5, 5, 0)
        doc.recompute()
        r = run_surface(box, tool="endmill", diameter=4.0, stepover=4.0, sample_step=2.0, progress=False)
        self.assertIs(r.op.Model, box)
        self.assertIs(r.job.Proxy.baseObject(r.job, r.job.Model.Group[0]), box)
        cut = r.toolpath.cutting_points()
        self.assertAlmostEqual(cut[:, 2].max(), 10.0, places=6)  # the flat top, with the placement
        self.assertAlmostEqual(cut[:, 0].min(), 5.0, places=6)
        self.assertAlmostEqual(r.op.SafeHeight.Value, r.job.Stock.Shape.BoundBox.ZMax + 5.0)  # above the stock

    def test_progress_callback_and_cancel(self) -> None:
        seen = []
        r = run_surface(bump_stl(), stepover=2.0, sample_step=1.0, progress=lambda f: seen.append(f) or True,
                        doc_name="TmmProgress")
        self.assertTrue(seen and seen[-1] == 1.0, seen[-3:])
        self.assertTrue(all(b >= a for a, b in zip(seen, seen[1:])))
        FreeCAD.closeDocument(r.doc.Name)
        docs = set(FreeCAD.listDocuments())
        with self.assertRaises(TmmError) as ctx:
            run_surface(bump_stl(), stepover=0.1, sample_step=0.05, progress=lambda f: f < 0.3)  # polled before the end
        self.assertIn("cancelled", str(ctx.exception))
        self.assertEqual(set(FreeCAD.listDocuments()), docs)  # the call's own document is closed again

    def test_cusp_spacing(self) -> None:
        r = run_surface(bump_stl(), sample_step=1.0, stepover_mode="adaptive", cusp=0.02,
                        progress=False, doc_name="TmmApiCusp")
        self.assertEqual((r.op.StepOverMode, round(r.op.CuspHeight.Value, 9)), ("Adaptive", 0.02))
        ys = sorted({round(float(y), 6) for y in r.toolpath.cutting_points()[:, 1]})
        self.assertGreater(len(ys), 10)
        FreeCAD.closeDocument(r.doc.Name)

    def test_bad_arguments(self) -> None:
        with self.assertRaises(TmmError) as ctx:
            run_surface(OUT / "nowhere.stl")
        self.assertIn("file not found", str(ctx.exception))
        for kwargs, text in (({"tool": "chamfer"}, "tool must be one of"), ({"pattern": "helix"}, "pattern"),
                             ({"boundary": "custom"}, "boundary"),
                             ({"tool": "bullnose", "corner_radius": 4.0}, "larger than the tool radius"),
                             ({"stepover": 0.0}, "must be a positive length"),
                             ({"stepover_mode": "scallop"},
                              "stepover_mode must be one of stepover, cusp, adaptive, offset3d, got 'scallop'"),
                             ({"cusp": -1.0}, "cusp must be >= 0.0001 mm, got -1"),
                             # an argument the chosen mode would ignore, and a step-over no tool covers
                             ({"cusp": 0.01}, "cusp 0.01 is not used with stepover_mode 'stepover'"),
                             ({"stepover": 0.5, "stepover_mode": "cusp"},
                              "stepover is not used with stepover_mode 'cusp'"),
                             ({"spiral_direction": "inward"}, "spiral_direction is used with pattern 'spiral' only"),
                             ({"arcs": True, "forward_step": "sample"}, "arcs need forward_step 'tolerance'"),
                             ({"stepover": 0.5, "stepover_percent": 10.0}, "not both"),
                             ({"stepover": 500.0}, "StepOver 500 mm is wider than the tool (diameter 6 mm)")):
            with self.subTest(**kwargs):
                with self.assertRaises(TmmError) as ctx:
                    run_surface(bump_stl(), progress=False, **kwargs)
                self.assertIn(text, str(ctx.exception))

    def test_a_flat_end_mill_in_a_cusp_mode_is_warned(self) -> None:
        from tmm_workbench.core.strategies.surface.estimate import tool_fit
        from tmm_workbench.core.strategies.raster_drop import SurfaceParams
        from tmm_workbench.core.tools.cutter import Cutter

        params = SurfaceParams(stepover_mode="cusp", cusp=0.01)
        self.assertIn("a ball or bull-nose end mill", tool_fit(params, Cutter.flat(6.0)))
        self.assertEqual(tool_fit(params, Cutter.ball(6.0)), "")
        self.assertEqual(tool_fit(SurfaceParams(stepover=6.0), Cutter.flat(6.0)), "")
        # a cusp with the verification is read in the step-over mode too
        r = run_surface(bump_stl(), cusp=0.05, verify_cusp=True, progress=False, doc_name="TmmVerifyStep")
        self.assertAlmostEqual(r.op.CuspHeight.Value, 0.05)


if __name__ == "__main__":
    unittest.main()
