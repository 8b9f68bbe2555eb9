"""The holder guard against the in-process stock (core.sim.stock_bodies) in a Job: a plate roughed only down to
20 mm above it (final_z), so that 20 mm of stock stands over the whole plate, far from any wall of the model;
then a ball D4 on a 20 mm stick-out in an ER32 collet chuck finishes it. The model alone never brings the shank
near (the same op in a Job of its own keeps its clearance everywhere); after the roughing the op lifts the tool
where the shank would enter the stock, and the Job's simulation finds neither the shank nor the holder in the
stock (its body check, the planner's verification)."""
from __future__ import annotations

from fc_helpers import OUT, FreeCADTestCase, write_ascii_stl
from tmm_workbench.app.api import run_roughing, run_surface, simulate

HOLDER = "SK40 ER32x70"
FINISH = dict(tool="ballend", diameter=4.0, stepover=2.0, sample_step=0.5, boundary="model", margin=-4.0,
              holder=HOLDER, stick_out=20.0, progress=False, post=None)


def plate_stl() -> str:
    """A 30 x 20 mm plate, its top at z 0, 5 mm thick."""
    x0, y0, x1, y1, z0, z1 = -15.0, -10.0, 15.0, 10.0, -5.0, 0.0
    c = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = [t for a, b, cc, d in quads for t in ((c[a], c[b], c[cc]), (c[a], c[cc], c[d]))]
    return str(write_ascii_stl(OUT / "plate.stl", tris, "plate"))


class StockAwareHolder(FreeCADTestCase):
    def test_after_a_roughing_the_shank_keeps_clear_of_the_stock_it_left(self) -> None:
        alone = run_surface(plate_stl(), doc_name="TmmStockHolderAlone", **FINISH)
        self.assertIn("keep their clearance everywhere", alone.op.HolderReport)
        rough = run_roughing(plate_stl(), tool="endmill", diameter=10.0, stock_above=30.0, final_z=20.0,
                             doc_name="TmmStockHolder", progress=False, post=None)
        after = run_surface(job=rough.job, **FINISH)
        self.assertIn("points raised where the shank or holder would come closer", after.op.HolderReport)
        zs = [c.Parameters["Z"] for c in after.op.Path.Commands if "Z" in c.Parameters]
        self.assertGreater(min(zs), 1.0)   # nowhere down at the plate: the stock stands 20 mm over all of it
        report = simulate(rough.job, cell=0.5, progress=False)
        self.assertEqual(report.stock_collisions, [], [c.summary() for _, c in report.stock_collisions])
        self.assertEqual(report.holder_collisions, [])
