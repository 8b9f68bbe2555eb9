"""Joins between a rest's pieces (core.strategies.rest_joins): across a ridge the join is lifted over it and no move
of it comes below the model; a piece farther than the longest join, or one whose join would bring the holder onto
a wall, is left to the linker; a rest on a wall has its entries joined and still does not gouge; a rest's entry beside a wall is fed only through
what stands off the design."""
from __future__ import annotations

import numpy as np

from tests.conftest import grid_mesh
from tests.core.test_rest_steep import TOL, WALL_X, wall_mesh
from tmm_workbench.core.footprint.rest import RestStock
from tmm_workbench.core.linking import LinkPolicy, StockHeights, know_op_design, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import CutSegment, SegmentKind
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import rest_joins
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.linear_moves import deepest_cut

D3 = Cutter.ball(3)
PARAMS = SurfaceParams(boundary=(0.0, 0.0, 20.0, 10.0), stepover=0.3)


def ridge():
    """A floor with a 45 deg ridge 1 mm high along y at x = 10."""
    return grid_mesh(lambda x, y: np.maximum(0.0, 1.0 - np.abs(x - 10.0)), 160, 40, (0.0, 0.0, 20.0, 10.0), "ridge")


def piece(surface: DropSurface, x: float, y0: float, y1: float) -> CutSegment:
    xy = np.array([[x, y0], [x, y1]])
    return CutSegment(np.column_stack([xy, surface.drop(D3, xy, -10.0)]))


def path_of(segments: list[CutSegment]) -> np.ndarray:
    return np.vstack([seg.tips for seg in segments])


def test_a_join_across_a_ridge_is_lifted_over_it_and_never_below_the_model() -> None:
    surface = DropSurface(ridge())
    a, b = piece(surface, 7.5, 2.0, 5.0), piece(surface, 12.5, 5.0, 2.0)   # 5 mm apart across the ridge
    out, joins = rest_joins.join_pieces(ridge(), D3, PARAMS, [a, b], surface)
    assert joins == 1 and b.joined
    link = out[1]
    assert link.kind is SegmentKind.LINK and link.joined
    assert link.tips[:, 2].max() >= 1.0 - 1e-9   # over the ridge: the ball's tip on its crest
    path = path_of(out)
    assert deepest_cut(surface, D3, path, np.ones(len(path), dtype=bool), 0.01)[0] < 1e-3
    # the straight move would have cut into it
    straight = np.vstack([a.tips, b.tips])
    assert deepest_cut(surface, D3, straight, np.ones(len(straight), dtype=bool), 0.01)[0] > 0.5


def test_a_piece_farther_than_the_longest_join_is_left_to_the_linker() -> None:
    mesh = ridge()
    surface = DropSurface(mesh)
    far = rest_joins.longest_join(D3) + 0.5
    a, b = piece(surface, 2.0, 2.0, 5.0), piece(surface, 2.0 + far, 5.0, 2.0)
    out, joins = rest_joins.join_pieces(mesh, D3, PARAMS, [a, b], surface)
    assert joins == 0 and not b.joined and len(out) == 2


def test_a_join_that_would_bring_the_holder_onto_a_wall_is_not_made() -> None:
    # a floor beside a wall 40 mm high; a ball D4 on a 20 mm stick-out: its holder reaches over the wall
    mesh = grid_mesh(lambda x, y: np.clip((x - 10.0) * 10.0, 0.0, 40.0), 120, 40, (0.0, 0.0, 30.0, 10.0), "wall")
    surface = DropSurface(mesh)
    ball = Cutter.ball(4)
    a = CutSegment(np.array([[5.0, 1.0, 0.0], [5.0, 3.0, 0.0]]))
    b = CutSegment(np.array([[5.0, 6.0, 0.0], [5.0, 8.0, 0.0]]))   # 3 mm on: longer than the radius
    free, joins = rest_joins.join_pieces(mesh, ball, PARAMS, [a, b], surface)
    assert joins == 1 and b.joined
    b.joined = False
    holder = ToolAssembly(ball, 4, 20.0, flute_length=12, holder="SK40 ER32x70")
    _, joins = rest_joins.join_pieces(mesh, ball, SurfaceParams(boundary=PARAMS.boundary, stepover=0.3,
                                                                 assembly=holder), [a, b], surface)
    assert joins == 0 and not b.joined


def plunges(tp) -> list[float]:
    """The fed descents straight down onto a segment's first tip (the entries), mm each."""
    return [tp.moves[i - 1].z - m.z for i, m in enumerate(tp.moves) if i and m.kind is MoveKind.PLUNGE]


def test_a_rest_entry_beside_a_wall_is_fed_from_above_what_stands_off_the_design_not_from_the_walls_top() -> None:
    """Beside a wall the highest stock within the tool's reach is the wall's top: the entries at its foot were fed
    from 1 mm above it. With the design known the rapid ends 1 mm above what stands off the design (the model the
    tool clears down to its tip): the same entries, shorter, no rapid into the stock, no gouge."""
    mesh = wall_mesh(80.0)
    grid = Grid.covering(WALL_X - 4.0, 0.0, WALL_X + 8.0, 10.0, 0.25)
    design = mesh_heights(mesh, grid)
    foot = (np.abs(grid.xs() - (WALL_X - 1.0)) < 1.0)[None, :] & np.ones((grid.ny, 1), dtype=bool)
    left = np.where(foot, design + 0.05, design)           # what an earlier tool left along the foot
    stock = RestStock(grid, np.where(foot, left, -np.inf), 0.002, design, TOL)
    params = SurfaceParams(boundary=PARAMS.boundary, stepover=0.3, rest=stock)
    surface = DropSurface(mesh)
    segments = [piece(surface, WALL_X - 1.2, y, y + 1.0) for y in (1.0, 4.5, 8.0)]   # at the wall's foot
    found = []
    for know in (False, True):
        policy = LinkPolicy(10.0, 12.0, material_top=StockHeights(grid, left, D3), low_links=True)
        if know:
            know_op_design(policy, mesh, params)
        tp = link(segments, policy)
        sim = simulate(tp, D3, grid, left)
        assert len(sim.collisions) == 0 and np.nanmin(sim.heights - design) > -0.005
        found.append((plunges(tp), sim.heights))
    (before, cut_before), (after, cut_after) = found
    assert len(after) == len(before) >= 3
    assert sum(after) < 0.7 * sum(before) and min(before) > 3.0 and max(after) < 1.06
    assert np.array_equal(cut_after, cut_before)   # the same cut
