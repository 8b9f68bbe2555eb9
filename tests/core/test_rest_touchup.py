"""Touch-ups (core.strategies.rest_touchup): the tool put where it reaches what a rest's passes and loops leave
above the tolerance; and a cell the tool brings within the tolerance is rest however little it takes off."""
from __future__ import annotations

import math

import numpy as np

from tests.conftest import grid_mesh
from tests.core.rest_case import after_d10
from tests.core.test_rest_steep import D3, TOL, WALL_X, wall_mesh
from tmm_workbench.core.footprint.reach import gentle_cosine
from tmm_workbench.core import polygons
from tmm_workbench.core.footprint import rest
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import raster_drop, rest_touchup
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

PARAMS = SurfaceParams(boundary=(0.0, 0.0, 30.0, 10.0), stepover=0.3)


def test_the_foot_of_a_wall_the_passes_and_loops_leave_is_touched_up_within_the_tolerance(monkeypatch) -> None:
    mesh = wall_mesh(45.0)
    case = after_d10(mesh, (WALL_X - 4.0, 0.0, WALL_X + 8.0, 10.0), 0.25, D3, 7.0, 10.0)
    grid, design, left, area = case.grid, case.design, case.left, case.area
    inner = np.zeros_like(design, dtype=bool)
    inner[8:-8, 8:-8] = True                     # two millimetres in from the finish's boundary
    reach = inner & np.isfinite(design) & (case.envelope - design <= TOL)
    params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, sample_step=0.25,
                           rest=area.stock(left), stepover=2 * math.sqrt(2 * D3.radius * 0.8 * TOL), verify_notes=[])
    policy = LinkPolicy(10.0, 12.0, material_top=StockHeights(grid, left, D3), low_links=True)

    def left_over(result) -> np.ndarray:
        after = simulate(link(result.segments, policy), D3, grid, left).heights
        assert np.nanmin(after - design) > -0.005
        return np.where(reach, (after - design) * gentle_cosine(design, grid.cell), np.nan)   # along the normal

    touched = raster_drop.compute(mesh, D3, params)
    assert touched.diagnostics["touch_ups"] > 0
    assert np.nanmax(left_over(touched)) <= TOL
    note = params.verify_notes[-1]   # the op's RestReport: the touch-ups, nothing left within reach
    assert note.touch_ups == touched.diagnostics["touch_ups"] and "touch-up(s) where" in note.summary()
    assert note.sloped_after == 0 and note.flat_after == 0
    monkeypatch.setattr(rest_touchup, "pieces", lambda *args, **kwargs: [])
    plain = left_over(raster_drop.compute(mesh, D3, params))
    feet = np.argwhere(plain > TOL)   # the passes and loops alone leave cells at the wall's foot
    assert len(feet) >= 2 and np.all(np.abs(grid.xs()[feet[:, 1]] - WALL_X) < D3.radius)


def flat_mesh() -> TriMesh:
    v = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0], [0.0, 10.0, 0.0]])
    return TriMesh(v, np.array([[0, 1, 2], [0, 2, 3]]), "flat")


def test_a_touch_up_goes_where_the_tool_reaches_the_cell_and_neighbours_are_one_piece() -> None:
    grid = Grid.covering(0.0, 0.0, 10.0, 10.0, 0.25)
    design = np.zeros((grid.ny, grid.nx))
    heights = np.full_like(design, -np.inf)
    heights[20, 20] = heights[20, 21] = heights[30, 5] = 0.05
    left = RestStock(grid, heights, 0.002, design, TOL, envelope=design.copy())
    mesh = flat_mesh()
    pieces = rest_touchup.pieces(mesh, D3, PARAMS, left, DropSurface(mesh))
    assert len(pieces) == 2
    one, two = sorted(pieces, key=lambda seg: float(np.ptp(seg.tips[:, 0])))
    assert np.allclose(one.tips, [[grid.xs()[5], grid.ys()[30], 0.0]] * 2)   # down there and up
    assert np.allclose(two.tips[[0, -1], :2], [[grid.xs()[20], grid.ys()[20]], [grid.xs()[21], grid.ys()[20]]][
        ::1 if two.tips[0, 0] < two.tips[-1, 0] else -1])
    assert np.allclose(two.tips[:, 2], 0.0)
    # a cell no position brings within the tolerance (a pit narrower than the tool) is left alone
    pit = design.copy()
    pit[10, 10] = -0.5
    heights = np.full_like(design, -np.inf)
    heights[10, 10] = 0.05
    left = RestStock(grid, heights, 0.002, pit, TOL)
    assert rest_touchup.pieces(mesh, D3, PARAMS, left, DropSurface(mesh)) == []


