"""Stock simulation of a Job (app.simulation, api.simulate): a 3-axis TMM Surface Job on the bump and seed
001's 5-axis Multipoint Job, each simulated in its stock and compared with its model (no gouge, scallops
left, the heat map written), the same paths lowered by 0.05 mm reported as gouges (and raised with
fail_on_gouge), the op's CycleTime replaced by TMM's estimate (3-axis: feeds and rapid rates; 5-axis: the
Tarus post's joint-speed estimate), and bad input refused by name."""
from __future__ import annotations

import unittest
from pathlib import Path as Path_

import Path

from fc_helpers import OUT, FreeCADTestCase, bump_stl, close_all, job_with_op, new_doc
from fc_test_multipoint import FAST, seed_net
from tmm_workbench.app import simulation
from tmm_workbench.app.api import run_multipoint, simulate
from tmm_workbench.core.errors import TmmError


def hms_seconds(text: str) -> int:
    h, m, s = (int(v) for v in text.split(":"))
    return 3600 * h + 60 * m + s


def lowered(op, dz: float = 0.05) -> None:
    """The op's Path with every feed move 0.05 mm lower (rapids as they were)."""
    out = []
    for c in op.Path.Commands:
        p = dict(c.Parameters)
        if c.Name in ("G1", "G01") and "Z" in p:
            p["Z"] -= dz
        out.append(Path.Command(c.Name, p))
    op.Path = Path.Path(out)


class Simulate3Axis(FreeCADTestCase):
    def test_surface_job(self) -> None:
        doc = new_doc("TmmSim3")
        job, tc, op = job_with_op(doc, str(bump_stl()), values={"StepOver": 1.0, "SampleStep": 0.5})
        self.assertTrue(op.isValid(), op.getStatusString())
        png = OUT / "sim3.png"
        r = simulate(job, cell=0.1, tolerance=0.01, png_path=png, progress=False)
        self.assertFalse(r.gouged, (r.min_deviation, r.gouge_cells))
        self.assertGreater(r.min_deviation, -0.01)
        self.assertGreater(r.max_left, 0.01)          # ball D4 at 1 mm step-over leaves cusps (0.063 mm)
        self.assertGreater(r.removed_volume, 0)
        self.assertEqual(r.collisions, [])
        # per slope band and per XY bucket: each set covers the compared cells once, and each region's
        # extremes lie within the whole's
        for prefix in ("slope", "bucket"):
            part = {k: v for k, v in r.regions.items() if k.startswith(prefix)}
            self.assertGreater(len(part), 1, prefix)
            self.assertEqual(sum(v["cells"] for v in part.values()), r.simulation.comparison.overall.cells)
        self.assertTrue(all(v["max_left"] <= r.max_left + 1e-12 for v in r.regions.values()))
        self.assertAlmostEqual(max(v["max_left"] for v in r.regions.values()), r.max_left, places=12)
        self.assertTrue(png.is_file() and png.stat().st_size > 20_000)
        banded = simulate(job, cell=0.1, tolerance=0.01, png_path=OUT / "sim3_band.png", png_band=0.01,
                          progress=False)   # TMM Simulate's colour band in the picture
        self.assertTrue(Path_(banded.png).is_file() and banded.max_left == r.max_left)
        with self.assertRaises(TmmError) as ctx:
            simulate(job, cell=0.1, png_band=0.01, progress=False)
        self.assertIn("png_band colours the heat map: give png_path as well", str(ctx.exception))
        # the op's CycleTime is TMM's estimate, and the report's
        self.assertAlmostEqual(hms_seconds(op.CycleTime), round(simulation.op_cycle_seconds(op)), delta=1)
        self.assertAlmostEqual(r.cycle_seconds, simulation.op_cycle_seconds(op), places=6)
        lowered(op)
        bad = simulate(op, cell=0.1, progress=False)
        self.assertTrue(bad.gouged)
        self.assertLess(bad.min_deviation, -0.04)
        with self.assertRaises(TmmError) as ctx:
            simulate(op, cell=0.1, progress=False, fail_on_gouge=True)
        self.assertIn("gouged", str(ctx.exception))
        close_all()

    def test_bad_input(self) -> None:
        doc = new_doc("TmmSimBad")
        job, _, op = job_with_op(doc, str(bump_stl()))
        for kwargs, text in ((dict(cell=0.0), "cell"), (dict(cell=float("nan")), "cell"),
                             (dict(tolerance=-1.0), "tolerance"), (dict(cell=1e-4), "simulation cells")):
            with self.assertRaises(TmmError) as ctx:
                simulate(job, progress=False, **kwargs)
            self.assertIn(text, str(ctx.exception))
        empty = doc.addObject("App::FeaturePython", "Loose")
        with self.assertRaises(TmmError) as ctx:
            simulate(empty, progress=False)
        self.assertIn("not in a Job", str(ctx.exception))
        close_all()


