"""TMM's fast posts (tmm_linuxcnc, tmm_grbl) against FreeCAD's linuxcnc and grbl posts on the same objects: what a
control reads from both programs (motion mode, plane, X Y Z, I J K, F, tool, spindle) is the same, and the text
is the same but for the header's post name and time. Jobs: a Surface op on sphere_on_plate with arcs off and on
(arcs through grbl, which writes K), a roughing + waterline Job with two tool controllers."""
from __future__ import annotations

import math
import random
import re
from typing import Any, Optional

import FreeCAD

from fc_helpers import OUT, SPHERE_ON_PLATE, FreeCADTestCase, close_all
from tmm_workbench.app import api, gcode_fast, path_build, posts
from tmm_workbench.app.compat import PathPreferences

_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")
Move = tuple[Any, ...]


def control_moves(text: str) -> list[Move]:
    """What a control executes: for every line that moves, (mode, plane, X, Y, Z, I, J, K, F, tool, spindle on,
    S) with the modal words carried over; comments and line numbers skipped; I J K belong to their line."""
    pos = {"X": math.nan, "Y": math.nan, "Z": math.nan}
    mode: Optional[int] = None
    plane, feed, speed, tool, pending, spindle = 17, math.nan, math.nan, None, None, False
    out: list[Move] = []
    for raw in text.splitlines():
        words = [(k, float(v)) for k, v in _WORD.findall(re.sub(r"\(.*?\)|;.*$", "", raw).upper()) if k != "N"]
        gs = [v for k, v in words if k == "G"]
        ms = [v for k, v in words if k == "M"]
        for k, v in words:
            pending = int(v) if k == "T" else pending
            speed = v if k == "S" else speed
            feed = v if k == "F" else feed
        tool = pending if 6 in ms else tool
        spindle = (spindle or 3 in ms or 4 in ms) and 5 not in ms
        plane = next((int(g) for g in gs if g in (17, 18, 19)), plane)
        mode = next((int(g) for g in reversed(gs) if g in (0, 1, 2, 3)), mode)
        moved = {k: v for k, v in words if k in "XYZ"}
        centre = {k: v for k, v in words if k in "IJK"}
        if mode is None or not (moved or centre) or any(g not in (0, 1, 2, 3, 17, 18, 19) for g in gs):
            continue
        pos.update(moved)
        out.append((mode, plane, pos["X"], pos["Y"], pos["Z"], centre.get("I"), centre.get("J"), centre.get("K"),
                    feed if mode else None, tool, spindle, speed))
    return out


def body(text: str) -> list[str]:
    """The program without the header lines naming the post and the time (the only lines allowed to differ)."""
    return [ln for ln in text.splitlines() if "(Post Processor:" not in ln and "(Output Time:" not in ln]


