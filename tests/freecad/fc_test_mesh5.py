"""The 'TMM 5-axis Mesh' op in a Path Job: a gently curved patch (a convex cylinder, radius 60 mm, as an STL
written here) finished with a flat end mill ToolBit at a coarse tolerance; posted through the Tarus post in joint
mode and driven back through the machine's forward kinematics (every cut's CL point reached, the joints
interpolated linearly stay on each move, no A turn inside a cut), simulated (no gouge, the scallop within the
tolerance inside the machined area); bad tools and values refused by name."""
from __future__ import annotations

import math
import re

import FreeCAD
import numpy as np

from fc_helpers import OUT, BadInputCase, FreeCADTestCase, new_doc, write_ascii_stl
from tmm_workbench.app import job as jobs
from tmm_workbench.app import registry, tools
from tmm_workbench.app.api import simulate
from tmm_workbench.app.compat import load_post
from tmm_workbench.core.post.tarus_writer import parse_args

R_CYL, HALF, TOL, D = 60.0, 12.0, 0.05, 10.0
VALUES = {"Tolerance": TOL, "TiltLimit": 24.0, "YawLimit": 30.0, "ForwardStep": 3.0}
POST_ARGS = "--no-show-editor --precision 6 --angle-precision 9 --tool-length 80"
_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


def patch_stl() -> str:
    n = 8
    xs, ys = np.linspace(-HALF, HALF, n + 1), np.linspace(-HALF, HALF, 6 * n + 1)
    z = lambda y: math.sqrt(R_CYL ** 2 - y * y)  # noqa: E731
    tris = []
    for x0, x1 in zip(xs, xs[1:]):
        for y0, y1 in zip(ys, ys[1:]):
            a, b, c, d = (x0, y0, z(y0)), (x1, y0, z(y0)), (x1, y1, z(y1)), (x0, y1, z(y1))
            tris += [(a, b, c), (a, c, d)]
    return str(write_ascii_stl(OUT / "mesh5_patch.stl", tris, "patch"))


def job_with_op(shape: str = "endmill", corner: float = 0.0, values: dict | None = None):
    doc = new_doc("TmmMesh5")
    jm = jobs.prepare_model(doc, patch_stl())
    doc.recompute()
    job = jobs.create_job(doc, jm.job_base)
    tc = jobs.set_tool(job, tools.make_tool_bit(doc, shape, D, corner), 1200 / 60, 300 / 60, 10000)
    op = registry.create("TMM_Mesh5", job, {"StlFile": jm.stl_file, **VALUES, **(values or {})})
    op.Proxy.progress_enabled = False
    doc.recompute()
    return doc, job, tc, op


def tarus_rows(text: str) -> tuple[list[str], np.ndarray]:
    """The motion word (G0/G1) and x, y, z, a, c (rad) of every motion line, modal words carried."""
    state = {"X": math.nan, "Y": math.nan, "Z": math.nan, "A": math.nan, "C": math.nan}
    names, rows, motion = [], [], "G0"
    for raw in text.splitlines():
        words = _WORD.findall(re.sub(r"\(.*?\)", "", raw))
        for k, v in words:
            if k == "G" and v in ("0", "00", "1", "01"):
                motion = f"G{int(v)}"
        if not any(k in state for k, _ in words):
            continue
        for k, v in words:
            if k in state:
                state[k] = math.radians(float(v)) if k in "AC" else float(v)
        names.append(motion)
        rows.append([state[k] for k in "XYZAC"])
    return names, np.array(rows).reshape(-1, 5)


