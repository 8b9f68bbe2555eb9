"""The tool's bodies above the flutes against the stock during the simulation: the kernel's body check through
the binding against a numpy replay (same poses, the flute rule, the clearance discs of cylinders in closed form),
core.sim.simulate(assembly=) and its StockCollisions, the heat map's marks; bad input refused by name."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

BODIES = np.array([[8.0, 30.0, 2.5, 2.5, 0.5], [30.0, 60.0, 10.0, 10.0, 1.0]])  # shank, holder (cylinders)
FLUTE_TOP = 8.0


def stock_with_boss_and_wall(grid: Grid) -> np.ndarray:
    x, y = np.meshgrid(grid.xs(), grid.ys())
    z = np.zeros((grid.ny, grid.nx))
    z[(np.abs(x) <= 5) & (np.abs(y) <= 5)] = 30.0   # a boss
    z[x >= 20] = 20.0                                 # a wall
    return z


def grown_lowest(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lowest point above the tip of each cylinder grown by its clearance (a ball swept over it) at the radial
    distance d, the lowest of them and its index."""
    low = []
    for z0, _, r, _, c in BODIES:
        e = d - r
        v = np.where(e <= 0, z0 - c, z0 - np.sqrt(np.maximum(c * c - e * e, 0.0)))
        low.append(np.where(e <= c, v, np.inf))
    low = np.array(low)
    return low.min(axis=0), low.argmin(axis=0)


def numpy_replay(grid: Grid, stock: np.ndarray, tips: np.ndarray, radius: float, step: float):
    """Per move: the cutter (flat) stamped at each pose where the flutes reach the material's top, then the
    bodies tested: {(move, piece): depth} and the per cell deepest of each move; then the stock cut exactly."""
    x, y = np.meshgrid(grid.xs(), grid.ys())
    out, per_cell = {}, []
    z = stock.copy()
    for k in range(len(tips) - 1):
        a, b = tips[k], tips[k + 1]
        n = max(1, math.ceil(np.linalg.norm(b - a) / step))
        s = z.copy()
        deepest = np.full(z.shape, -np.inf)
        for i in range(n + 1):
            p = a + (b - a) * (i / n)
            d = np.hypot(x - p[0], y - p[1])
            cut = (d <= radius) & (s <= p[2] + FLUTE_TOP)
            s = np.where(cut, np.minimum(s, p[2]), s)
            low, owner = grown_lowest(d)
            depth = s - (p[2] + low)
            deepest = np.maximum(deepest, depth)
            for piece in (0, 1):
                hit = (owner == piece) & np.isfinite(low) & (depth > 1e-3)
                if hit.any():
                    out[(k, piece)] = max(out.get((k, piece), -np.inf), float(depth[hit].max()))
        per_cell.append(deepest)
        zm = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
        zm.heights[:] = z
        native.cut_3axis(zm, Cutter.flat(2 * radius).native, np.ascontiguousarray([a, b]), np.zeros(1, np.uint8))
        z = np.array(zm.heights)
    return out, per_cell


def test_binding_matches_a_numpy_replay():
    grid = Grid.covering(-30, -30, 30, 30, 0.25)
    stock = stock_with_boss_and_wall(grid)
    tips = np.array([[-25, 14, 10], [-25, 14, -5], [25, 14, -5], [12, 0, 0], [18, 0, -2], [12, -20, 1.0]])
    kinds = np.zeros(len(tips) - 1, np.uint8)
    zmap = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
    zmap.heights[:] = stock
    rep = native.cut_3axis(zmap, Cutter.flat(4).native, tips, kinds, bodies=BODIES, flute_top=FLUTE_TOP,
                           body_step=0.125)
    rows = rep["body_collisions"]
    assert rows.shape[1] == 6 and len(rows) >= 3
    want, per_cell = numpy_replay(grid, stock, tips, 2.0, 0.125)
    got = {(int(m), int(p)): d for m, p, _, _, _, d in rows}
    assert set(got) == set(want)
    for key, depth in want.items():
        assert got[key] == pytest.approx(depth, abs=1e-9), key
    for m, _, x, y, z, d in rows:  # the reported cell is one this deep, at its stock height
        i, j = int(round((x - grid.x0) / grid.cell - 0.5)), int(round((y - grid.y0) / grid.cell - 0.5))
        assert per_cell[int(m)][j, i] >= d - 1e-9
        assert z == stock[j, i] or z <= stock[j, i]
    # the holder over the boss (move 1), the shank into the wall above the flutes (move 3)
    assert (1, 1) in got and got[(1, 1)] == pytest.approx(30 - (-5 + 29), abs=1e-9)
    assert (3, 0) in got and got[(3, 0)] == pytest.approx(20 - (-2 + 7.5), abs=0.3)
    # the heights are those of the plain cut
    plain = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
    plain.heights[:] = stock
    assert "body_collisions" not in native.cut_3axis(plain, Cutter.flat(4).native, tips, kinds)
    assert np.array_equal(plain.heights, zmap.heights)


def test_five_axis_binding_reports_the_holder_over_the_boss():
    grid = Grid.covering(-30, -30, 30, 30, 0.5)
    zmap = native.ZMap(grid.x0, grid.y0, grid.cell, grid.nx, grid.ny, 0.0)
    zmap.heights[:] = stock_with_boss_and_wall(grid)
    tips = np.array([[-15.0, 14, -5], [15.0, 14, -5]])
    axes = np.array([[0.0, 0, 1], [0.0, 0, 1]])
    rep = native.cut_5axis(zmap, 0.0, 2.0, "bull_nose", tips, axes, np.zeros(1, np.uint8), 0.5, bodies=BODIES)
    (row,) = rep["body_collisions"]
    assert int(row[0]) == 0 and int(row[1]) == 1 and row[5] == pytest.approx(6.0, abs=1e-6)
    assert abs(row[2]) <= 5 and 3 <= row[3] <= 5 and row[4] == 30.0


