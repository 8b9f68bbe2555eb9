"""The shank and holder against the in-process stock (core.sim.stock_bodies): a flat plate with a block of stock
an earlier op left standing beside the passes, taller than the flutes. The model-only guard passes the shank
through the block (the simulation's body check finds it); with the stock known the guard lifts the tool there or
leaves those moves out, and the body check is clean; the linker's hop check sees the block too. Where nothing
stands off the design the heights are the model's, exactly; the grown body's lower envelope against a brute-force
one."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy, StockHeights
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.sim.stock_bodies import InProcessStock, StockAwareDrop, give, lower_envelope
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.strategies import holder_guard, raster_drop, rest_joins
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

BALL = Cutter.ball(4)
TOOL = ToolAssembly(BALL, 4, 30.0, flute_length=8)   # shank D4, clearance 1 mm, no holder
POLICY = LinkPolicy(safe_height=40.0, clearance_height=45.0)
GRID = Grid.covering(-20.0, -10.0, 20.0, 10.0, 0.25)
BLOCK = (-3.0, 2.5, 3.0, 6.0, 12.0)   # x0, y0, x1, y1, top: 12 mm of stock beside the pass at y 0


@pytest.fixture(scope="module")
def plate():
    return grid_mesh(lambda x, y: np.zeros_like(x), 8, 4, (-20.0, -10.0, 20.0, 10.0), "plate")


def stock_heights(block: bool = True) -> np.ndarray:
    x, y = np.meshgrid(GRID.xs(), GRID.ys())
    z = np.zeros((GRID.ny, GRID.nx))
    if block:
        x0, y0, x1, y1, top = BLOCK
        z[(x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)] = top
    return z


def stock(block: bool = True) -> InProcessStock:
    return InProcessStock(GRID, stock_heights(block), within=0.01, design=np.zeros((GRID.ny, GRID.nx)))


def params(**kw) -> SurfaceParams:
    base = dict(boundary=(-15.0, -0.5, 15.0, 0.5), stepover=2.0, sample_step=0.5, angle_deg=0.0, assembly=TOOL)
    return SurfaceParams(**{**base, **kw})


def body_check(path) -> object:
    """The simulation's body check (the kernel's), at the depth the guard lets a move pass under the bodies'
    height between its points (holder_guard.BETWEEN_MM)."""
    return simulate(path, BALL, GRID, stock_heights(), assembly=TOOL,
                    body_tolerance=holder_guard.BETWEEN_MM).stock_collisions


def test_the_model_only_guard_drives_the_shank_into_the_stock(plate) -> None:
    notes: list = []
    path = raster_drop.compute_surface_toolpath(plate, BALL, params(holder_notes=notes), POLICY)
    assert notes[0].affected == 0   # the plate alone never comes near the shank
    found = body_check(path)
    assert not found.ok and set(found.per_piece) == {"shank"} and found.deepest > 3.0


def test_with_the_stock_the_guard_lifts_the_tool_and_the_shank_stays_clear(plate) -> None:
    notes: list = []
    path = raster_drop.compute_surface_toolpath(plate, BALL, params(holder_notes=notes, stock=stock()), POLICY)
    report = notes[0]
    assert report.affected > 0 and set(report.pieces) == {"shank"}
    # the shank's grown bottom (8 - 1 mm above the tip) over the 12 mm block: the tip at 5 mm at least
    assert report.max_lift == pytest.approx(12.0 - 7.0, abs=0.05)
    x0, _, x1, _ = report.region
    assert -3.0 - 3.5 <= x0 and x1 <= 3.0 + 3.5      # only where the block stands within the shank's reach
    assert body_check(path).ok, body_check(path).summary()


def test_with_the_stock_leave_out_cuts_only_where_the_shank_is_clear(plate) -> None:
    notes: list = []
    path = raster_drop.compute_surface_toolpath(
        plate, BALL, params(holder_notes=notes, stock=stock(), holder_collision="leave_out"), POLICY)
    assert notes[0].affected > 0
    pts = path.points()
    low = pts[pts[:, 2] < 1.0]
    assert len(low) and not np.any(np.abs(low[:, 0]) < 3.0)   # nothing cut beside the block
    assert body_check(path).ok, body_check(path).summary()


def test_nothing_off_the_design_gives_the_models_heights_exactly(plate) -> None:
    rng = np.random.default_rng(3)
    xy = np.column_stack([rng.uniform(-19, 19, 500), rng.uniform(-9, 9, 500)])
    model = AssemblyDrop(plate, TOOL).heights_of(holder_guard.BODIES, xy)
    aware = StockAwareDrop(plate, TOOL, None, stock(block=False)).heights_of(holder_guard.BODIES, xy)
    assert np.array_equal(model[0], aware[0]) and np.array_equal(model[1], aware[1])
    with_block = StockAwareDrop(plate, TOOL, None, stock()).heights_of(holder_guard.BODIES, xy)
    far = np.hypot(np.maximum(np.abs(xy[:, 0]) - 3.0, 0), np.maximum(np.maximum(2.5 - xy[:, 1], xy[:, 1] - 6), 0)) > 3.2
    assert np.array_equal(with_block[0][far], model[0][far])   # beyond the shank's reach of the block: unchanged
    assert np.all(with_block[0][~far] >= model[0][~far]) and np.any(with_block[0] > model[0] + 4.0)


def test_the_hop_check_sees_the_stock(plate) -> None:
    hop = np.array([[-10.0, 0.0, 1.0], [10.0, 0.0, 1.0]])
    assert rest_joins.bodies_clear(plate, TOOL)(hop)
    assert not rest_joins.bodies_clear(plate, TOOL, stock=stock())(hop)
    assert rest_joins.bodies_clear(plate, TOOL, stock=stock())(hop + [0.0, 0.0, 6.0])


def test_give_sets_the_stock_only_with_an_assembly_and_a_known_stock(plate) -> None:
    left = StockHeights(GRID, stock_heights(), BALL)
    p = params()
    give(p, left, plate)
    assert p.stock is not None and np.array_equal(p.stock.heights, left.heights)
    left.heights[:] = -1.0                       # the linker cuts its stock as it links: the guard's is a copy
    assert p.stock.excess().max() == 12.0
    give(p, None, plate)
    assert p.stock is None
    q = params(assembly=None)
    give(q, left, plate)
    assert q.stock is None


def test_the_design_the_linker_knows_is_taken_not_dropped_again(plate) -> None:
    """An op's linker drops the mesh's heights onto the same grid (know_op_design) before the guard asks: the
    stock takes those, and its material off the design is what the mesh's own drop gives."""
    from tmm_workbench.core.linking import know_op_design

    own = params()
    give(own, StockHeights(GRID, stock_heights(), BALL), plate)
    left = StockHeights(GRID, stock_heights(), BALL)
    p, policy = params(), LinkPolicy(safe_height=40.0, clearance_height=45.0, material_top=left)
    give(p, left, plate)
    assert know_op_design(policy, plate, p) and left.design is not None
    assert np.array_equal(p.stock.excess(), own.stock.excess())
    assert p.stock.design is left.design


