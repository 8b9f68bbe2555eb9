"""The linker's design (core.linking.know_design): a waterline's loops on a wall entered from just above what
stands off the design, not from the wall's top; the waterline's repeated pieces left out; a raster's pieces in the
rest's order."""
from __future__ import annotations

import numpy as np

from tests.conftest import grid_mesh
from tmm_workbench.core.linking import LinkPolicy, StockHeights, know_design, know_op_design, link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import raster_drop, waterline
from tmm_workbench.core.strategies.surface.params import ONEWAY, SurfaceParams
from tmm_workbench.core.strategies.waterline import WaterlineParams
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter

D4 = Cutter.flat(4)
TOP, ROUGH = 10.0, 0.5


def bosses():
    """Two round bosses 10 mm high on a floor at 0, their sides as steep as the mesh makes them (a 0.25 mm
    triangle: 88 deg): the boss's top within the tool's reach at every loop."""
    def z(x, y):
        r = np.minimum(np.hypot(x - 12, y - 15), np.hypot(x - 38, y - 15))
        return TOP * np.clip((8.0 - r) / 0.01, 0.0, 1.0)
    return grid_mesh(z, 200, 120, (0.0, 0.0, 50.0, 30.0))


def plunges(tp) -> list[float]:
    return [tp.moves[i - 1].z - m.z for i, m in enumerate(tp.moves) if i and m.kind is MoveKind.PLUNGE]


def test_waterline_entries_come_down_to_the_loop_above_not_the_walls_top() -> None:
    """The boss's top and floor finished, its side as a roughing left it (0.5 mm over the design): without the
    design each loop's entry is fed from 1 mm above the boss's top (within the tool's reach); with it from
    1 mm above what stands off the design (what the loops above left). The same cut, no rapid into material,
    no gouge."""
    mesh = bosses()
    grid = Grid.covering(0.0, 0.0, 50.0, 30.0, 0.25)
    design = mesh_heights(mesh, grid)
    side = (design > 0.01) & (design < TOP - 0.01)
    left = np.where(side, design + ROUGH, design)
    params = WaterlineParams(boundary=(0.0, 0.0, 50.0, 30.0), step_down=1.0, bottom_z=1.0, top_z=TOP,
                             chord_tol=0.01)
    segments = waterline.compute(mesh, D4, params).segments
    for seg in segments:   # each loop entered (the loops below one another are joined by straight moves)
        seg.joined = False
    found = []
    for know in (False, True):
        policy = LinkPolicy(15.0, 20.0, material_top=StockHeights(grid, left, D4), low_links=True)
        if know:
            assert know_op_design(policy, mesh, params)
        tp = link(segments, policy)
        sim = simulate(tp, D4, grid, left)
        assert len(sim.collisions) == 0
        assert np.nanmin(sim.heights - design) > -0.01
        found.append((plunges(tp), sim.heights))
    (before, cut_before), (after, cut_after) = found
    assert len(after) == len(before) >= 5
    assert max(before) > 5.0 and sum(after) < 0.6 * sum(before) and min(after) < 1.01
    assert np.array_equal(cut_after, cut_before)


def test_the_design_is_not_given_without_stock_heights_or_below_the_model() -> None:
    mesh = bosses()
    grid = Grid.covering(0.0, 0.0, 50.0, 30.0, 1.0)
    assert not know_design(LinkPolicy(15.0, 20.0), mesh, 0.01)
    top = StockHeights(grid, mesh_heights(mesh, grid), D4)
    assert not know_design(LinkPolicy(15.0, 20.0, material_top=top), mesh, 0.01, stock_to_leave=-0.1)
    assert top.design is None
    assert know_design(LinkPolicy(15.0, 20.0, material_top=top), mesh, 0.01)
    assert top.design is not None and top.within == 0.01


def test_moves_repeating_an_earlier_lifted_piece_are_left_out_and_the_rest_entered() -> None:
    x = np.linspace(0.0, 5.0, 11)
    lifted = CutSegment(np.column_stack([x, np.zeros_like(x), 1.0 + 0.1 * x]))   # a piece the guard lifted
    other = CutSegment(np.array([[0.0, 3.0, 1.0], [5.0, 3.0, 1.0]]))
    again = CutSegment(lifted.tips + [0.0, 0.0, 5e-4])                          # the same, a hair higher
    after = CutSegment(np.array([[5.0, 0.5, 0.5], [0.0, 0.5, 0.5]]), joined=True)
    end_lower = lifted.tips.copy()
    end_lower[-1, 2] -= 0.4                                                      # its last tip at its level
    tail = CutSegment(end_lower)
    lower = CutSegment(lifted.tips - [0.0, 0.0, 0.01])                          # cuts 10 um deeper: new
    flat = CutSegment(np.column_stack([x, np.full_like(x, 2.0), np.full_like(x, 3.0)]))   # lifted whole
    flat_again = CutSegment(flat.tips.copy())
    level = CutSegment(np.column_stack([x, np.full_like(x, 2.0), np.full_like(x, 1.0)]))  # at its level
    out, count = waterline.without_repeats([lifted, other, again, after, tail, lower, flat, flat_again, level,
                                            CutSegment(level.tips.copy())], [1.0])
    assert count == 3
    assert out[:3] == [lifted, other, after] and not after.joined
    assert np.array_equal(out[3].tips, end_lower[-2:]) and not out[3].joined    # only its last move, entered
    # a piece at its level is never a repeat (every level's loops are cut once; only the guard's lifts repeat)
    assert out[4] is lower and out[5] is flat and out[6] is level and len(out) == 8


def gaps(segments: list[CutSegment]) -> float:
    return float(sum(np.hypot(*(b.tips[0, :2] - a.tips[-1, :2])) for a, b in zip(segments, segments[1:])))


def test_a_zigzag_rasters_pieces_are_cut_region_by_region() -> None:
    """Two regions 40 mm apart, pass by pass: the tool crossed between them at every pass; in the rest's order
    (nearest-first, nearer end, 2-opt) it crosses about once. The same pieces; a one-way raster keeps its order."""
    pieces = []
    for j in range(10):
        for x0 in (0.0, 50.0):
            xs = [x0, x0 + 10.0][:: 1 if j % 2 == 0 else -1]
            pieces.append(CutSegment(np.array([[xs[0], j * 0.5, 1.0], [xs[1], j * 0.5, 1.0]])))
    params = SurfaceParams(boundary=(0.0, 0.0, 60.0, 5.0), stepover=0.5)
    out = raster_drop.pieces_ordered(params, list(pieces))
    assert gaps(out) < 0.25 * gaps(pieces)
    key = lambda seg: tuple(sorted(map(tuple, seg.tips.tolist())))   # noqa: E731
    assert sorted(map(key, out)) == sorted(map(key, pieces))
    oneway = SurfaceParams(boundary=(0.0, 0.0, 60.0, 5.0), stepover=0.5, pattern=ONEWAY)
    assert raster_drop.pieces_ordered(oneway, list(pieces)) == pieces
