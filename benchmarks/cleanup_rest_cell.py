"""The clean-up's rest found on coarser cells than the simulation judges it on (the FreeCAD op finds its rest on
the cells of the Job's stock heights: app.simulation.known_cell): tests/core/crease_case.py finished with a ball
D10 at 0.6 mm step-over (the FreeCAD test's), its rest for a ball D2 found on cells of 0.25, 0.125 and 0.1 mm (a
quarter, an eighth and a tenth of the D2's radius), cleaned up (Pattern Pencil, PencilSource CleanUp, PencilPasses
0, sample step 0.25 mm), all simulated on 0.1 mm cells; printed: cells more than 0.01 mm above the design where the
D2 reaches, the largest left there, the lowest deviation.

Run: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/cleanup_rest_cell.py
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.core.crease_case import HEIGHT, WALL_H, WIDTH, crease_mesh  # noqa: E402
from tmm_workbench.core import polygons  # noqa: E402
from tmm_workbench.core.footprint import rest  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.surface.params import SurfaceParams  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

TOL, BOX = 0.01, (0.0, 0.0, WIDTH, HEIGHT)
D10, D2 = Cutter.ball(10), Cutter.ball(2)


def main() -> None:
    mesh = crease_mesh()
    top = WALL_H + 1.0
    policy = LinkPolicy(top + 3, top + 7)
    finish = raster_drop.compute_surface_toolpath(mesh, D10, SurfaceParams(boundary=BOX, stepover=0.6,
                                                                           sample_step=0.25), policy)
    fine = Grid.covering(*BOX, 0.1)
    design = mesh_heights(mesh, fine)
    envelope = rest.tool_envelope(mesh, D2, fine)
    reach = np.isfinite(design) & (envelope - design <= TOL)
    left_fine = simulate(finish, D10, fine, box_heights(fine, top)).heights
    print(f"{'rest cells mm':>14s} {'cells > tol':>12s} {'max left':>9s} {'min dev':>9s}")
    for cell in (0.25, 0.125, 0.1):
        grid = Grid.covering(*BOX, cell)
        left = simulate(finish, D10, grid, box_heights(grid, top)).heights
        area = rest.rest_area(left, mesh_heights(mesh, grid), rest.tool_envelope(mesh, D2, grid), grid, TOL,
                              D2.radius)
        params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, sample_step=0.25,
                               rest=area.stock(left), pattern="pencil", pencil_passes=0, pencil_source="cleanup",
                               cleanup_reference=D10, stepover=2 * math.sqrt(2 * D2.radius * 0.8 * TOL), cusp=TOL)
        path = link(raster_drop.compute(mesh, D2, params).segments,
                    LinkPolicy(policy.safe_height, policy.clearance_height,
                               material_top=StockHeights(grid, left, D2), low_links=True))
        after = simulate(path, D2, fine, left_fine).heights - design
        there = np.where(reach, after, np.nan)
        print(f"{cell:14.3f} {int(np.sum(there > TOL)):12d} {np.nanmax(there):9.4f} {np.nanmin(after):9.4f}")


if __name__ == "__main__":
    main()