class Mesh5Op(FreeCADTestCase):
    @classmethod
    def setUpClass(cls) -> None:
        cls.doc, cls.job, cls.tc, cls.op = job_with_op()
        cls.text = load_post("tarus").export([cls.tc, cls.op], str(OUT / "mesh5.tarus.ngc"), POST_ARGS)

    def tearDown(self) -> None:
        pass   # the class's document stays for its tests

    @classmethod
    def tearDownClass(cls) -> None:
        FreeCAD.closeDocument(cls.doc.Name)

    def test_op_computes_and_reports(self) -> None:
        op = self.op
        self.assertTrue(op.isValid(), op.getStatusString())
        d = op.Proxy.diagnostics
        self.assertGreaterEqual(d["passes"], 2)
        self.assertIn(f"{d['passes']} passes, {d['cc_points']} CC points cut", op.Mesh5Summary)
        self.assertEqual(d["unfinished"], [])   # a convex patch: every CC point has a posture
        self.assertNotIn("empty C-space", op.Mesh5Summary)

    def test_tarus_joints_reach_every_cut_point_stay_on_their_moves_and_never_turn_a_in_a_cut(self) -> None:
        machine, options = parse_args(POST_ARGS)
        names, j = tarus_rows(self.text)
        self.assertTrue(np.isfinite(j[1:]).all())
        tips, axes = machine.forward_path(j)
        # every CL point of every cut is a machine position, in order, with its tool axis
        rows = []
        for seg in self.op.Proxy.segments:
            for t, a in zip(seg.tips, seg.axes):
                d = np.linalg.norm(tips - t, axis=1)
                k = int(np.argmin(np.where(np.arange(len(d)) > (rows[-1] if rows else -1), d, np.inf)))
                self.assertLess(d[k], 1e-4, t)
                self.assertLess(np.linalg.norm(axes[k] - a), 1e-6)
                rows.append(k)
            rows.append(-1)
        # the control interpolates the joints linearly: every G1 stays within the post's tip tolerance of its
        # straight line (the joint-mode pieces)
        for k in range(1, len(j)):
            if names[k] != "G1":
                continue
            s = np.linspace(0.0, 1.0, 11)[1:-1, None]
            mid = machine.forward_path((1 - s) * j[k - 1] + s * j[k])[0]
            line = (1 - s) * tips[k - 1] + s * tips[k]
            self.assertLess(np.linalg.norm(mid - line, axis=1).max(), options.tip_tolerance + 1e-5, k)
        # no A turn inside a cut: from the first to the last CL point of a segment no move swings the tilted
        # tool round (A by more than 90 deg with the tool over 2 deg from the vertical at both ends) and A never
        # unwinds (less than a whole turn in all); only A turns at C = 0 (a pole pass) move nothing
        firsts = [rows[i] for i in range(len(rows)) if rows[i] >= 0 and (i == 0 or rows[i - 1] == -1)]
        lasts = [rows[i] for i in range(len(rows)) if rows[i] >= 0 and rows[i + 1] == -1]
        self.assertEqual(len(firsts), len(self.op.Proxy.segments))
        for a, b in zip(firsts, lasts):
            turn = np.abs(np.diff(j[a:b + 1, 3]))
            tilted = np.minimum(j[a:b, 4], j[a + 1:b + 1, 4]) > math.radians(2.0)
            self.assertTrue((turn[tilted] < math.pi / 2).all(), (a, b))
            self.assertLess(turn[tilted].sum(), 2 * math.pi)

    def test_apt_cl_carries_every_cut_point_with_its_axis(self) -> None:
        text = load_post("apt_cl").export([self.tc, self.op], str(OUT / "mesh5.apt"), "--no-show-editor")
        goto = np.array([[float(v) for v in ln[5:].split(",")] for ln in text.splitlines()
                         if ln.startswith("GOTO/")]).reshape(-1, 6)
        for seg in self.op.Proxy.segments:
            for t, a in zip(seg.tips, seg.axes):
                k = int(np.argmin(np.linalg.norm(goto[:, :3] - t, axis=1)))
                self.assertLess(np.linalg.norm(goto[k, :3] - t), 1e-3)
                self.assertLess(np.linalg.norm(goto[k, 3:] - a), 1e-5)

    def test_simulated_stock_has_no_gouge_and_the_scallop_within_the_tolerance(self) -> None:
        report = simulate(self.job, cell=0.2, tolerance=TOL, progress=False)
        sim = report.simulation
        dev = sim.comparison.deviation
        self.assertGreaterEqual(float(np.nanmin(dev)), -0.01)
        self.assertEqual(report.collisions, [])
        X, Y = np.meshgrid(sim.grid.xs(), sim.grid.ys())
        # inside the machined area: a cutter radius and more from the passes' ends, away from the side edges
        inside = (np.abs(X) < HALF - D / 2 - 1.0) & (np.abs(Y) < HALF - 3.0)
        slope = np.cos(np.arcsin(np.abs(Y[inside]) / R_CYL))   # vertical deviation = normal / cos(slope)
        self.assertLessEqual(float(np.max(dev[inside] * slope)), TOL + 0.1 * TOL + 1e-3)
        self.assertGreater(float(np.max(dev[inside])), 0.3 * TOL)   # scallops there, near the tolerance


class Mesh5BadInput(BadInputCase):
    def setUp(self) -> None:
        self.doc, self.job, self.tc, self.op = job_with_op(values={"ForwardStep": 30.0, "Tolerance": 0.5})
        self.assertTrue(self.op.isValid(), self.op.getStatusString())

    def test_a_ball_end_mill_is_refused_naming_it(self) -> None:
        self.tc.Tool = tools.make_tool_bit(self.doc, "ballend", D)
        self.assertFails("ball", "not taken by 5-axis mesh finishing", "flat end mill or a bull-nose")

    def test_tolerance_not_above_zero_is_refused(self) -> None:
        self.op.Tolerance = 0.0
        self.assertFails("tolerance", "got 0")

    def test_a_tilt_limit_outside_the_machine_is_refused(self) -> None:
        self.op.TiltLimit = 60.0
        self.assertFails("tilt limit 60 deg is outside the machine's tilt range C 0..45 deg")