class FastPostsTest(FreeCADTestCase):
    """One document per job, made once (computing them is the slow part)."""

    @classmethod
    def setUpClass(cls) -> None:
        stl = str(SPHERE_ON_PLATE)
        lines = api.run_surface(stl, stepover=2.0, sample_step=0.5, post="tmm_linuxcnc", progress=False,
                                doc_name="FastLines")
        arcs = api.run_surface(stl, stepover=2.0, arcs=True, post="tmm_grbl", progress=False, doc_name="FastArcs")
        rough = api.run_roughing(stl, diameter=6.0, step_down=6.0, post="tmm_linuxcnc", progress=False,
                                 doc_name="FastTwoTools")
        water = api.run_waterline(job=rough.job, diameter=3.0, step_down=3.0, post="tmm_linuxcnc", progress=False)
        cls.results = {"lines": lines, "arcs": arcs, "two_tools": water}
        cls.objects = {"lines": [lines.op.ToolController, lines.op], "arcs": [arcs.op.ToolController, arcs.op],
                       "two_tools": [rough.op.ToolController, rough.op, water.op.ToolController, water.op]}

    @classmethod
    def tearDownClass(cls) -> None:
        close_all()

    def tearDown(self) -> None:
        pass  # the documents are shared by the tests (closed in tearDownClass)

    def compare(self, job: str, stock: str, fast: str, args: Optional[str] = None, precision: int = 4) -> list[Move]:
        """Both posts' programs for `job` read as a control reads them: equal within the printed precision,
        and equal as text but for the header. The moves read."""
        objects = self.objects[job]
        slow_text = posts.export(stock, objects, args=args)
        fast_text = posts.export(fast, objects, args=args)
        slow, quick = control_moves(slow_text), control_moves(fast_text)
        self.assertGreater(len(slow), 20, f"{job}: too few moves read from {stock}'s program")
        self.assertEqual(len(slow), len(quick), f"{job} {args}: move counts differ")
        half = 0.5 * 10.0 ** -precision
        for i, (a, b) in enumerate(zip(slow, quick)):
            for x, y in zip(a, b):
                same = (x == y or (isinstance(x, float) and isinstance(y, float)
                                   and (abs(x - y) <= half or (math.isnan(x) and math.isnan(y)))))
                self.assertTrue(same, f"{job} {args}: move {i} differs: {stock} {a} / {fast} {b}")
        self.assertEqual(body(slow_text), body(fast_text), f"{job} {args}: text differs beyond the header")
        return slow

    def test_surface_linuxcnc_and_grbl(self) -> None:
        for stock in ("linuxcnc", "grbl"):
            moves = self.compare("lines", stock, "tmm_" + stock)
            self.assertTrue(any(m[0] == 1 and m[8] == 1000.0 for m in moves), f"{stock}: no cut at F1000")
            self.assertTrue(all(m[9] == 1 for m in moves) if stock == "linuxcnc" else True)

    def test_surface_arcs_grbl(self) -> None:
        moves = self.compare("arcs", "grbl", "tmm_grbl")
        arcs = [m for m in moves if m[0] in (2, 3)]
        self.assertTrue(arcs, "the arcs job posted no G2/G3")
        self.assertTrue(any(m[7] is not None for m in arcs), "no arc with K (a vertical arc) in the arcs job")

    def test_two_tool_controllers(self) -> None:
        moves = self.compare("two_tools", "linuxcnc", "tmm_linuxcnc")
        self.assertEqual({m[9] for m in moves}, {1, 2}, "the moves are not cut by both tools")
        self.compare("two_tools", "grbl", "tmm_grbl", "--no-show-editor --precision 4 --tool-change")

    def test_arguments(self) -> None:
        """FreeCAD's arguments that change what a control reads give the same programs."""
        for args, precision in (("--no-show-editor", 3), ("--no-show-editor --precision 4 --line-numbers", 4),
                                ("--no-show-editor --no-comments --no-header --precision 2", 2),
                                ("--no-show-editor --inches", 4),
                                ("--no-show-editor --precision 4 --modal --axis-modal --no-tlo", 4)):
            self.compare("two_tools", "linuxcnc", "tmm_linuxcnc", args, precision)
        for args, precision in (("--no-show-editor --precision 4 --line-numbers --inches", 4),
                                ("--no-show-editor --no-comments --wait-for-spindle 2 --return-to 0,0 --bcnc", 3)):
            self.compare("arcs", "grbl", "tmm_grbl", args, precision)

    def test_unit_rounding_is_freecads(self) -> None:
        """The fast posts divide by the unit where FreeCAD converts a Quantity: the same digits at every value."""
        rng = random.Random(7)
        for _ in range(20000):
            v = rng.uniform(-500.0, 500.0) * rng.choice((1.0, 1e-3, 1e2))
            speed = FreeCAD.Units.Quantity(v, FreeCAD.Units.Velocity)
            length = FreeCAD.Units.Quantity(v, FreeCAD.Units.Length)
            self.assertEqual("%.4f" % (v / gcode_fast.MM_PER_MIN), format(float(speed.getValueAs("mm/min")), ".4f"))
            self.assertEqual("%.4f" % (v / gcode_fast.IN_PER_MIN), format(float(speed.getValueAs("in/min")), ".4f"))
            self.assertEqual("%.4f" % (v / gcode_fast.IN), format(float(length.getValueAs("in")), ".4f"))

    def test_the_ops_record_is_their_path(self) -> None:
        """The fast posts read a TMM op's record of its Path (app.path_build), not the Path: the record holds the
        Path's commands exactly (names, words, doubles), and the program written from it is the program written
        from the Path read back."""
        for job, objects in self.objects.items():
            for op in objects[1::2]:
                rec = path_build.record_of(op)
                self.assertIsNotNone(rec, f"{job}: {op.Label} keeps no record of its Path")
                path = [(c.Name, dict(c.Parameters)) for c in op.Path.Commands]
                self.assertEqual([(c.Name, c.Parameters) for c in rec.commands()], path, f"{job}: {op.Label}")
            for fast in ("tmm_linuxcnc", "tmm_grbl"):
                from_record = posts.export(fast, objects)
                kept = [op.Proxy.path_record for op in objects[1::2]]
                try:
                    for op in objects[1::2]:
                        op.Proxy.path_record = None
                    self.assertEqual(body(from_record), body(posts.export(fast, objects)), f"{job} {fast}")
                finally:
                    for op, rec in zip(objects[1::2], kept):
                        op.Proxy.path_record = rec

    def test_reopened_document(self) -> None:
        """A document saved and reopened has no record (the ops are not recomputed): the fast posts read the Path,
        and write what FreeCAD's posts write from it; an edit of the Path (undo, a script) forgets the record."""
        path = str(OUT / "fast_posts_reopen.FCStd")
        doc = self.results["lines"].doc
        doc.saveCopy(path)
        again = FreeCAD.openDocument(path)
        self.assertNotEqual(again.Name, doc.Name)
        try:
            op = next(o for o in again.Objects if o.Name == self.results["lines"].op.Name)
            self.assertIsNone(path_build.record_of(op))
            self.objects["reopened"] = [op.ToolController, op]
            for stock in ("linuxcnc", "grbl"):
                self.compare("reopened", stock, "tmm_" + stock)
        finally:
            self.objects.pop("reopened", None)
            FreeCAD.closeDocument(again.Name)
        op = self.results["arcs"].op
        rec = op.Proxy.path_record
        op.Path = op.Path
        self.assertIsNone(path_build.record_of(op))
        op.Proxy.path_record = rec

    def test_offered_by_the_job(self) -> None:
        """The fast posts are in FreeCAD's post list and the Job's choices; run_surface chose the one asked for."""
        posts.install_post_dir()
        job = self.results["lines"].job
        for name in ("tmm_linuxcnc", "tmm_grbl"):
            self.assertIn(name, PathPreferences.allAvailablePostProcessors())
            self.assertIn(name, job.getEnumerationsOfProperty("PostProcessor"))
        self.assertEqual(job.PostProcessor, "tmm_linuxcnc")
        self.assertEqual(self.results["arcs"].job.PostProcessor, "tmm_grbl")
        self.assertIn("G2", self.results["arcs"].gcode + " ")


if __name__ == "__main__":
    import unittest

    unittest.main()
