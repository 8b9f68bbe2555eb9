"""5-axis moves in a FreeCAD Path (X Y Z tip + U V W axis, core.path5) through FreeCAD's post chain:
TMM's `tarus` and `apt_cl` posts found through the search-path hook and loaded by compat.load_post, their
output parsed back (Tarus through forward kinematics) equal to the tool path; stock linuxcnc/grbl posts and
Inspect-style reading accept the representation; a joint limit violation is an error and writes no file."""
from __future__ import annotations

import math
import os
import re
import unittest
from pathlib import Path as FilePath

import FreeCAD
import Path
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, new_doc
from tmm_workbench.app import job as jobs
from tmm_workbench.app import posts
from tmm_workbench.app import compat, tools
from tmm_workbench.app.compat import PathPreferences, load_post
from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine import TarusMachine
from tmm_workbench.core.toolpath import MoveKind, Toolpath

HORIZ, VERT = 20.0, 5.0  # mm/s
_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


def tilted_toolpath(n: int = 120, max_tilt_deg: float = 40.0) -> Toolpath:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, -30, 0, 60)
    tp.add(MoveKind.PLUNGE, -30, 0, 0)
    for k in range(n):
        s = k / (n - 1)
        c = math.radians(max_tilt_deg) * abs(math.sin(2.5 * math.pi * s))
        a = 1.5 * math.pi * s + 0.4
        tp.add(MoveKind.FEED, -30 + 60 * s, 10 * math.sin(6 * s), 2 * math.cos(5 * s) - 2,
               axis=(math.sin(c) * math.cos(a), math.sin(c) * math.sin(a), math.cos(c)))
    last = tp.moves[-1]
    tp.add(MoveKind.RAPID, last.x, last.y, 60, axis=last.axis)
    return tp


def parse_tarus(text: str) -> np.ndarray:
    """(n, 5) x, y, z, a (rad), c (rad) of every motion line, modal words carried."""
    state = {"X": math.nan, "Y": math.nan, "Z": math.nan, "A": math.nan, "C": math.nan}
    rows = []
    for raw in text.splitlines():
        line = re.sub(r"\(.*?\)", "", raw).strip()
        words = _WORD.findall(line)
        if not any(k in state for k, _ in words):
            continue
        for k, v in words:
            if k in state:
                state[k] = math.radians(float(v)) if k in "AC" else float(v)
        rows.append([state[k] for k in "XYZAC"])
    return np.array(rows).reshape(-1, 5)


def parse_goto(text: str) -> np.ndarray:
    return np.array([[float(v) for v in ln[5:].split(",")] for ln in text.splitlines()
                     if ln.startswith("GOTO/")]).reshape(-1, 6)


GOLDEN = FilePath(__file__).resolve().parents[1] / "data" / "posts"  # written on FreeCAD 0.20, the same on 1.0, 1.1


def without_dates(text: str) -> str:
    return "\n".join(ln for ln in text.splitlines() if "Generated on" not in ln)


