"""The whole tool against the stock in the simulation (api.simulate, app.simulation, the kernel's body check): the
cavity of fc_test_holder (40 mm deep) finished with a ball D4 computed without a holder, simulated with an ER32
collet chuck at 20 mm stick-out, shows its shank and holder in the stock with positions, and raises with
fail_on_gouge; computed with the holder it keeps clear of the design, but finishing from the raw block it still
drives the shank into material no op has cut (only the stock check sees that); a roughing whose stick-out is too
short for its step-down hits the layer's uncut stock above the flutes on moves where the design check sees
nothing."""
from __future__ import annotations

import numpy as np

from fc_helpers import OUT, FreeCADTestCase
from fc_test_holder import FAST, HOLDER, cavity_stl
from tmm_workbench.app.api import run_roughing, run_surface, simulate
from tmm_workbench.core.errors import TmmError


def stock_box(result) -> tuple:
    bb = result.job.Stock.Shape.BoundBox
    return bb.XMin, bb.XMax, bb.YMin, bb.YMax, bb.ZMax


class StockCollisionsInTheSimulation(FreeCADTestCase):
    def test_a_job_computed_without_the_holder_hits_the_stock(self) -> None:
        ignored = run_surface(cavity_stl(), doc_name="TmmSimStockNo", **FAST)
        report = simulate(ignored, cell=0.5, progress=False, holder=HOLDER, stick_out=20.0,
                          png_path=str(OUT / "sim_holder.png"))
        ((label, found),) = report.stock_collisions
        self.assertEqual(label, ignored.op.Label)
        self.assertGreater(found.per_piece.get("holder", 0), 0)
        self.assertEqual(found.positions.shape, (found.count, 3))
        x0, x1, y0, y1, top = stock_box(ignored)
        pos = found.positions
        self.assertTrue(np.all((pos[:, 0] >= x0) & (pos[:, 0] <= x1) & (pos[:, 1] >= y0) & (pos[:, 1] <= y1)))
        self.assertLessEqual(float(pos[:, 2].max()), top + 1e-9)
        self.assertTrue(np.all(found.depths > 0))
        self.assertIn("Tool collision with the stock", found.summary())
        self.assertIs(report.simulation.ops[0].stock, found)
        self.assertTrue((OUT / "sim_holder.png").stat().st_size > 10_000)
        with self.assertRaises(TmmError) as ctx:
            simulate(ignored, cell=0.5, progress=False, holder=HOLDER, stick_out=20.0, fail_on_gouge=True)
        self.assertIn("collision with the stock", str(ctx.exception))
        plain = simulate(ignored, cell=0.5, progress=False)   # no holder to check: nothing checked
        self.assertEqual(plain.stock_collisions, [])
        self.assertIsNone(plain.simulation.ops[0].stock)
        self.assertTrue(np.array_equal(plain.simulation.result.heights, report.simulation.result.heights))

    def test_the_holder_safe_job_keeps_clear_of_the_design_not_of_the_raw_block(self) -> None:
        safe = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmSimStockSafe", **FAST)
        report = simulate(safe, cell=0.5, progress=False)     # the op's own holder
        self.assertEqual(report.holder_collisions, [])
        ((_, found),) = report.stock_collisions
        # finishing 40 mm deep from the raw block: the shank (flutes 12 mm) meets material no op has cut, which
        # stands higher than the design anywhere it is hit
        self.assertGreater(found.per_piece.get("shank", 0), 0)
        _, _, _, _, top = stock_box(safe)
        self.assertAlmostEqual(float(found.positions[:, 2].max()), top, places=6)

    def test_a_roughing_too_short_for_its_step_down_hits_uncut_stock(self) -> None:
        rough = run_roughing(cavity_stl(), tool="endmill", diameter=6.0, step_down=18.0, stock_to_leave=1.5,
                             doc_name="TmmSimRough", progress=False)
        report = simulate(rough, cell=0.5, progress=False, holder=HOLDER, stick_out=18.5)
        ((_, found),) = report.stock_collisions
        design = dict(report.holder_collisions)
        seen = set(design[rough.op.Label].move.tolist()) if rough.op.Label in design else set()
        # the design check numbers a move by its end point, the stock check by its start
        only_stock = set((found.moves + 1).tolist()) - seen
        self.assertGreater(len(only_stock), 100)
        self.assertGreater(found.per_piece.get("holder", 0), 0)
        self.assertGreater(found.per_piece.get("shank", 0), 0)
        first = np.isin(found.moves + 1, sorted(only_stock))
        _, _, _, _, top = stock_box(rough)
        self.assertAlmostEqual(float(found.positions[first, 2].max()), top, places=6)   # the block's top, uncut
