"""The steep part of a rest (core.strategies.rest_steep): the split by the passes' vertical cusp, the waterline
levels spaced by the cusp on the wall, and a 75 deg wall finished with a ball D10 then rested with a ball D3:
where the D3 reaches the wall, what is left is within the tolerance with the waterline, not with the raster
alone."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.rest_case import after_d10
from tmm_workbench.core import polygons
from tmm_workbench.core.footprint import rest
from tmm_workbench.core.footprint.reach import gentle_cosine, reach_excess
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.strategies import raster_drop, rest_order, rest_steep
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

TOL = 0.01
D3 = Cutter.ball(3)


WALL_DEG, WALL_X, WALL_H = 60.0, 10.0, 6.0


def wall_mesh(deg: float = WALL_DEG) -> TriMesh:
    """A floor meeting a `deg` wall along y (from x = 10) up to a plateau 6 mm high: a height field on 0.25 mm."""
    xs = np.unique(np.concatenate([np.arange(0.0, 20.01, 0.25),
                                   [WALL_X, WALL_X + WALL_H / math.tan(math.radians(deg))]]))
    ys = np.arange(0.0, 10.01, 0.25)
    X, Y = np.meshgrid(xs, ys)
    Z = np.clip((X - WALL_X) * math.tan(math.radians(deg)), 0.0, WALL_H)
    nx, ny = len(xs), len(ys)
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    return TriMesh(np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]),
                   np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])]), "wall")


def ramp(slope_deg: float, along_y: bool = False) -> tuple[Grid, np.ndarray]:
    grid = Grid.covering(0.0, 0.0, 10.0, 10.0, 0.25)
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    return grid, (Y if along_y else X) * math.tan(math.radians(slope_deg))


def test_the_steep_cells_are_the_sloped_ones_the_tool_reaches() -> None:
    for slope, steep_expected in ((10.0, False), (25.0, True), (70.0, True)):
        grid, design = ramp(slope)
        steep = rest_steep.steep_cells(RestStock(grid, design + 0.05, TOL * rest.LEAST_CUT, design, TOL), 1.5)
        assert (steep is not None) == steep_expected, slope
        if steep is not None:
            assert np.isfinite(steep.heights).all()   # the edges' slopes read one-sided
    # not where the tool's envelope stays more than the tolerance above the design along its normal (no spacing
    # holds it there); a vertical gap of twice the tolerance on a 70 deg wall is 0.0068 mm along the normal: reached
    grid, design = ramp(70.0)
    normal = math.cos(math.radians(70.0))
    for gap, reached in ((0.1 / normal, False), (0.02, True)):
        sloped = rest_steep.steep_cells(RestStock(grid, design + 0.05, 0.002, design, TOL, envelope=design + gap),
                                        1.5)
        assert (sloped is not None) == reached, gap


def test_the_levels_leave_the_cusp_on_the_wall() -> None:
    grid, design = ramp(60.0)
    stock = RestStock(grid, design + 0.05, 0.002, design, TOL)
    zs = np.array(rest_steep.levels(stock, 1.5, 0.008))
    a = math.radians(60.0)
    dz = math.sin(a) * math.sqrt(8 * 1.5 * 0.008)   # the cusp along the wall's normal
    steps = -np.diff(zs)
    assert np.all(steps > 0)
    assert np.median(steps) == pytest.approx(dz, rel=0.02)
    assert (np.median(steps) / math.sin(a)) ** 2 / (8 * 1.5) == pytest.approx(0.008, rel=0.05)
    inner = design[1:-1, 1:-1]
    assert zs[0] >= inner.max() - 1.5 * (1 - math.cos(a)) - 1e-6   # the top cell's contact level
    assert zs[-1] <= inner.min()


def test_a_steep_wall_rested_is_within_the_tolerance_along_the_normal() -> None:
    mesh = wall_mesh()
    case = after_d10(mesh, (WALL_X - 4.0, 0.0, WALL_X + 8.0, 10.0), 0.25, D3, 7.0, 10.0)
    grid, design, left, envelope, area = case.grid, case.design, case.left, case.envelope, case.area
    inner = np.zeros_like(design, dtype=bool)
    inner[8:-8, 8:-8] = True                     # two millimetres in from the finish's boundary
    # in reach along the normal, as the planner's left check judges (the vertical gap on the wall is twice that)
    reach = inner & np.isfinite(design) & (reach_excess(envelope, design, grid.cell, D3.radius) <= TOL)
    on_wall = reach & (np.nan_to_num(rest_steep.slope_deg(design, grid.cell)) > 55.0)
    normal = gentle_cosine(design, grid.cell)
    assert on_wall.sum() > 100 and np.nanmax(np.where(on_wall, (left - design) * normal, np.nan)) > 1.5 * TOL
    params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, sample_step=0.25,
                           rest=area.stock(left), stepover=2 * math.sqrt(2 * D3.radius * 0.8 * TOL), verify_notes=[])
    rest_policy = LinkPolicy(10.0, 12.0, material_top=StockHeights(grid, left, D3), low_links=True)
    worst = {}
    for name, p in (("raster alone", replace(params, rest=replace(params.rest, design=None))), ("split", params)):
        result = raster_drop.compute(mesh, D3, p)
        after = simulate(link(result.segments, rest_policy), D3, grid, left).heights
        worst[name] = float(np.nanmax(np.where(on_wall, (after - design) * normal, np.nan)))
        assert np.nanmin(after - design) > -0.005
        if name == "split":   # what the passes leave above the tolerance: loops over the sloped cells, touch-ups
            steep = result.diagnostics["steep"]
            assert steep["cells"] > 0 and result.diagnostics["touch_ups"] > 0
            note = p.verify_notes[-1]   # what the op reports: the loops' cells, what stays (the wall's ends)
            assert isinstance(note, rest_steep.SteepReport)
            assert note.sloped == pytest.approx(steep["cells"] * grid.cell_area)
            assert note.summary().startswith(f"the passes left {note.sloped:.1f} mm2 of sloped rest above 0.01 mm")
    assert worst["raster alone"] > 1.2 * TOL        # the passes cannot hold the cusp at the wall's edges
    assert worst["split"] <= TOL, worst


def test_the_pieces_go_nearest_first_and_downhill_keeping_joined_ones_together() -> None:
    from tmm_workbench.core.segments import CutSegment, SegmentKind

    def piece(x0: float, z: float, joined: bool = False) -> CutSegment:
        tips = np.array([[x0, 0.0, z], [x0 + 1.0, 0.0, z]])
        return CutSegment(tips, SegmentKind.PASS, joined=joined)

    a, far, b, b2, up = piece(0.0, 5.0), piece(50.0, 5.0), piece(1.5, 4.8), piece(2.6, 4.7, True), piece(2.0, 6.0)
    # from a's end (1, 0, 5): b 0.5 away and 0.2 down; the piece 1 mm away but 1 mm up costs 1 + 4; far last
    assert rest_order.ordered([a, far, up, b, b2]) == [a, b, b2, up, far]


def test_the_work_estimate_counts_the_loops_over_the_rest_slopes() -> None:
    # a 60 deg cone, its ring between radii 2 and 4.5 mm left 0.05 mm above it
    tan = math.tan(math.radians(60.0))
    cone = lambda x, y: np.maximum(0.0, (6.0 - np.hypot(x, y)) * tan)   # noqa: E731
    mesh = grid_mesh(cone, 96, 96, (-8.0, -8.0, 8.0, 8.0))
    grid = Grid.covering(-8.0, -8.0, 8.0, 8.0, 0.25)
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    design = cone(X, Y)
    ring = (np.hypot(X, Y) > 2.0) & (np.hypot(X, Y) < 4.5)
    stock = RestStock(grid, np.where(ring, design + 0.05, -np.inf), 0.002, design, TOL)
    plain = SurfaceParams(boundary=(-8.0, -8.0, 8.0, 8.0), stepover=0.3)
    bounds = (-8.0, -8.0, 0.0, 8.0, 8.0, 6.0 * tan)
    without = raster_drop.estimate_work(plain, D3, bounds)
    work = raster_drop.estimate_work(replace(plain, rest=stock), D3, bounds)
    count, length, n = rest_steep.estimate(replace(plain, rest=stock), D3)
    assert n == len(rest_steep.levels(rest_steep.of_params(replace(plain, rest=stock), D3), D3.radius, 0.008))
    assert count > 0 and work.count == pytest.approx(without.count + count)
    assert work.cut_length == pytest.approx(without.cut_length + length)
    assert dict(work.paces)["waterline"] == count and "waterline loops" in work.note
    # the loops made: the tip runs r sin a outside the contacts around the cone (radius 2 to 4.5): 1.3 to 1.6 times
    made = rest_steep.passes(mesh, D3, replace(plain, rest=stock), rest_steep.of_params(replace(plain, rest=stock),
                                                                                       D3), None, {})
    real = sum(float(np.linalg.norm(np.diff(seg.tips, axis=0), axis=1).sum()) for seg in made)
    assert 1.2 * length < real < 1.7 * length