class Posts5(FreeCADTestCase):
    def setUp(self) -> None:
        self.doc = new_doc("TmmPosts5")
        box = self.doc.addObject("Part::Box", "Block")
        box.Length, box.Width, box.Height = 60, 40, 10
        box.Placement.Base = FreeCAD.Vector(-30, -20, -10)
        self.doc.recompute()
        self.job = jobs.create_job(self.doc, box)
        # TMM's own bit, not the Job's default one (which differs between FreeCAD versions)
        self.tc = jobs.set_tool(self.job, tools.make_tool_bit(self.doc, "endmill", 5.0), HORIZ, VERT, 10000)
        self.tp = tilted_toolpath()
        self.op = self.path_object("Tilted", self.tp)

    def path_object(self, name: str, tp: Toolpath):
        """A plain Path::Feature in the Job's Operations, carrying TMM's representation."""
        obj = self.doc.addObject("Path::Feature", name)
        cmds = [Path.Command("(TMM 5-axis test path)")]
        cmds += [Path.Command(n, p) for n, p in path5.encode_toolpath(tp, HORIZ, VERT)]
        obj.Path = Path.Path(cmds)
        self.job.Operations.addObject(obj)
        self.doc.recompute()
        return obj

    def test_posts_found_through_the_search_path_hook(self) -> None:
        self.assertIn(posts.POST_DIR, PathPreferences.searchPathsPost())
        available = PathPreferences.allAvailablePostProcessors()
        for name in ("tarus", "apt_cl"):
            self.assertIn(name, available)
            self.assertIn(name, self.job.getEnumerationsOfProperty("PostProcessor"))
            processor = load_post(name)
            self.assertEqual(os.path.dirname(os.path.realpath(processor.__file__)),
                             os.path.realpath(posts.POST_DIR))
            self.assertTrue(processor.TOOLTIP and processor.TOOLTIP_ARGS)
            self.assertEqual(processor.UNITS, "G21")

    def test_the_same_gcode_on_every_freecad(self) -> None:
        """tarus and apt_cl write byte for byte the files written on FreeCAD 0.20 (TMM_WRITE_GOLDEN=1 rewrites
        them); from 1.0 also through FreeCAD's own post factory, as the CAM Post command runs them."""
        for post, name in (("tarus", "tilted.tarus.ngc"), ("apt_cl", "tilted.apt")):
            with self.subTest(post=post):
                text = without_dates(load_post(post).export([self.tc, self.op], "-", "--no-show-editor"))
                golden = GOLDEN / name
                if os.environ.get("TMM_WRITE_GOLDEN") == "1":
                    golden.parent.mkdir(parents=True, exist_ok=True)
                    golden.write_text(text)
                self.assertEqual(text, golden.read_text())
                if compat.freecad_version() < (1, 0):
                    continue
                from Path.Post.Processor import PostProcessorFactory

                self.job.PostProcessor = post
                self.job.PostProcessorArgs = "--no-show-editor"
                sections = PostProcessorFactory.get_post_processor(self.job, post).export()
                ours = [ln for ln in text.splitlines() if ln.startswith(("G1", "G0", "GOTO/", "G93"))]
                theirs = [ln for _, g in sections for ln in without_dates(g).splitlines()
                          if ln.startswith(("G1", "G0", "GOTO/", "G93"))]
                self.assertEqual(theirs, ours)

    def test_representation_is_exact_in_the_document(self) -> None:
        moves = path5.decode_commands([(c.Name, c.Parameters) for c in self.op.Path.Commands])
        self.assertEqual(len(moves), len(self.tp))
        for m, d in zip(self.tp, moves):
            self.assertEqual(d.tip, (m.x, m.y, m.z))
            self.assertLess(max(abs(a - b) for a, b in zip(d.axis, m.axis)), 2.3e-16)

    def test_tarus_round_trip_through_fk(self) -> None:
        m = TarusMachine(pivot_length=150.0, tool_length=80.0)
        for tcp in (False, True):
            with self.subTest(tcp=tcp):
                target = OUT / f"tarus_{'tcp' if tcp else 'joints'}.ngc"
                # one line per move (joint-mode subdivision off; tests/core/test_post_writers.py checks it)
                args = "--no-show-editor --precision 10 --angle-precision 12 --tool-length 80 " \
                    "--tip-tolerance 1e9 --axis-tolerance 89" + (" --tcp" if tcp else "")
                processor = load_post("tarus")
                text = processor.export([self.tc, self.op], str(target), args)
                self.assertEqual(target.read_text(), text)
                self.assertIn("T1 M6", text)
                self.assertIn("S10000 M3", text)
                self.assertIn("G93 G1", text)
                j = parse_tarus(text)
                self.assertEqual(len(j), len(self.tp))
                tips, axes = m.forward_path(j)
                if tcp:
                    tips = j[:, :3]
                self.assertLess(np.abs(tips - self.tp.points()).max(), 1e-6)
                self.assertLess(np.abs(axes - self.tp.axes()).max(), 1e-9)

    def test_tarus_through_the_headless_api(self) -> None:
        text = posts.export("tarus", [self.tc, self.op], OUT / "tarus_api.ngc", "--no-show-editor --inches")
        self.assertIn("G20", text)
        self.assertTrue(any(ln.startswith("G93 G1") for ln in text.splitlines()))

    def test_apt_cl(self) -> None:
        processor = load_post("apt_cl")
        target = OUT / "tilted.apt"
        text = processor.export([self.tc, self.op], str(target), "--no-show-editor --precision 9 --axis-precision 12")
        self.assertEqual(target.read_text(), text)
        lines = text.splitlines()
        for want in ("LOADTL/1", "SPINDL/ 10000.0000,RPM,CLW", "FEDRAT/ 1200.0000,MMPM", "SPINDL/OFF"):
            self.assertIn(want, lines)
        self.assertTrue(any(ln.startswith("CUTTER/ 5.000000") for ln in lines), lines[:20])
        g = parse_goto(text)
        self.assertEqual(len(g), len(self.tp))
        self.assertLess(np.abs(g[:, :3] - self.tp.points()).max(), 1e-8)
        self.assertLess(np.abs(g[:, 3:] - self.tp.axes()).max(), 1e-11)

    def test_stock_posts_and_inspect_read_the_representation(self) -> None:
        for post in ("linuxcnc", "grbl"):
            with self.subTest(post=post):
                text = posts.export(post, [self.tc, self.op], OUT / f"tilted_{post}.nc")
                self.assertIn("G1", text)
        linuxcnc = (OUT / "tilted_linuxcnc.nc").read_text()
        self.assertFalse(re.search(r"\b[UVW]-?\d", linuxcnc))  # linuxcnc drops U V W: the tip path only
        # Inspect-style reading: commands, G-code text, length, bounding box, re-parsing the text
        cmds = self.op.Path.Commands
        self.assertTrue(all(isinstance(c.Name, str) and isinstance(c.Parameters, dict) for c in cmds))
        gcode = Path.Path(cmds).toGCode()
        self.assertIn("U", gcode)
        self.assertGreater(self.op.Path.Length, 0.0)
        bb = self.op.Path.BoundBox
        self.assertAlmostEqual(bb.ZMax, 60.0, places=6)
        again = Path.Path()
        again.setFromGCode(gcode)
        self.assertEqual(len(again.Commands), len(cmds))
        back = path5.decode_commands([(c.Name, c.Parameters) for c in again.Commands])
        self.assertLess(max(abs(a - b) for d, m in zip(back, self.tp) for a, b in zip(d.axis, m.axis)), 2e-6)
        # FreeCAD's geometry of a command: edges from X, Y, Z; the placement ignores U, V, W
        PathGeom = compat.import_app("geom")
        start = FreeCAD.Vector(-30, 0, 60)
        for c in cmds[3:20]:
            self.assertEqual(c.Placement.Rotation.Angle, 0.0)
            edge = PathGeom.edgeForCmd(c, start)
            end = FreeCAD.Vector(c.Parameters["X"], c.Parameters["Y"], c.Parameters["Z"])
            if edge is not None:
                self.assertLess((edge.Vertexes[-1].Point - end).Length, 1e-9)
            start = end

    def test_three_axis_ops_post_on_the_tarus(self) -> None:
        tp = Toolpath()
        tp.add(MoveKind.RAPID, 1, 2, 30)
        tp.add(MoveKind.FEED, 5, 2, -1)
        flat = self.path_object("Flat", tp)
        text = posts.export("tarus", [self.tc, flat], None, "--no-show-editor")
        self.assertIn("G1 X5.0000 Y2.0000 Z249.0000 A0.000000 C0.000000 F1200.0000", text)  # pivot 150 + tool 100
        self.assertNotIn("G93", text)

    def test_job_post_processor_and_a_tmm_surface_op(self) -> None:
        """A Job set to the tarus post; TMM's own 3-axis op posts through it (pivot-compensated)."""
        from fc_helpers import bump_stl, job_with_op
        from tmm_workbench.core.toolpath import Z_AXIS

        self.job.PostProcessor = "tarus"
        self.job.PostProcessorArgs = "--no-show-editor --precision 8"
        self.assertEqual(self.job.PostProcessor, "tarus")
        doc = new_doc("TmmPosts5Surface")
        job, tc, op = job_with_op(doc, str(bump_stl()), values={"BoundaryShape": "Model", "StepOver": 4.0})
        self.assertTrue(op.isValid(), op.getStatusString())
        text = posts.export("tarus", [tc, op], OUT / "bump_tarus.ngc", "--no-show-editor --precision 8")
        self.assertNotIn("G93", text)
        moves = path5.decode_commands([(c.Name, c.Parameters) for c in op.Path.Commands])
        self.assertTrue(all(m.axis == Z_AXIS for m in moves))
        j = parse_tarus(text)
        self.assertEqual(len(j), len(moves))
        self.assertTrue(np.all(j[:, 3:] == 0.0))
        m = TarusMachine()
        tips = m.forward_path(j)[0]
        want = np.array([mv.tip for mv in moves])
        known = ~np.isnan(want)
        self.assertLess(np.abs(tips[known] - want[known]).max(), 1e-8)

    def test_limit_violation_is_an_error_and_writes_nothing(self) -> None:
        steep = self.path_object("Steep", tilted_toolpath(30, max_tilt_deg=60.0))
        for name in ("tarus",):
            target = OUT / "steep_tarus.ngc"
            target.unlink(missing_ok=True)
            processor = load_post(name)
            with self.assertRaises(TmmError) as ctx:
                processor.export([self.tc, steep], str(target), "--no-show-editor")
            self.assertIn("operation 'Steep'", str(ctx.exception))
            self.assertIn("joint C", str(ctx.exception))
            self.assertFalse(target.exists())
        # a wider tilt range on the command line makes it reachable
        text = load_post("tarus").export([self.tc, steep], "-", "--c-max 70")
        self.assertIn("M2", text)
        self.assertFalse(FilePath("-").exists())


if __name__ == "__main__":
    unittest.main()