def test_bad_bodies_are_refused_by_name():
    zmap = native.ZMap(0, 0, 1, 4, 4, 0.0)
    tips, kinds = np.array([[0.0, 0, 0], [1, 0, 0]]), np.zeros(1, np.uint8)
    with pytest.raises(ValueError, match="bodies must be"):
        native.cut_3axis(zmap, Cutter.flat(4).native, tips, kinds, bodies=np.zeros((2, 4)))
    with pytest.raises(ValueError, match="flute_top"):
        native.cut_3axis(zmap, Cutter.flat(4).native, tips, kinds, bodies=BODIES, flute_top=-1.0)


def boss_pass(z: float) -> Toolpath:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, -25, 20, 60)
    tp.add(MoveKind.FEED, -25, 20, z)
    tp.add(MoveKind.FEED, 25, 20, z)
    tp.add(MoveKind.RAPID, 25, 20, 60)
    return tp


def boss_case(cell: float) -> tuple:
    """A block at 0 with a boss 10 mm square and 40 mm tall; a flat D6 (flutes 12) at 25 mm in an ER32 chuck."""
    grid = Grid.covering(-30, -30, 30, 30, cell)
    stock = box_heights(grid, 0.0)
    x, y = np.meshgrid(grid.xs(), grid.ys())
    stock[(np.abs(x) <= 5) & (np.abs(y) <= 5)] = 40.0
    cutter = Cutter.flat(6)
    return grid, stock, cutter, ToolAssembly(cutter, 6, 25, flute_length=12, holder="SK40 ER32x70")


def test_simulate_returns_the_stock_collisions_of_the_assembly():
    grid, stock, cutter, assembly = boss_case(0.25)
    res = simulate(boss_pass(0.0), cutter, grid, stock, assembly=assembly)
    found = res.stock_collisions
    assert found is not None and found.count >= 1 and found.per_piece == {"holder": found.count}
    assert 1 in found.moves and set(found.moves.tolist()) <= {0, 1, 2}   # the wide nut reaches it from the ends too
    assert found.positions[0, 2] == 40.0 and abs(found.positions[0, 0]) <= 5
    assert "holder" in found.summary() and "Tool collision with the stock" in found.summary()
    plain = simulate(boss_pass(0.0), cutter, grid, stock)
    assert plain.stock_collisions is None and np.array_equal(plain.heights, res.heights)
    # high enough above the boss: nothing
    clear = simulate(boss_pass(30.0), cutter, grid, stock, assembly=assembly).stock_collisions
    assert clear.ok and "Tool clear of the stock" in clear.summary()
    with pytest.raises(TmmError, match="body tolerance"):
        simulate(boss_pass(0.0), cutter, grid, stock, assembly=assembly, body_tolerance=-1.0)
    with pytest.raises(TmmError, match="ToolAssembly"):
        simulate(boss_pass(0.0), cutter, grid, stock, assembly="ER32")


def test_heat_map_marks_the_collisions(tmp_path):
    from tmm_workbench.core.preview.deviation_png import COLLISION_LABEL, render_deviation_png
    from tmm_workbench.core.sim.compare import compare

    grid, stock, cutter, assembly = boss_case(0.5)
    res = simulate(boss_pass(0.0), cutter, grid, stock, assembly=assembly)
    cmp = compare(res, np.full_like(stock, -1.0), 0.01)
    marked = render_deviation_png(cmp, grid, str(tmp_path / "marked.png"), "t", collisions=res.stock_collisions)
    plain = render_deviation_png(cmp, grid, str(tmp_path / "plain.png"), "t")
    from PIL import Image

    a = np.asarray(Image.open(marked).convert("RGB")).astype(int)
    b = np.asarray(Image.open(plain).convert("RGB")).astype(int)
    assert a.shape == b.shape and (np.abs(a - b).sum(axis=2) > 0).sum() > 50   # crosses and the legend drawn
    assert COLLISION_LABEL == "holder/shank collision"


def test_heat_map_in_a_colour_band(tmp_path):
    """With a band the colours span +-band and the cells beyond take the map's darkest ends: half the cells 0.004
    mm above the design read clearly red in a 0.01 band, near white over the whole range (to 1 mm)."""
    from PIL import Image

    from tmm_workbench.core.preview.deviation_png import render_deviation_png
    from tmm_workbench.core.sim.compare import compare

    grid, stock, cutter, _ = boss_case(0.5)
    cmp = compare(simulate(boss_pass(0.0), cutter, grid, stock), np.full_like(stock, -1.0), 0.01)
    cmp.deviation[:] = np.where(np.arange(cmp.deviation.shape[1]) < cmp.deviation.shape[1] // 2, 0.004, 1.0)

    def red_pixels(path: str) -> int:
        img = np.asarray(Image.open(path).convert("RGB")).astype(int)
        return int((img[..., 0] - img[..., 2] > 60).sum())

    banded = red_pixels(render_deviation_png(cmp, grid, str(tmp_path / "band.png"), "t", band=0.01))
    whole = red_pixels(render_deviation_png(cmp, grid, str(tmp_path / "whole.png"), "t"))
    assert banded > 1.5 * whole, (banded, whole)