def test_touch_ups_keep_the_holder_clear_of_a_wall() -> None:
    # a floor beside a wall 40 mm high; a ball D4 on a 20 mm stick-out: its holder reaches over the wall
    mesh = grid_mesh(lambda x, y: np.clip((x - 10.0) * 10.0, 0.0, 40.0), 120, 40, (0.0, 0.0, 30.0, 10.0), "wall")
    surface = DropSurface(mesh)
    ball = Cutter.ball(4)
    grid = Grid.covering(0.0, 0.0, 30.0, 10.0, 0.25)
    design = mesh_heights(mesh, grid)
    heights = np.full_like(design, -np.inf)
    heights[20, 31] = 0.05                      # on the floor at x 7.9, y 5.1, the ball D4 reaches it
    left = RestStock(grid, heights, 0.002, design, TOL)
    free = rest_touchup.pieces(mesh, ball, PARAMS, left, surface)
    assert len(free) == 1 and np.allclose(free[0].tips[:, 2], 0.0, atol=1e-6)
    holder = ToolAssembly(ball, 4, 20.0, flute_length=12, holder="SK40 ER32x70")
    params = SurfaceParams(boundary=PARAMS.boundary, stepover=0.3, assembly=holder, holder_collision="leave_out",
                           holder_notes=[])
    # every position that reaches the cell puts the holder on the wall: none is put there
    assert rest_touchup.pieces(mesh, ball, params, left, surface) == []


def test_a_touch_up_takes_the_position_where_the_shank_keeps_its_clearance() -> None:
    # a floor beside a wall 8 mm high (x < 10), taller than the flutes; a bull D4 r0.5 reaches a floor cell at
    # x 12.5 from positions up to 1.5 mm off it, but its shank (D4, 1 mm clearance) is clear of the wall above the
    # flutes (x < 9.7) only from x 12.7
    mesh = grid_mesh(lambda x, y: np.clip((10.0 - x) * 10.0, 0.0, 8.0), 120, 40, (0.0, 0.0, 30.0, 10.0), "wall")
    surface = DropSurface(mesh)
    bull = Cutter(4, 0.5)
    grid = Grid.covering(0.0, 0.0, 30.0, 10.0, 0.25)
    design = mesh_heights(mesh, grid)
    heights = np.full_like(design, -np.inf)
    iy, ix = 20, int(np.argmin(np.abs(grid.xs() - 12.5)))
    heights[iy, ix] = 0.05
    left = RestStock(grid, heights, 0.002, design, TOL)
    shank = ToolAssembly(bull, 4, 20.0, flute_length=3, holder="SK40 ER32x70")
    params = SurfaceParams(boundary=PARAMS.boundary, stepover=0.3, assembly=shank, holder_collision="leave_out",
                           holder_notes=[])
    pieces = rest_touchup.pieces(mesh, bull, params, left, surface)
    assert len(pieces) == 1 and params.holder_notes[-1].affected == 0
    tip = pieces[0].tips[0]
    assert tip[0] >= 9.7 + 2.0 + 1.0 - 1e-6 and abs(tip[2]) < 1e-6          # the shank clear, on the floor
    assert np.hypot(tip[0] - grid.xs()[ix], tip[1] - grid.ys()[iy]) <= 1.5    # the flat bottom over the cell
    # the cutter alone would stand where its shank meets the wall: the guard leaves that touch-up out
    alone = SurfaceParams(boundary=PARAMS.boundary, stepover=0.3)
    spot = rest_touchup.pieces(mesh, bull, alone, left, surface)[0].tips[0]
    assert spot[0] < 12.7


def test_a_cell_the_tool_brings_within_the_tolerance_is_rest_however_little_it_takes_off() -> None:
    grid = Grid.covering(0.0, 0.0, 2.0, 2.0, 0.25)
    design = np.zeros((grid.ny, grid.nx))
    left = np.full_like(design, 0.0105)
    envelope = np.full_like(design, 0.009)   # lowered by 0.0015 mm, less than LEAST_CUT of the tolerance
    assert 0.0105 - 0.009 < rest.LEAST_CUT * TOL
    assert rest.rest_area(left, design, envelope, grid, TOL, D3.radius).mask.all()
    # out of reach and lowered that little: no rest
    assert not rest.rest_area(left, design, envelope + 0.0025, grid, TOL, D3.radius).mask.any()
    assert rest.rest_area(left + 0.01, design, envelope + 0.0025, grid, TOL, D3.radius).mask.all()


def test_a_rest_of_two_pieces_is_cut_piece_by_piece() -> None:
    # two patches left 0.05 mm on a wavy floor, 18 mm apart along the raster's passes, in one region: nearest first,
    # the tool finishes one before it goes to the other (in the raster's own order it crossed over on every pass)
    mesh = grid_mesh(lambda x, y: 0.3 * np.sin(x) + 0.02 * y, 240, 40, (0.0, 0.0, 30.0, 10.0), "waves")
    grid = Grid.covering(0.0, 0.0, 30.0, 10.0, 0.25)
    design = mesh_heights(mesh, grid)
    x, y = np.meshgrid(grid.xs(), grid.ys())
    patches = ((y > 2) & (y < 8)) & (((x > 2) & (x < 6)) | ((x > 24) & (x < 28)))
    left = RestStock(grid, np.where(patches, design + 0.05, -np.inf), 0.002, design, TOL, envelope=design.copy())
    params = SurfaceParams(boundary=(0.0, 0.0, 30.0, 10.0), region=[polygons.rectangle(1.0, 1.0, 29.0, 9.0)],
                           sample_step=0.25, rest=left, stepover=0.3)
    segments = raster_drop.compute(mesh, D3, params).segments
    side = np.array([seg.tips[0, 0] > 15.0 for seg in segments])
    assert side.any() and not side.all()
    assert int(np.sum(side[1:] != side[:-1])) == 1
