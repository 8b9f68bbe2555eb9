"""Rest machining in the Surface op (Region 'Rest', app.rest_source): the cavity of tests/core/cavity.py finished
with a ball D10, then a ball D3 added to the Job with region='rest'. It cuts only where the D10 left more than the
tolerance that the D3 reaches (the simulation of the whole Job: what is left there drops to the tolerance, no
gouge, no rapid through stock), with a path a fraction of a full D3 finish; from a reference tool as well; the
report and the marks for the view; bad values refused by name with no path."""
from __future__ import annotations

import math

import FreeCAD
import numpy as np

from fc_helpers import FreeCADTestCase, reopened
from fc_test_holder import cavity_stl
from tmm_workbench.app import work_estimate
from tmm_workbench.app.api import run_surface, simulate
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.rest import tool_envelope
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.toolpath import MoveKind

HALF = dict(boundary="model", margin=0.0, sample_step=0.5, progress=False, post=None)
STEP_D3 = 2 * math.sqrt(2 * 1.5 * 0.008)   # a cusp of 0.008 mm between D3 passes


def feed_length(tp) -> float:
    p = tp.points()
    feed = np.array([m.kind is MoveKind.FEED for m in tp.moves[1:]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1)[feed].sum())


def finished(doc_name: str):
    return run_surface(cavity_stl(), tool="ballend", diameter=10.0, stepover=0.6, doc_name=doc_name, **HALF)


class RestInTheSurface(FreeCADTestCase):
    def test_the_rest_of_a_d10_finish_with_a_d3(self) -> None:
        big = finished("TmmRest")
        before = simulate(big.job, cell=0.25, progress=False)
        rest = run_surface(job=big.job, tool="ballend", diameter=3.0, stepover=STEP_D3, region="rest", **HALF)
        op = rest.op
        self.assertIn("rest", op.RestReport)
        self.assertGreater(len(op.RestRegions), 100)
        area = op.Proxy.rest.area
        self.assertGreater(area.volume_before, 5 * area.volume_after)
        after = simulate(big.job, cell=0.25, progress=False)
        self.assertFalse(after.gouged, after.min_deviation)
        self.assertEqual(after.collisions, [])
        # where the D3 reaches the model within the tolerance, what is left is the tolerance (sim cells read over)
        sim = after.simulation
        design = mesh_heights(op.Proxy.mesh, sim.grid)
        reach = np.isfinite(design) & (tool_envelope(op.Proxy.mesh, op.Proxy.cutter(), sim.grid) - design <= 0.01)
        dev = sim.comparison.deviation
        self.assertLess(np.sum(reach & (dev > 0.012)), 0.001 * reach.sum())
        self.assertGreater(np.sum(reach & (before.simulation.comparison.deviation > 0.012)), 1000)
        full = run_surface(job=big.job, tool="ballend", diameter=3.0, stepover=STEP_D3, **HALF)
        # (0.64: its loops take the cusps the D10's raster leaves on the walls, judged along the normal; 0.5 before)
        self.assertLess(feed_length(op.Proxy.toolpath), 0.7 * feed_length(full.op.Proxy.toolpath))
        told = work_estimate.estimate(op)   # after a run: over the rest it found and its slopes' loops
        found, op.Proxy.rest = op.Proxy.rest, None
        boxed = work_estimate.estimate(op)  # before: over the box
        op.Proxy.rest = found
        # (0.94: the loops' bound counts every sloped cell the D3 reaches along the normal as left by the passes, the
        # walls' cusps the D10 leaves; 0.58 when the rest judged its reach vertically and took no walls)
        self.assertLess(told.cut_length, boxed.cut_length)
        op = reopened(rest.doc, op, "rest.FCStd")   # the report and marks are saved with the op
        self.assertEqual((op.Region, op.RestFrom, len(op.RestRegions) > 100), ("Rest", "EarlierOps", True))

    def test_the_rest_of_a_reference_tool(self) -> None:
        big = finished("TmmRestRef")
        ref = run_surface(job=big.job, tool="ballend", diameter=3.0, stepover=STEP_D3, region="rest",
                          rest_from="reference_tool", rest_reference=big.op.ToolController, **HALF)
        area = ref.op.Proxy.rest.area
        self.assertGreater(area.volume_before, 5 * area.volume_after)
        self.assertEqual(ref.op.RestReference, big.op.ToolController)

    def test_bad_values_are_refused_by_name_and_leave_no_path(self) -> None:
        big = finished("TmmRestBad")
        small = run_surface(job=big.job, tool="ballend", diameter=3.0, stepover=1.0, **HALF)
        cases = [(dict(rest_tolerance=0.0), "rest_tolerance must be in (0, 10] mm, got 0"),
                 (dict(rest_from="reference_tool", rest_reference=small.op.ToolController, diameter=10.0),
                  "the reference tool ball D3 is smaller than the rest tool"),
                 (dict(rest_reference=big.op.ToolController), "rest_reference is used with rest_from='reference_"),
                 (dict(rest_from="reference_tool"), "rest_from='reference_tool' needs rest_reference="),
                 (dict(rest_from="somewhere"), "rest_from must be"),
                 (dict(region=None, rest_tolerance=0.02), "rest_tolerance is used with region='rest' only")]
        for kwargs, said in cases:
            args = {**dict(tool="ballend", diameter=3.0, stepover=1.0, region="rest"), **HALF, **kwargs}
            with self.subTest(kwargs=kwargs), self.assertRaises(TmmError) as ctx:
                run_surface(job=big.job, **args)
            self.assertIn(said, str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:   # a new Job: no earlier op left anything
            run_surface(cavity_stl(), tool="ballend", diameter=3.0, region="rest", doc_name="TmmRestNone", **HALF)
        self.assertIn("no earlier operation of the Job has a path", str(ctx.exception))
        self.assertNotIn("TmmRestNone", FreeCAD.listDocuments())


class RestInTheWaterline(FreeCADTestCase):
    def test_the_waterline_cuts_only_the_rest_on_the_walls(self) -> None:
        from tmm_workbench.app.api import run_waterline

        big = finished("TmmRestWl")
        rest = run_waterline(job=big.job, tool="ballend", diameter=3.0, step_down=1.0, rest=True, progress=False,
                             post=None)
        self.assertIn("rest", rest.op.RestReport)
        after = simulate(big.job, cell=0.25, progress=False)   # the finish and the rest's loops
        full = run_waterline(job=big.job, tool="ballend", diameter=3.0, step_down=1.0, progress=False, post=None)
        # (the D10 raster leaves its passes 11 mm apart in z on the walls along it: the rest is most of those walls)
        self.assertLess(feed_length(rest.op.Proxy.toolpath), 0.95 * feed_length(full.op.Proxy.toolpath))
        self.assertFalse(after.gouged, after.min_deviation)
        self.assertEqual(after.collisions, [])
        with self.assertRaises(TmmError) as ctx:
            run_waterline(job=big.job, tool="ballend", diameter=3.0, rest_tolerance=0.02, progress=False, post=None)
        self.assertIn("rest_tolerance is used with rest=True only", str(ctx.exception))
