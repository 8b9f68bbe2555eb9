"""The linker's approach: where the material's top over an entry is known (the segment's entry_z, the policy's
material_top: the lower of the two), the tool rapids down to entry_clearance above it and is fed only from
there; unknown, it is fed from the safe height as before. heights_top drops the tool onto a height grid (cells
stand for material up to half their diagonal nearer). The simulation sees no rapid into the stock."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.linking import HELIX, LinkPolicy, StockHeights, heights_top, link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter


def line(z: float, x0: float = 0.0, x1: float = 10.0, y: float = 0.0) -> np.ndarray:
    return np.array([[x0, y, z], [x1, y, z]])


def kinds_z(tp, n: int) -> list:
    return [(m.kind, round(m.z, 9)) for m in tp.moves[:n]]


def test_plunge_rapids_to_the_clearance_above_the_known_top():
    const = lambda top: (lambda xy: np.full(len(xy), top))  # noqa: E731
    pol = LinkPolicy(20.0, 25.0, material_top=const(4.0))
    tp = link([CutSegment(line(0.0))], pol)
    assert kinds_z(tp, 4) == [(MoveKind.RAPID, 25.0), (MoveKind.RAPID, 20.0), (MoveKind.RAPID, 5.0),
                              (MoveKind.PLUNGE, 0.0)]
    # the segment's entry_z and the policy's top: the lower one (both bound the material from above)
    tp = link([CutSegment(line(0.0), entry_z=2.0)], LinkPolicy(20.0, 25.0, entry_clearance=0.5,
                                                                   material_top=const(4.0)))
    assert tp.moves[2].z == 2.5 and tp.moves[3].kind is MoveKind.PLUNGE
    # no material there: the clearance above the tip; not known (+inf, NaN) or above the safe height: as before
    assert link([CutSegment(line(0.0))], LinkPolicy(20.0, 25.0, material_top=const(-math.inf))).moves[2].z == 1.0
    plain = link([CutSegment(line(0.0))], LinkPolicy(20.0, 25.0))
    for top in (math.inf, math.nan, 19.5):
        assert link([CutSegment(line(0.0))], LinkPolicy(20.0, 25.0, material_top=const(top))).moves == plain.moves
    assert kinds_z(plain, 3) == [(MoveKind.RAPID, 25.0), (MoveKind.RAPID, 20.0), (MoveKind.PLUNGE, 0.0)]


def test_helix_without_entry_z_starts_at_the_material_top_over_its_path():
    """The policy's material top over the helix's XY: 6 mm on the helix's -X half, 3 mm elsewhere; the helix
    starts at 6 (the highest over its path), the rapid ends 1 mm above that."""
    top = lambda xy: np.where(xy[:, 0] < 0.0, 6.0, 3.0)  # noqa: E731
    seg = CutSegment(line(0.0, 2.0, 12.0), entry=HELIX, helix_centre=(0.0, 0.0))
    tp = link([seg], LinkPolicy(20.0, 25.0, ramp_angle_deg=5.0, material_top=top))
    pts = tp.points()
    k = [m.kind for m in tp.moves].index(MoveKind.PLUNGE)
    assert tp.moves[k - 1].kind is MoveKind.RAPID and tp.moves[k - 1].z == pytest.approx(7.0)
    assert pts[k, 2] == pytest.approx(6.0) and pts[k + 1:-1, 2].max() <= 6.0 + 1e-12
    helix_len = np.hypot(*np.diff(pts[k:-1], axis=0)[:, :2].T)
    assert helix_len.sum() >= 6.0 / math.tan(math.radians(5.0))


def test_heights_top_drops_the_tool_onto_the_cells():
    grid = Grid(0.0, 0.0, 1.0, 20, 20)
    h = np.zeros((20, 20))
    h[10, 14] = 5.0                                   # a spike at the cell centre (14.5, 10.5)
    ball = Cutter.ball(6)
    pad = math.sqrt(0.5)
    flat = heights_top(grid, h, 3.0)
    rounded = heights_top(grid, h, 3.0, ball.native.height)
    # 2 mm, 5.5 mm and 0 mm from the spike; between its centre and a neighbour's the stock may stand at 5 too
    at = np.array([[12.5, 10.5], [9.0, 10.5], [14.5, 10.5]])
    assert flat(at).tolist() == [5.0, 0.0, 5.0]
    assert rounded(at)[0] == pytest.approx(5.0 - ball.native.height(np.array([1.0 - pad]))[0])
    assert rounded(at)[2] == 5.0
    # near the edge: what lies off the grid
    assert heights_top(grid, h, 3.0, outside=math.inf)(np.array([[1.0, 10.0]]))[0] == math.inf
    assert heights_top(grid, h, 3.0)(np.array([[1.0, 10.0]]))[0] == 0.0
    assert heights_top(grid, h, 3.0)(np.array([[-50.0, 10.0]]))[0] == -math.inf


def test_no_rapid_into_a_stepped_stock_and_less_plunging():
    """A stock 10 mm high with a 6 mm deep slot cut along y = 20 (what an earlier op left); passes at z 3 in the
    slot, one lifted after another: with the stock's heights the rapids end 1 mm above the slot's material, the
    simulation sees none of them cut, and the plunging is shorter than from the safe height."""
    grid = Grid.covering(0, 0, 40, 40, 0.25)
    stock = box_heights(grid, 10.0)
    Y = np.meshgrid(grid.xs(), grid.ys())[1]
    stock[np.abs(Y - 20.0) < 8.0] = 4.0
    tool = Cutter.flat(6)
    segs = [CutSegment(line(3.0, 5.0, 35.0, y)) for y in (18.0, 20.0, 22.0)]
    top = heights_top(grid, stock, tool.radius)
    known = link(segs, LinkPolicy(30.0, 35.0, material_top=top))
    blind = link(segs, LinkPolicy(30.0, 35.0))
    for tp in (known, blind):
        assert len(simulate(tp, tool, grid, stock).collisions) == 0
    plunged = lambda tp: sum(abs(b.z - a.z) for a, b in zip(tp.moves, tp.moves[1:])  # noqa: E731
                             if b.kind is MoveKind.PLUNGE)
    assert plunged(known) == pytest.approx(3 * 2.0) and plunged(blind) == pytest.approx(3 * 27.0)
    # the same rapids into the full 10 mm stock would cut: the heights are what makes them safe
    full = box_heights(grid, 10.0)
    assert len(simulate(known, tool, grid, full).collisions) == 3


def test_a_wall_between_two_cell_centres_is_above_the_lower_one():
    """A height is the stock's at its cell's centre: between a cut centre (0) and an uncut one (10) the stock may
    rise to 10 anywhere short of the cut centre (a relief's wall). A tool whose reach ends just past the cut
    centre, a cell short of the uncut one, must see 10 there (mount_rush: a rapid ended 11 mm inside the stock)."""
    grid = Grid(0.0, 0.0, 1.0, 20, 5)
    h = np.zeros((5, 20))
    h[:, 10] = 10.0                       # the uncut column's centres at x = 10.5; cut centres at x = 11.5
    radius = 2.0
    pad = math.sqrt(0.5)
    x = 11.5 + radius + pad - 0.05        # the cut centre just within reach, the uncut one a cell beyond it
    top = heights_top(grid, h, radius)(np.array([[x, 2.5]]))[0]
    assert top == 10.0
    far = heights_top(grid, h, radius)(np.array([[x + 1.2, 2.5]]))[0]
    assert far == 0.0                     # two cells away the wall cannot reach


def test_low_links_hop_just_above_the_material_between_and_never_through_it():
    """The slotted stock above with a 7 mm rib left standing across the slot at x = 20: passes in the slot either
    side of it. Low links hop at 1 mm over the highest material top along the way (the rib), never up to the safe
    height, and the simulation sees no rapid cut; without a known top they stay at the safe height."""
    grid = Grid.covering(0, 0, 40, 40, 0.25)
    stock = box_heights(grid, 10.0)
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    stock[np.abs(Y - 20.0) < 8.0] = 4.0
    stock[(np.abs(Y - 20.0) < 8.0) & (np.abs(X - 20.0) < 1.0)] = 7.0
    tool = Cutter.ball(4)
    segs = [CutSegment(line(3.0, 5.0, 15.0, 18.0)), CutSegment(line(3.0, 25.0, 35.0, 22.0)),
            CutSegment(line(3.0, 35.0, 25.0, 20.0))]
    policy = LinkPolicy(30.0, 35.0, material_top=StockHeights(grid, stock, tool), low_links=True)
    tp = link(segs, policy)
    assert len(simulate(tp, tool, grid, stock).collisions) == 0
    rapids = [m for m in tp.moves[2:-1] if m.kind is MoveKind.RAPID]
    assert rapids and max(m.z for m in rapids) < 9.0        # over the rib (7 + 1), below the stock's 10 top
    end = next(i for i, m in enumerate(tp.moves) if (m.x, m.y, m.z) == (15.0, 18.0, 3.0))
    up, across = tp.moves[end + 1], tp.moves[end + 2]   # the hop over the rib to the second pass
    assert (up.kind, across.kind) == (MoveKind.RAPID, MoveKind.RAPID) and (up.x, up.y) == (15.0, 18.0)
    assert up.z == across.z == pytest.approx(8.0, abs=0.01) and (across.x, across.y) == (25.0, 22.0)
    high = link(segs, LinkPolicy(30.0, 35.0, material_top=StockHeights(grid, stock, tool)))
    assert max(m.z for m in high.moves[2:-1]) == 30.0


def test_a_low_link_crosses_above_an_entry_lifted_over_the_material():
    """A pass whose first tip stands above the material (the holder guard lifted it beside a wall): the low link
    crosses at 1 mm over that tip, not over the material only and then up (that drove a rest's shank into
    wheel_in_box's wall)."""
    grid = Grid.covering(0, 0, 40, 40, 0.25)
    stock = box_heights(grid, 4.0)
    tool = Cutter.ball(4)
    segs = [CutSegment(line(3.0, 5.0, 15.0, 18.0)), CutSegment(line(12.0, 25.0, 35.0, 22.0))]
    tp = link(segs, LinkPolicy(30.0, 35.0, material_top=StockHeights(grid, stock, tool), low_links=True))
    end = next(i for i, m in enumerate(tp.moves) if (m.x, m.y, m.z) == (15.0, 18.0, 3.0))
    up, across = tp.moves[end + 1], tp.moves[end + 2]
    assert (up.x, up.y) == (15.0, 18.0) and (across.x, across.y) == (25.0, 22.0)
    assert up.z == across.z >= 12.0 + 1.0 - 1e-9


def test_a_low_link_the_shank_would_not_clear_goes_up_to_the_safe_height():
    """The same passes, with a hop check (LinkPolicy.hop_clear: a shank or holder beside a wall) that refuses
    the hop over the rib only: that link lifts to the safe height, the other stays low."""
    grid = Grid.covering(0, 0, 40, 40, 0.25)
    stock = box_heights(grid, 10.0)
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    stock[np.abs(Y - 20.0) < 8.0] = 4.0
    tool = Cutter.ball(4)
    segs = [CutSegment(line(3.0, 5.0, 15.0, 18.0)), CutSegment(line(3.0, 25.0, 35.0, 22.0)),
            CutSegment(line(3.0, 35.0, 25.0, 20.0))]
    asked = []

    def clear(path: np.ndarray) -> bool:
        asked.append(path.copy())
        return not (path[0, 0] < 20.0 < path[1, 0])          # the move across x = 20
    policy = LinkPolicy(30.0, 35.0, material_top=StockHeights(grid, stock, tool), low_links=True, hop_clear=clear)
    tp = link(segs, policy)
    assert len(asked) == 2 and all(p.shape == (2, 3) and p[0, 2] == p[1, 2] for p in asked)
    end = next(i for i, m in enumerate(tp.moves) if (m.x, m.y, m.z) == (15.0, 18.0, 3.0))
    assert tp.moves[end + 1].z == 30.0                       # up to the safe height over x = 20
    second = next(i for i, m in enumerate(tp.moves) if (m.x, m.y, m.z) == (35.0, 22.0, 3.0))
    assert tp.moves[second + 1].z < 9.0                      # the other hop stays low