@pytest.mark.parametrize("body", [(8.0, 30.0, 2.0, 2.0, 1.0), (8.0, 12.0, 1.0, 3.0, 0.5), (5.0, 9.0, 3.0, 1.5, 0.8),
                                  (30.0, 60.0, 10.0, 10.0, 1.0)])
def test_the_grown_bodys_lower_envelope_against_brute_force(body) -> None:
    z0, z1, r0, r1, c = body
    rho = np.linspace(0.0, max(r0, r1) + c + 0.5, 301)
    h = np.linspace(0.0, 1.0, 801)
    outline = np.vstack([np.column_stack([h * r0, np.full_like(h, z0)]),                      # the bottom
                         np.column_stack([r0 + h * (r1 - r0), z0 + h * (z1 - z0)])])         # the side
    brute = np.full(len(rho), math.inf)
    for a, b in outline:
        d = np.abs(rho - a)
        ok = d <= c + 1e-12
        brute[ok] = np.minimum(brute[ok], b - np.sqrt(np.maximum(c * c - d[ok] ** 2, 0.0)))
    got = lower_envelope(body, rho)
    assert np.all(np.isinf(got[rho > max(r0, r1) + c + 1e-9]))   # beyond the grown rim: nothing
    inner = rho < max(r0, r1) + c - 0.05    # (at the rim the sampled outline's error grows as a square root)
    assert np.all(np.isfinite(got[inner])) and np.all(np.isfinite(brute[inner]))
    assert np.all(got[inner] <= brute[inner] + 1e-9) and np.all(brute[inner] - got[inner] < 2e-3)


def test_bad_stock_is_refused_by_name() -> None:
    with pytest.raises(TmmError, match="stock heights have shape"):
        InProcessStock(GRID, np.zeros((3, 3)), design=np.zeros((3, 3)))
    with pytest.raises(TmmError, match="within"):
        InProcessStock(GRID, stock_heights(), within=-1.0, design=np.zeros((GRID.ny, GRID.nx)))
    with pytest.raises(TmmError, match="design"):
        InProcessStock(GRID, stock_heights())
