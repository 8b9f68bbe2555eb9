"""app.path_build: a tool path's rows and the Path commands made from them (what the op's Path holds and the
fast posts, the status line and the cycle time read instead of it)."""
from __future__ import annotations

import math

import numpy as np

from fc_helpers import FreeCADTestCase
from tmm_workbench.app import path_build
from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.errors import Cancelled
from tmm_workbench.core.toolpath import MoveKind, Toolpath

H, V = 1000.0 / 60.0, 300.0 / 60.0   # mm/s


def sample_path(arc: bool = False) -> Toolpath:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 20)
    tp.add(MoveKind.PLUNGE, 0, 0, 1)
    tp.add(MoveKind.FEED, 10, 0, 1)        # level: horizontal feed
    tp.add(MoveKind.FEED, 10.5, 0, -4)     # down 84 deg: the plunge feed
    tp.add(MoveKind.FEED, 20, 0, -5)       # down 6 deg: horizontal feed
    if arc:
        tp.add(MoveKind.FEED, 30, 0, 5, arc=Arc(centre=(30.0, 0.0, -5.0), clockwise=False, plane="XZ"))
    tp.add(MoveKind.RAPID, tp.moves[-1].x, 0, 20)
    tp.add(MoveKind.RAPID, 40, 40, 20)
    tp.add(MoveKind.PLUNGE, 40, 40, 0)
    tp.add(MoveKind.FEED, 50, 40, 0)
    return tp


class PathRows(FreeCADTestCase):
    def test_commands_feeds_and_planes(self) -> None:
        rows = path_build.rows_of(sample_path(arc=True), H, V, 45.0, clearance=25.0)
        commands = [(c.Name, c.Parameters) for c in path_build.path_commands(rows)]
        self.assertEqual(commands[0], ("G0", {"Z": 25.0}))
        self.assertEqual(commands[1], ("G0", {"X": 0.0, "Y": 0.0, "Z": 20.0}))
        feeds = [p.get("F") for n, p in commands if n == "G1"]
        self.assertEqual(feeds[:4], [V, H, V, H])
        names = [n for n, _ in commands]
        self.assertEqual(names[6:8], ["G18", "G3"])   # the arc in XZ, its plane before it, XY again at the end
        self.assertEqual(names[-1], "G17")
        self.assertEqual(commands[7][1]["F"], H)
        self.assertEqual(list(rows.commands()), [path_build.Cmd(n, p) for n, p in commands])

    def test_record_counts_cuts_and_moves(self) -> None:
        rows = path_build.rows_of(sample_path(), H, V, 45.0, clearance=25.0)
        made = [path_build.Cmd("(op)", {})] + list(rows.commands()) + [path_build.Cmd("G0", {"Z": 25.0})]
        rec = path_build.record(made, 1, rows)
        self.assertEqual(len(rec), len(made))
        self.assertEqual(rec.cuts(), 2)
        pts, feeds = path_build.line_moves(rec)
        self.assertEqual(len(pts), len(feeds))
        self.assertTrue(math.isinf(feeds[0]) and feeds[1] == V and feeds[2] == H and math.isinf(feeds[-1]))
        self.assertEqual(pts[-1].tolist(), [50.0, 40.0, 25.0])
        arcs = path_build.rows_of(sample_path(arc=True), H, V, 45.0, None)
        self.assertIsNone(path_build.line_moves(path_build.record(list(arcs.commands()), 0, arcs)))

    def test_unusable_word_and_cancel(self) -> None:
        rows = path_build.rows_of(sample_path(), H, V, 45.0, None)
        self.assertIsNone(path_build.unusable_row(rows, 1e9))
        rows.values[3, 2] = np.nan
        self.assertEqual(path_build.unusable_row(rows, 1e9)[:3], (3, "G1", "Z"))
        with self.assertRaises(Cancelled):
            path_build.path_commands(rows, lambda f: False)
