"""Seed 000's clean-up in the Surface op (Pattern 'Pencil', PencilSource 'CleanUp', Region 'Rest') on the crease and
groove of tests/core/crease_case.py: finished with a ball D10 in a Job, then cleaned up with a ball D2; the Job
simulated: where the D2 reaches, what is left drops to the tolerance, no gouge, no rapid through stock; the pass
along the wall's foot at the D2's exact two-contact x; bad values refused by name."""
from __future__ import annotations

import math
import re

import numpy as np

from fc_helpers import FreeCADTestCase, mesh_stl
from tests.core.crease_case import crease_mesh, fold_x
from tmm_workbench.app.api import run_surface, simulate
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.rest import tool_envelope
from tmm_workbench.core.sim.stock import mesh_heights

COMMON = dict(boundary="model", margin=0.0, sample_step=0.25, progress=False, post=None)
STEP_D2 = 2 * math.sqrt(2 * 1.0 * 0.008)   # a cusp of 0.008 mm between D2 passes


def crease_stl() -> str:
    return mesh_stl(crease_mesh(), "crease_groove")


def finished(doc_name: str):
    return run_surface(crease_stl(), tool="ballend", diameter=10.0, stepover=0.6, doc_name=doc_name, **COMMON)


class CleanUpInTheSurface(FreeCADTestCase):
    def test_the_strips_of_a_d10_finish_cleaned_up_with_a_d2(self) -> None:
        big = finished("TmmCleanUp")
        before = simulate(big.job, cell=0.1, progress=False)
        clean = run_surface(job=big.job, tool="ballend", diameter=2.0, stepover=STEP_D2, region="rest",
                            pattern="pencil", pencil_source="cleanup", pencil_passes=0, **COMMON)
        op = clean.op
        self.assertEqual((op.Pattern, op.PencilSource, op.Region), ("Pencil", "CleanUp", "Rest"))
        after = simulate(big.job, cell=0.1, progress=False)
        self.assertFalse(after.gouged, after.min_deviation)
        self.assertEqual(after.collisions, [])
        sim = after.simulation
        design = mesh_heights(op.Proxy.mesh, sim.grid)
        reach = np.isfinite(design) & (tool_envelope(op.Proxy.mesh, op.Proxy.cutter(), sim.grid) - design <= 0.01)
        left_before = np.sum(reach & (before.simulation.comparison.deviation > 0.01))
        left_after = np.sum(reach & (sim.comparison.deviation > 0.01))
        self.assertGreater(left_before, 5000)
        # within the tolerance wherever the D2 reaches, the groove's ends too (the rest found on cells of an
        # eighth of the D2's radius: on a quarter, 3 cells of up to 0.0113 mm stayed where the groove's bottom
        # meets its sloped ends)
        self.assertEqual(left_after, 0, float(np.nanmax(np.where(reach, sim.comparison.deviation, np.nan))))
        # the pass along the wall's foot: on the floor, where the D2 touches the floor and the wall at once (moves
        # both of whose ends lie there, most of the wall's 40 mm long)
        pts = op.Proxy.toolpath.points()
        at = (np.abs(pts[:, 0] - fold_x(1.0)) < 0.005) & (np.abs(pts[:, 2]) < 0.01)
        along = np.abs(np.diff(pts[:, 1]))[at[:-1] & at[1:]]
        self.assertGreater(float(along.sum()), 30.0)
        # the strips' summary with the rest's in the op's RestReport: how many, how long, the points placed
        found = re.search(r"; clean-up strips (\d+) mm2 .*, (\d+) curve\(s\) (\d+) mm long; (\d+) of (\d+) curve "
                          r"points placed in their crease, (\d+) flank pass", op.RestReport)
        self.assertIsNotNone(found, op.RestReport)
        area, curves, length, placed, points, passes = map(int, found.groups())
        self.assertTrue(op.RestReport.startswith("rest "), op.RestReport)
        self.assertGreater(area, 100)
        self.assertGreaterEqual(curves, 2)                        # the wall's foot and the groove at least
        self.assertGreater(length, 40 + 25)
        self.assertGreater(placed, 0.8 * points)
        self.assertGreater(passes, 0)
        print(f"TMM-FC-NOTE cleanup: {op.RestReport}; cells > 0.01: {left_before} -> {left_after}")

    def test_bad_values_are_refused_by_name(self) -> None:
        big = finished("TmmCleanUpBad")
        cases = [(dict(pencil_source="cleanup"), "pencil_source='cleanup' needs region='rest'"),
                 (dict(pencil_source="cleanup", region="rest", diameter=12.0),
                  "the clean-up tool must be at most 10 mm"),
                 (dict(pencil_source="cleaning", region="rest"), "pencil_source must be"),
                 (dict(pencil_source="cleanup", region="rest", pencil_passes=51),
                  "pencil_passes must be a whole number in [0, 50], got 51")]
        for kwargs, said in cases:
            args = {**dict(tool="ballend", diameter=2.0, pattern="pencil"), **COMMON, **kwargs}
            with self.subTest(kwargs=kwargs), self.assertRaises(TmmError) as ctx:
                run_surface(job=big.job, **args)
            self.assertIn(said, str(ctx.exception))
