"""Seed 000's clean-up strips (core.footprint.cleanup) on the crease and groove of tests/core/crease_case.py: the
derived threshold, the strips a ball D10 leaves, their curves slid to the crease by the drop along a vector, the
flank passes, and the pencil source 'cleanup' of the Surface's pattern."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.core.crease_case import GROOVE_Y, HEIGHT, WALL_X, WIDTH, crease_mesh, fold_x
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import cleanup, pencil
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

D10, D2 = Cutter.ball(10), Cutter.ball(2)


@pytest.fixture(scope="module")
def case():
    mesh = crease_mesh()
    surface = DropSurface(mesh)
    grid = Grid.covering(0, 0, WIDTH, HEIGHT, 0.25)
    found = cleanup.strips(mesh, surface, D10, grid, mesh_heights(mesh, grid), None, 0.01, D2.diameter)
    return mesh, surface, grid, found


def test_the_jump_limit_is_where_the_corner_left_reaches_the_tolerance() -> None:
    limit = cleanup.jump_limit(D10, 0.01)
    assert 5.0 * (1 / math.cos(limit / 2) - 1) == pytest.approx(0.01, rel=1e-12)
    assert math.degrees(limit) == pytest.approx(7.24, abs=0.01)
    assert cleanup.jump_limit(Cutter.bull(10, 1), 0.01) > limit   # a smaller corner bridges more before it leaves
    with pytest.raises(TmmError, match="has no corner radius"):
        cleanup.jump_limit(Cutter(10, 0), 0.01)
    with pytest.raises(TmmError, match="clean-up tolerance must be a length > 0 mm, got 0"):
        cleanup.jump_limit(D10, 0)


def test_the_strips_lie_between_the_d10_contacts_at_the_wall_and_over_the_groove(case) -> None:
    mesh, surface, grid, found = case
    xs, ys = grid.xs(), grid.ys()
    row = found.jumps[int(30 / 0.25)]            # y = 30: across the wall's foot
    band = xs[row]
    # from the D10's floor contact (under its tip, touching both) to its wall contact, 5 sin 75 deg further
    assert band.min() == pytest.approx(fold_x(5.0), abs=0.5)
    assert band.max() == pytest.approx(fold_x(5.0) + 5.0 * math.sin(math.radians(75.0)), abs=0.5)
    col = found.jumps[:, int(18 / 0.25)]          # x = 18: across the groove, its rims 1.5 mm either side
    assert ys[col].min() == pytest.approx(GROOVE_Y - 1.5, abs=0.5)   # slopes read over a cell: a little in
    assert ys[col].max() == pytest.approx(GROOVE_Y + 1.5, abs=0.5)
    assert not found.jumps[:, int(50 / 0.25)].any()              # the plateau: nothing
    groove = [c for c in found.curves if abs(np.median(c[:, 1]) - GROOVE_Y) < 0.5 and np.median(c[:, 0]) < 35]
    assert len(groove) == 1                                      # one medial curve, not one per ridge cell


def test_the_strip_points_slide_to_the_two_contact_position(case) -> None:
    mesh, surface, grid, found = case
    pts = np.array([[WALL_X - 2.5, 25.0], [WALL_X - 0.4, 25.0], [18.0, GROOVE_Y + 0.3], [18.0, GROOVE_Y],
                    [18.0, GROOVE_Y + 0.03], [5.67, 19.13]])
    across = np.array([[-1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.0], [0.0, 1.0], [-0.6, 0.8]])
    slide = cleanup.slide_to_crease(mesh, surface, D2, pts, across, -5.0, 10.0)
    assert slide.xy[0, 0] == pytest.approx(fold_x(1.0), abs=1e-3)   # from the floor, horizontally, to the wall
    assert slide.direction[0, 2] == pytest.approx(0.0, abs=1e-9)
    assert slide.xy[1, 0] == pytest.approx(fold_x(1.0), abs=2e-3)   # from the wall's flank, down it
    assert slide.direction[1, 2] < -0.5
    assert slide.xy[2, 1] == pytest.approx(GROOVE_Y, abs=2e-3)      # down the groove's flank to its middle
    assert slide.moved[3] < 1e-6                                     # in the groove's fold already: kept
    # within a probe of the fold (both sides higher): moved into it, to the groove's middle and to the crease of
    # its sloped end with its flank (x - 5 = y - 18.5) whatever the direction across
    assert slide.xy[4, 1] == pytest.approx(GROOVE_Y, abs=1e-5)
    assert slide.xy[5, 0] - 5.0 == pytest.approx(slide.xy[5, 1] - 18.5, abs=1e-5)
    z = surface.drop(D2, slide.xy, -5.0)
    assert z[0] == pytest.approx(0.0, abs=1e-3)                      # on the floor, against the wall


def test_the_strip_keeps_its_short_branches_into_the_groove_ends(case) -> None:
    # the groove's sloped ends meet its flanks in creases running to its corners: the strip's medial axis forks
    # there in branches shorter than the clean-up tool (a D2), kept as branches of the groove's curve
    found = case[3]
    groove = [c for c in found.curves if np.median(c[:, 0]) < 35 and np.abs(c[:, 1] - GROOVE_Y).max() < 2]
    trunk = max(groove, key=len)
    branches = [c for c in groove if pencil.curve_length(c) < D2.diameter]
    assert len(branches) == 2
    assert sorted(np.median(c[:, 0]) < 15 for c in branches) == [False, True]   # one at each end
    for c in branches:
        gaps = [np.hypot(*(trunk - p).T).min() for p in (c[0], c[-1])]
        assert min(gaps) < 1.0                                   # joined to the groove's curve
        tip = c[int(np.argmax(gaps)) * -1]
        assert tip[1] > GROOVE_Y + 0.2                           # towards the corners the trunk's ends miss


def test_the_cleaned_curves_and_the_flank_passes(case) -> None:
    mesh, surface, grid, found = case
    curves, slide = cleanup.cleanup_curves(mesh, surface, D2, found, -5.0, 10.0, 0.25)
    wall = max(curves, key=len)
    middle = wall[np.abs(wall[:, 1] - 20) < 10]
    assert np.abs(middle[:, 0] - fold_x(1.0)).max() < 2e-3
    step = 0.25
    passes = cleanup.flank_passes(surface, D2, [middle], -5.0, step, 3)
    xs = sorted(float(np.median(p[:, 0])) for p in passes)
    wall_side = [x for x in xs if x > fold_x(1.0)]
    floor_side = [x for x in xs if x < fold_x(1.0)]
    assert len(wall_side) == 3 and len(floor_side) == 3
    assert floor_side[-1] == pytest.approx(fold_x(1.0) - step, abs=1e-3)   # a floor: the step itself
    slope = math.tan(math.radians(75.0))
    assert wall_side[0] - fold_x(1.0) == pytest.approx(step * (1 + slope ** 2) ** -0.75, rel=0.05)


def test_pencil_valleys_two_cells_wide_give_one_curve_when_strict() -> None:
    xs = ys = np.arange(40) * 0.5
    z = np.zeros((40, 40))
    z[:, 19:21] = -1.0      # a flat-bottomed valley two cells wide
    loose = pencil.valley_curves(xs, ys, z, 0.1, 2.0)
    strict = pencil.valley_curves(xs, ys, z, 0.1, 2.0, strict=True)
    assert len(strict) == 1 and np.ptp(strict[0][:, 0]) < 1e-9     # one column of the two
    assert np.ptp(np.vstack(loose)[:, 0]) > 0.05                     # both: a zig-zag between them


def test_the_pencil_source_cleanup_needs_its_finishing_tool(case) -> None:
    mesh = case[0]
    with pytest.raises(TmmError, match="pencil source 'cleanup' needs the finishing tool"):
        SurfaceParams(boundary=(0, 0, WIDTH, HEIGHT), pattern="pencil", pencil_source="cleanup").validate()
    params = SurfaceParams(boundary=(30, 10, 45, 30), pattern="pencil", pencil_source="cleanup",
                           cleanup_reference=D10, pencil_passes=1, sample_step=0.5, cusp=0.01)
    res = raster_drop.compute(mesh, D2, params)
    tips = np.vstack([s.tips for s in res.segments])
    at_foot = tips[np.abs(tips[:, 0] - fold_x(1.0)) < 2e-3]
    assert len(at_foot) >= 2 and np.abs(at_foot[:, 2]).max() < 2e-3


def test_the_groove_end_is_cleaned_within_the_tolerance_where_the_d2_reaches() -> None:
    # seed 000's case at the groove's end (x 30): finished with the D10 (cusp 0.01 mm), cleaned up with the D2;
    # simulated: every cell the D2 can bring within 0.01 mm of the design is within it, no gouge below -0.005 mm
    from tmm_workbench.core.linking import LinkPolicy, StockHeights, link
    from tmm_workbench.core.sim.simulate import simulate
    from tests.core.rest_case import after_d10

    mesh, tol = crease_mesh(), 0.01
    case = after_d10(mesh, (24.0, 14.0, 34.0, 26.0), 0.1, D2, 2.0, 8.0)
    grid, design, left, envelope, area = case.grid, case.design, case.left, case.envelope, case.area
    params = SurfaceParams(boundary=(25.0, 15.0, 33.0, 25.0), region=area.region, sample_step=0.2,
                           rest=area.stock(left), pattern="pencil", pencil_passes=0, pencil_source="cleanup",
                           cleanup_reference=D10, stepover=2 * math.sqrt(2 * 1.0 * 0.8 * tol), cusp=tol)
    tp = link(raster_drop.compute(mesh, D2, params).segments,
              LinkPolicy(8.0, 10.0, material_top=StockHeights(grid, left, D2), low_links=True))
    after = simulate(tp, D2, grid, left).heights
    inner = np.zeros_like(design, dtype=bool)
    inner[10:-10, 10:-10] = True                       # a millimetre in from the finish's boundary
    reach = inner & np.isfinite(design) & (envelope - design <= tol)
    assert np.nanmax(np.where(reach, left - design, np.nan)) > 0.3      # the D10 left the end's creases
    assert np.nanmax(np.where(reach, after - design, np.nan)) <= tol
    assert np.nanmin(after - design) > -0.005