class FreeCADArcs(FreeCADTestCase):
    def test_a_path_with_arcs_is_simulated_as_chords(self) -> None:
        """A Path object in the Job with a G2 full circle (as FreeCAD's Profile writes): read as chords within
        1 um, and the flat end mill's groove in the stock is the circle's (depth and radius)."""
        import numpy as np

        doc = new_doc("TmmArcs")
        job, tc, op = job_with_op(doc, str(bump_stl()), shape="endmill", diameter=2.0)
        arc = doc.addObject("Path::Feature", "Circle")
        arc.addProperty("App::PropertyLink", "ToolController", "Path")
        arc.ToolController = tc
        top = job.Stock.Shape.BoundBox.ZMax
        arc.Path = Path.Path([Path.Command("G0", {"X": 15.0, "Y": 10.0, "Z": top + 5}),
                              Path.Command("G1", {"X": 15.0, "Y": 10.0, "Z": top - 0.5, "F": 5.0}),
                              Path.Command("G2", {"X": 15.0, "Y": 10.0, "Z": top - 0.5, "I": -5.0, "J": 0.0}),
                              Path.Command("G0", {"X": 15.0, "Y": 10.0, "Z": top + 5})])
        job.Operations.addObject(arc)
        tp, feeds = simulation.toolpath_and_feeds(arc)
        pts = tp.points()[2:-1]
        self.assertGreater(len(pts), 100)
        np.testing.assert_allclose(np.hypot(pts[:, 0] - 10.0, pts[:, 1] - 10.0), 5.0, atol=1e-9)
        r = simulate(arc, cell=0.1, progress=False)
        sim = r.simulation
        h, xs, ys = sim.result.heights, sim.grid.xs(), sim.grid.ys()
        X, Y = np.meshgrid(xs, ys)
        rho = np.hypot(X - 10.0, Y - 10.0)
        self.assertTrue(np.allclose(h[np.abs(rho - 5.0) < 0.9], top - 0.5))      # under the 2 mm tool
        self.assertTrue(np.allclose(h[(rho < 3.9) | (rho > 6.1)], top))          # beside it: untouched
        # fed down 5.5 mm and round the circle at 5 mm/s, rapid up 5.5 mm
        self.assertAlmostEqual(r.ops[0].cycle_seconds, (5.5 + 2 * np.pi * 5.0) / 5.0 + 5.5 / simulation_rapid(tc),
                               delta=1e-3)
        close_all()


def simulation_rapid(tc) -> float:
    from tmm_workbench.core.sim.cycle_time import DEFAULT_RAPID_MM_S

    return tc.VertRapid.Value or DEFAULT_RAPID_MM_S


class OptimalCutter(FreeCADTestCase):
    def test_compare_cutters_from_tool_bits(self) -> None:
        from tmm_workbench.app import tools
        from tmm_workbench.app.api import compare_cutters

        doc = new_doc("TmmOptimal")
        ball = tools.make_tool_bit(doc, "ballend", 4.0)
        bull = tools.make_tool_bit(doc, "bullnose", 4.0, 1.0)
        out = compare_cutters(str(bump_stl()), [ball, bull], stepover=1.0, sample_step=0.5, cell=0.1)
        self.assertEqual({s.label for s in out.scores}, {ball.Label, bull.Label})
        self.assertEqual(len(out.reasons), 2)
        self.assertTrue(all(s.gouge <= 0.01 for s in out.scores))
        with self.assertRaises(TmmError):
            compare_cutters(str(bump_stl()), [ball], stepover=0.0, sample_step=0.5)
        close_all()


class Simulate5Axis(FreeCADTestCase):
    def test_multipoint_job(self) -> None:
        r5 = run_multipoint(seed_net(), doc_name="TmmSim5", **FAST)
        png = OUT / "sim5.png"
        r = simulate(r5, cell=0.5, tolerance=0.01, png_path=png, progress=False)
        self.assertFalse(r.gouged, (r.min_deviation, r.gouge_cells))
        self.assertGreater(r.max_left, 0.05)           # 18 mm between passes
        self.assertTrue(r.ops[0].five_axis)
        self.assertTrue(png.is_file())
        tarus = simulation._tarus_cycle_time(r5.op)
        self.assertAlmostEqual(r.cycle_seconds, tarus, places=6)
        self.assertAlmostEqual(hms_seconds(r5.op.CycleTime), round(tarus), delta=1)
        lowered(r5.op)
        self.assertTrue(simulate(r5.op, cell=0.5, progress=False).gouged)
        close_all()


if __name__ == "__main__":
    unittest.main()
