"""Pencil and multi-pencil in the Surface op (Pattern 'Pencil', app.pencil_source) on the sign of tests/core/sign.py:
finished with a radiused cutter, then a ball D1.5 along the letters' outline (a Part object of the drawing's
loops), along the creases it finds itself, and along a footprint file; the Job simulated: less left, no gouge, no
rapid through stock; bad values refused by name."""
from __future__ import annotations

import FreeCAD
import Part

from fc_helpers import OUT, FreeCADTestCase, mesh_stl
from tests.core.sign import outlines, sign_mesh
from tmm_workbench.app.api import run_surface, simulate
from tmm_workbench.core.errors import TmmError

COMMON = dict(boundary="model", margin=0.0, sample_step=0.5, progress=False, post=None)


def sign_stl() -> str:
    return mesh_stl(sign_mesh(0.5), "sign")


def finished(doc_name: str):
    return run_surface(sign_stl(), tool="bullnose", diameter=6.0, corner_radius=1.5, stepover=0.8,
                       doc_name=doc_name, **COMMON)


def drawing(doc) -> object:
    wires = [Part.makePolygon([FreeCAD.Vector(x, y, 0) for x, y in loop]) for loop in outlines()]
    obj = doc.addObject("Part::Feature", "Lettering")
    obj.Shape = Part.makeCompound(wires)
    return obj


class PencilInTheSurface(FreeCADTestCase):
    def test_pencil_along_the_outline_the_creases_and_a_footprint_file(self) -> None:
        big = finished("TmmPencil")
        before = simulate(big.job, cell=0.2, progress=False)
        outline = run_surface(job=big.job, tool="ballend", diameter=1.5, pattern="pencil", pencil_source="outline",
                              pencil_curve=drawing(big.doc), pencil_side="inside", pencil_passes=2, stepover=0.4,
                              **COMMON)
        self.assertGreater(len(outline.op.Path.Commands), 100)
        after = simulate(big.job, cell=0.2, progress=False)
        self.assertFalse(after.gouged, after.min_deviation)
        self.assertEqual(after.collisions, [])
        self.assertLess(after.remaining_volume, 0.8 * before.remaining_volume)
        creases = run_surface(job=big.job, tool="ballend", diameter=1.5, pattern="pencil", **COMMON)
        self.assertGreater(len(creases.op.Path.Commands), 100)
        footprint = OUT / "sign.fp"
        footprint.write_text("10 20 0\n30 20 0\n30 25 0\n50 10 1\n60 10 0\n")
        filed = run_surface(job=big.job, tool="ballend", diameter=1.5, pattern="pencil", pencil_source="file",
                            pencil_file=str(footprint), **COMMON)
        xs = [c.Parameters["X"] for c in filed.op.Path.Commands if c.Name == "G1" and "X" in c.Parameters]
        self.assertAlmostEqual(min(xs), 10.0, places=6)
        self.assertAlmostEqual(max(xs), 60.0, places=6)
        self.assertFalse(simulate(big.job, cell=0.2, progress=False).gouged)

    def test_bad_values_are_refused_by_name(self) -> None:
        big = finished("TmmPencilBad")
        bad = OUT / "bad.fp"
        bad.write_text("0 0 0\n1 nan 0\n")
        line = big.doc.addObject("Part::Feature", "OpenStroke")
        line.Shape = Part.makePolygon([FreeCAD.Vector(10, 10, 0), FreeCAD.Vector(30, 10, 0)])
        cases = [(dict(pencil_passes=-1), "pencil_passes must be a whole number in [0, 50], got -1"),
                 (dict(pencil_curve=drawing(big.doc)), "pencil_curve is used with pencil_source='outline' only"),
                 (dict(pencil_source="outline"), "pencil_source='outline' needs pencil_curve="),
                 (dict(pencil_source="outline", pencil_curve=line), "pencil side 'outside' needs closed loops"),
                 (dict(pencil_side="inside"), "pencil_side is used with pencil_source='outline' only"),
                 (dict(pencil_source="file"), "pencil_source='file' needs pencil_file="),
                 (dict(pencil_source="file", pencil_file=str(bad)), "bad.fp line 2: x and y must be finite"),
                 (dict(pattern="zigzag", pencil_passes=2), "pencil_passes is used with pattern='pencil' only"),
                 (dict(stepover_mode="adaptive", cusp=0.01), "the pencil pattern spaces its passes")]
        for kwargs, said in cases:
            args = {**dict(tool="ballend", diameter=1.5, pattern="pencil"), **COMMON, **kwargs}
            with self.subTest(kwargs=kwargs), self.assertRaises(TmmError) as ctx:
                run_surface(job=big.job, **args)
            self.assertIn(said, str(ctx.exception))
