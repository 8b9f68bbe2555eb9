"""Rest machining's region (core.footprint.rest): the tool envelope against a brute force over every CL position,
the rest cells and volumes against their definition, the region covering every rest cell grown by the tool radius,
and a cavity finished with a ball D10 then rested with a ball D3 inside the region: what the D3 reaches is then
within the tolerance, with a path much shorter than a full D3 finish."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.core.cavity import cavity_mesh
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import rest
from tmm_workbench.core.footprint.reach import gentle_cosine, reach_excess
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.segments import SegmentKind
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies import raster_drop, rest_filter
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter


@pytest.fixture(scope="module")
def cavity():
    return cavity_mesh()


def brute_envelope(cl: np.ndarray, grid: Grid, r: float) -> np.ndarray:
    """min over every CL position p within r of a cell centre c of z_p + (r - sqrt(r^2 - |c - p|^2)) (a ball)."""
    c = grid.centres()
    out = np.full(len(c), np.inf)
    for k, (x, y, z) in enumerate(cl):
        d2 = (c[:, 0] - x) ** 2 + (c[:, 1] - y) ** 2
        near = d2 <= r * r
        out[near] = np.minimum(out[near], z + r - np.sqrt(r * r - d2[near]))
    return out.reshape(grid.ny, grid.nx)


def test_the_envelope_is_the_lowest_tool_surface_over_every_cl_position(cavity) -> None:
    grid = Grid.covering(30.0, -6.0, 40.0, 4.0, 0.5)   # over the pocket's rim and wall
    ball = Cutter.ball(4)
    env = rest.tool_envelope(cavity, ball, grid)
    cl = DropSurface(cavity).drop(ball, grid.centres(), float(cavity.vertices[:, 2].min()))
    ref = brute_envelope(np.column_stack([grid.centres(), cl]), grid, 2.0)
    assert np.abs(env - ref).max() < 1e-6
    design = mesh_heights(cavity, grid)
    assert (env - design).min() > -1e-6          # never below the model
    assert (env - design).max() > 1.0            # the ball cannot reach into the wall's foot


def test_the_rest_is_above_the_tolerance_where_the_tool_takes_some_off() -> None:
    grid = Grid.covering(0.0, 0.0, 10.0, 10.0, 1.0)
    design = np.zeros((10, 10))
    design[0, 0] = np.nan                         # no design: never rest
    left = np.full((10, 10), 1.0)
    env = np.full((10, 10), 0.999)                # takes less than LEAST_CUT of the tolerance off everywhere but
    env[4:7, 2:5] = 0.2                           # a 3 x 3 patch it can lower
    env[9, 9] = 0.0                               # and a single cell (a large tool's cusp on a slope)
    env[0, 0] = -5.0
    area = rest.rest_area(left, design, env, grid, 0.01, 1.5)
    assert area.mask.sum() == 10 and area.mask[4:7, 2:5].all() and area.mask[9, 9]
    assert area.area == 10.0
    assert math.isclose(area.volume_before, 99.0)
    assert math.isclose(area.volume_after, 89 * 0.999 + 9 * 0.2 + 0.0)
    assert area.out_of_reach == 99.0 - 1         # the single cell lowered to the design
    for x, y in area.cells_xy():                  # every rest cell is inside the region
        assert polygons.contains_point(area.region, (x, y))
    x0, y0, x1, y1 = polygons.bounds(area.region)
    assert (x0, y0, x1, y1) == pytest.approx((2 - 1.5, 4 - 1.5, 10 + 1.5, 10 + 1.5), abs=0.02)
    assert "rest 10 mm2 in 2 region(s)" in area.summary()


def test_nothing_left_says_so() -> None:
    grid = Grid.covering(0.0, 0.0, 4.0, 4.0, 1.0)
    flat = np.zeros((4, 4))
    area = rest.rest_area(flat, flat, flat, grid, 0.01, 1.0)
    assert area.empty and area.region == [] and "nothing left" in area.summary()


@pytest.mark.parametrize("tolerance", [0.0, -0.1, float("nan")])
def test_a_tolerance_not_above_zero_is_refused(tolerance: float) -> None:
    grid = Grid.covering(0.0, 0.0, 2.0, 2.0, 1.0)
    with pytest.raises(TmmError, match="rest tolerance must be a length > 0 mm"):
        rest.rest_area(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)), grid, tolerance, 1.0)
    with pytest.raises(TmmError, match="rest left heights have shape"):
        rest.rest_area(np.zeros((3, 2)), np.zeros((2, 2)), np.zeros((2, 2)), grid, 0.01, 1.0)


def test_cutting_is_the_tool_coming_more_than_the_tolerance_below_what_is_left() -> None:
    grid = Grid.covering(0.0, 0.0, 6.0, 6.0, 0.2)
    rng = np.random.default_rng(3)
    left = rng.uniform(0.0, 0.3, (grid.ny, grid.nx))
    stock = rest_filter.RestStock(grid, left, 0.01)
    ball = Cutter.ball(2)
    tips = np.column_stack([rng.uniform(0, 6, 400), rng.uniform(0, 6, 400), rng.uniform(-0.2, 0.6, 400)])
    c = grid.centres()
    want = []
    for x, y, z in tips:   # brute force over every cell centre
        d2 = (c[:, 0] - x) ** 2 + (c[:, 1] - y) ** 2
        near = d2 <= 1.0
        surface = z + 1.0 - np.sqrt(1.0 - d2[near])
        want.append(bool(np.any(left.ravel()[near] - surface > 0.01)))
    assert rest_filter.cutting(tips, ball, stock).tolist() == want
    assert 50 < sum(want) < 350   # both kinds present


def moves(segments) -> set:
    """The straight moves (from, to) the tool makes with the tool down: within each segment and into a joined one
    from the end of the segment before it."""
    key = lambda p: tuple(np.round(p, 9))   # noqa: E731
    out = set()
    for k, seg in enumerate(segments):
        if seg.joined and k:
            out.add((key(segments[k - 1].tips[-1]), key(seg.tips[0])))
        out |= {(key(a), key(b)) for a, b in zip(seg.tips[:-1], seg.tips[1:])}
    return out


def test_a_pass_joined_across_a_left_out_link_of_one_point_is_entered_anew() -> None:
    # pass A (y 2) cuts only near its start, the zig-zag link's one point (15, 3) and pass B (y 4) cut material
    # beyond A's end: the link's run of one tip is dropped, so B reached from A's kept piece would be a straight
    # 14 mm move across what the filter left out (the 3D offset rest's -0.79 mm gouge on sphere_on_plate)
    grid = Grid.covering(-2.0, -1.0, 18.0, 8.0, 0.25)
    left = np.full((grid.ny, grid.nx), -np.inf)
    c = grid.centres().reshape(grid.ny, grid.nx, 2)
    left[np.hypot(c[..., 0], c[..., 1] - 2.0) < 0.5] = 0.5
    left[np.hypot(c[..., 0] - 15.5, c[..., 1] - 4.2) < 0.3] = 1.2
    stock = rest_filter.RestStock(grid, left, 0.01)
    x = np.arange(0.0, 15.0 + 1e-9, 0.25)
    a = rest_filter.CutSegment(np.column_stack([x, np.full_like(x, 2.0), np.zeros_like(x)]))
    link_point = rest_filter.CutSegment(np.array([[15.0, 3.0, 0.0]]), SegmentKind.LINK, joined=True)
    b = rest_filter.CutSegment(np.column_stack([x[::-1], np.full_like(x, 4.0), np.zeros_like(x)]), joined=True)
    params = SurfaceParams(boundary=(-2.0, -1.0, 18.0, 8.0), stepover=1.0, rest=stock)
    kept = rest_filter.apply(params, Cutter.ball(3), [a, link_point, b], {})
    assert len(kept) == 2 and kept[0].tips[-1, 0] < 5.0 and kept[1].tips[0, 0] == 15.0   # A's start, B's start
    assert not kept[1].joined
    assert moves(kept) <= moves([a, link_point, b])    # no move the input did not make


def path_length(tp) -> float:
    p = tp.points()
    feed = np.array([m.kind is MoveKind.FEED for m in tp.moves[1:]])
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1)[feed].sum())


def test_a_d3_rest_after_a_d10_finish_cuts_what_the_d3_reaches_and_little_else(cavity) -> None:
    grid = Grid.covering(-50, -50, 50, 0, 0.25)    # half the cavity: its pocket's corners, walls and boss
    design = mesh_heights(cavity, grid)
    policy = LinkPolicy(safe_height=5.0, clearance_height=10.0)
    box = (-50.0, -50.0, 50.0, 0.0)
    d10, d3 = Cutter.ball(10), Cutter.ball(3)
    finish = raster_drop.compute_surface_toolpath(cavity, d10, SurfaceParams(boundary=box, stepover=0.6,
                                                                             sample_step=0.25), policy)
    left = simulate(finish, d10, grid, box_heights(grid, 0.0)).heights
    envelope = rest.tool_envelope(cavity, d3, grid)
    area = rest.rest_area(left, design, envelope, grid, 0.01, d3.radius)
    assert area.volume_before > 5 * area.volume_after > 0
    step = 2 * math.sqrt(2 * d3.radius * 0.008)   # a cusp of 0.008 mm between the rest passes
    params = SurfaceParams(boundary=polygons.bounds(area.region), region=area.region, stepover=step, sample_step=0.25,
                           rest=area.stock(left))
    rest_path = link(raster_drop.compute(cavity, d3, params).segments, policy)
    full = raster_drop.compute_surface_toolpath(cavity, d3, SurfaceParams(boundary=box, stepover=step,
                                                                          sample_step=0.25), policy)
    after = simulate(rest_path, d3, grid, left).heights - design
    # where the D3 reaches along the normal, within the tolerance along the normal (the D10's raster leaves its
    # cusps on the walls too: the rest's loops take them)
    reach = np.isfinite(design) & (reach_excess(envelope, design, grid.cell, d3.radius) <= 0.01)
    normal = np.where(reach, after * gentle_cosine(design, grid.cell), np.nan)
    assert np.nanmax(normal) < 0.015                                # the sim's cells read a little over
    assert np.sum(normal > 0.01) < 0.001 * reach.sum()
    assert np.nanmin(after) > -0.005                                # no gouge, links included
    # the passes alone (no loops, no touch-ups) go only where the D10 left rest
    passes = replace(params, rest=replace(params.rest, design=None))
    assert path_length(link(raster_drop.compute(cavity, d3, passes).segments, policy)) < 0.5 * path_length(full)
