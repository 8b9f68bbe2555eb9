"""The simulation pipeline (core.sim): grid sizing and refusals, a ball raster on a plane against the cusp's
closed form (R - sqrt(R^2 - s^2/4)) through simulate + compare, removed volume, a path lowered by 0.05 mm
seen as a gouge, a rapid through the stock seen as a collision, and a 5-axis multipoint path on seed 001's
convex patch: no gouge beyond the positioning and sub-stepping bounds, and the same path lowered gouges."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SEED_JSON, grid_mesh
from tmm_workbench.core import limits
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.sim.compare import compare
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, cylinder_heights, mesh_heights
from tmm_workbench.core.strategies.multipoint import MultipointParams, compute_multipoint_toolpath
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter


def raster(x0, x1, y0, y1, step, z, along=0.5) -> Toolpath:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, x0, y0, z + 10)
    for k, y in enumerate(np.arange(y0, y1 + 1e-9, step)):
        xs = np.arange(x0, x1 + 1e-9, along)
        for x in (xs if k % 2 == 0 else xs[::-1]):
            tp.add(MoveKind.FEED, x, y, z)
    return tp


def test_grid_refuses_by_name():
    with pytest.raises(TmmError, match="cell size must be a length > 0 mm, got 0"):
        Grid.covering(0, 0, 10, 10, 0)
    with pytest.raises(TmmError, match="cell size must be a length > 0 mm, got nan"):
        Grid.covering(0, 0, 10, 10, math.nan)
    old = limits.set_limits(max_points=1_000_000)
    try:
        with pytest.raises(TmmError, match=r"cell size 0.001 mm over 100 x 100 mm \(100000 x 100000\)"):
            Grid.covering(0, 0, 100, 100, 0.001)
    finally:
        limits.set_limits(max_points=old.max_points)
    g = Grid.covering(0, 0, 10, 5, 0.5)
    assert (g.nx, g.ny) == (20, 10) and g.xs()[0] == 0.25 and g.centres().shape == (200, 2)


def test_ball_raster_leaves_the_closed_form_cusp_and_a_lowered_path_gouges():
    R, s = 3.0, 1.0
    plane = grid_mesh(lambda x, y: 0 * x, 10, 10, (-10, -10, 30, 30))
    grid = Grid.covering(0, 0, 20, 20, 0.05)
    design = mesh_heights(plane, grid)
    assert np.allclose(design, 0.0)
    stock = box_heights(grid, 5.0)
    tp = raster(-4, 24, -4, 24, s, 0.0)
    res = simulate(tp, Cutter.ball(2 * R), grid, stock)
    cmp = compare(res, design, tolerance=0.005)
    # cusp lines at y = k + 1/2, cell centres at 0.025 + 0.05 j: the highest cells are 0.025 off the line, so
    # 0.475 from each pass: R - sqrt(R^2 - 0.475^2) (the cusp itself, R - sqrt(R^2 - s^2/4), lies between)
    near = s / 2 - 0.025
    assert cmp.overall.max_left == pytest.approx(R - math.sqrt(R * R - near * near), abs=1e-9)
    assert cmp.overall.max_left < R - math.sqrt(R * R - s * s / 4)
    assert cmp.overall.min_deviation >= -1e-9 and not cmp.gouged
    assert res.removed_volume == pytest.approx(5.0 * 400.0 - cmp.overall.remaining_volume, rel=1e-9)
    assert len(res.collisions) == 0                                # the first rapid is above the stock

    lowered = raster(-4, 24, -4, 24, s, -0.05)
    cmp = compare(simulate(lowered, Cutter.ball(2 * R), grid, stock), design, tolerance=0.01)
    off = R - math.sqrt(R * R - 0.025 ** 2)  # the deepest cells are 0.025 beside the pass lines
    assert cmp.gouged and cmp.overall.min_deviation == pytest.approx(-0.05 + off, abs=1e-9)


def test_design_heights_exact_on_a_steep_wall():
    """The design under each cell is the mesh on the cell centre's vertical line: on a plane at 88 deg (a relief's
    wall) within 1e-4 mm of it (the needle's radius times the slope; a 1e-4 mm needle read 0.0029 mm high, a false
    gouge for a path within 0.001 mm of the exact CL path)."""
    k = math.tan(math.radians(88.0))
    mesh = grid_mesh(lambda x, y: k * x, 4, 4, (0.0, 0.0, 0.2, 1.0))
    grid = Grid.covering(0.02, 0.1, 0.18, 0.9, 0.01)
    design = mesh_heights(mesh, grid)
    exact = k * grid.centres()[:, 0].reshape(grid.ny, grid.nx)
    assert np.isfinite(design).all() and np.abs(design - exact).max() <= 1e-4


def test_rapid_through_the_stock_is_a_collision():
    grid = Grid.covering(0, 0, 20, 20, 0.1)
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 2, 2, 10)
    tp.add(MoveKind.RAPID, 2, 2, 3)      # into a 5 mm high stock: 2 mm deep
    tp.add(MoveKind.RAPID, 18, 2, 3)
    res = simulate(tp, Cutter.flat(4.0), grid, box_heights(grid, 5.0))
    assert len(res.collisions) >= 1
    assert res.collisions[0][0] == 0 and res.collisions[0][1] == pytest.approx(2.0, abs=1e-9)


def test_cylinder_stock_and_bad_input():
    grid = Grid.covering(-10, -10, 10, 10, 0.5)
    h = cylinder_heights(grid, (0, 0), 8.0, 5.0, 0.0)
    assert h[grid.ny // 2, grid.nx // 2] == 5.0 and h[0, 0] == 0.0
    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0)
    with pytest.raises(TmmError, match="no moves"):
        simulate(tp, Cutter.ball(6), grid, h)
    tp.add(MoveKind.FEED, 1, math.nan, 0)
    with pytest.raises(TmmError, match="point 1 is not finite"):
        simulate(tp, Cutter.ball(6), grid, h)


def test_five_axis_multipoint_path_on_seed_001():
    face = BezierFace.from_net(bezier.load_seed_patch(SEED_JSON, "convex"))
    tool = Cutter.torus(6.7, 6.0)
    tp, _ = compute_multipoint_toolpath(face, tool, MultipointParams(side_step=18.0, forward_step=2.0,
                                                                     shape="bull_nose"))
    grid = Grid.covering(20, 20, 130, 130, 0.25)
    u = np.linspace(0, 1, 301)
    U, V = np.meshgrid(u, u, indexing="ij")
    pts = face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
    i, j = np.meshgrid(np.arange(300), np.arange(300), indexing="ij")
    a = (i * 301 + j).ravel()
    tris = np.vstack([np.column_stack([a, a + 301, a + 1]), np.column_stack([a + 1, a + 301, a + 302])])
    design = mesh_heights(TriMesh(pts, tris, "convex"), grid)
    stock = box_heights(grid, float(np.nanmax(design)) + 2.0)
    res = simulate(tp, tool, grid, stock, shape="bull_nose", max_step=0.1)
    assert res.five_axis
    cmp = compare(res, design, tolerance=0.01)
    # positions within 1 um, moves checked to 0.005 mm, sub-steps 0.1 mm (cusp 0.1^2 / (8 * 6) = 0.0002 mm),
    # the design tessellated 0.5 mm apart (its chords lie below the face by up to about 0.002 mm)
    assert cmp.overall.min_deviation > -0.01, cmp.overall
    assert 0.05 < cmp.overall.max_left < 5.0   # scallops between 18 mm passes, and the unmachined margins
    lowered = Toolpath()
    for m in tp:
        lowered.add(m.kind, m.x, m.y, m.z - (0.05 if m.kind is not MoveKind.RAPID else 0.0), m.axis)
    cmp = compare(simulate(lowered, tool, grid, stock, shape="bull_nose", max_step=0.1), design, tolerance=0.01)
    assert cmp.gouged and cmp.overall.min_deviation < -0.04
