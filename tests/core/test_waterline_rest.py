"""The Waterline's rest-only mode joins its pieces as the Surface's rest does (core.strategies.rest_joins): on a
60 deg wall 4 mm long rested with a ball D3 after a D10 finish, fewer entries from above, the same material left
on the wall, and no move below the model."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from tests.core.rest_case import after_d10
from tests.core.test_rest_steep import D3, WALL_X, wall_mesh
from tmm_workbench.core import polygons
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.strategies import waterline


def test_the_rest_only_waterline_joins_its_pieces_without_gouging() -> None:
    mesh = wall_mesh()
    case = after_d10(mesh, (WALL_X - 4.0, 0.0, WALL_X + 8.0, 4.0), 0.25, D3, 7.0, 10.0)
    grid, design, left = case.grid, case.design, case.left
    params = waterline.WaterlineParams(boundary=polygons.bounds(case.area.region), step_down=0.25, chord_tol=0.005)
    params.rest = case.area.stock(left)
    policy = LinkPolicy(10.0, 12.0, material_top=StockHeights(grid, left, D3), low_links=True)
    surface = DropSurface(mesh)
    made = {}
    for join in (False, True):
        result = waterline.compute(mesh, D3, replace(params, join_rest=join), None, surface)
        entries = sum(1 for seg in result.segments if not seg.joined)
        after = simulate(link(result.segments, policy), D3, grid, left).heights
        made[join] = (entries, after, result.diagnostics)
        assert np.nanmin(after - design) > -0.005
    assert made[True][2]["joins"] > 0 and "joins" not in made[False][2]
    assert made[True][0] < made[False][0]
    # the joins cut only what lies above the model: what the loops leave is not higher anywhere
    assert np.nanmax(made[True][1] - made[False][1]) < 1e-6
