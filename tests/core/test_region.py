"""Machining regions, the spiral and the slope range (issue 14 item 3): passes clipped exactly to a region
with holes (checked against Clipper's point-in-polygon on dense samples), every cutting move's tool centre
inside the region with lifts between chains, the spiral covering the region within the step-over, the
slope filter against a sphere's known slope, and a simulated cut: no gouge, the stock farther than the tool
radius outside the region untouched, the region itself cut; bad input refused by name."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import region, spiral
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.sim.compare import compare
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute, compute_surface_toolpath
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter

WAVY = grid_mesh(lambda x, y: 2.0 + 0.08 * x + 0.6 * np.sin(y / 4.0), 60, 60, (0, 0, 60, 60), "wavy")


def ring_with_notch() -> polygons.Shape:
    """A disc (r 20 about (30, 30)) with a square hole and a notch cut from its rim."""
    disc = [polygons.circle((30, 30), 20, 0.01)]
    hole = [polygons.rectangle(24, 26, 34, 33), polygons.rectangle(10, 28, 16, 32)]
    return polygons.difference(disc, hole)


def distance_to_boundary(p: np.ndarray, shape: polygons.Shape) -> float:
    a, b = region.edges_of(shape)
    ab = b - a
    t = np.clip(((p - a) * ab).sum(axis=1) / (ab * ab).sum(axis=1), 0, 1)
    return float(np.hypot(*(a + t[:, None] * ab - p).T).min())


def inside(shape: polygons.Shape, pts: np.ndarray) -> np.ndarray:
    """Even-odd ray crossing (+X) over all the shape's edges, vectorised (the shapes here are clean unions,
    where even-odd and non-zero agree); an independent check of clip_line's winding rule."""
    pts = np.asarray(pts, dtype=float).reshape(-1, 2)
    a, b = region.edges_of(shape)
    x, y = pts[:, :1], pts[:, 1:]
    straddle = (a[None, :, 1] > y) != (b[None, :, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[None, :, 0] + (y - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (b[None, :, 1] - a[None, :, 1])
    return ((straddle & (xc > x)).sum(axis=1) % 2) == 1


@pytest.mark.parametrize("angle", [0.0, 30.0, 90.0, 137.0])
def test_raster_clipped_exactly_against_the_polygon(angle):
    shape = ring_with_notch()
    a = math.radians(angle)
    n = np.array([-math.sin(a), math.cos(a)])
    across = np.vstack(shape) @ n
    lines = region.region_lines(shape, np.linspace(across.min(), across.max(), 23), angle)
    per_pass = region.clip_raster(lines, shape)
    assert sum(len(p) for p in per_pass) > 23  # the hole and the notch split passes
    for ln, pieces in zip(lines, per_pass):
        d = (ln[1] - ln[0]) / np.hypot(*(ln[1] - ln[0]))
        for piece in pieces:
            assert (piece[1] - piece[0]) @ d > 0                               # in the pass direction
            for end in piece:
                assert distance_to_boundary(end, shape) < 1e-9                # ends exactly on an edge
        starts = [float((p[0] - ln[0]) @ d) for p in pieces]
        assert starts == sorted(starts)
        # the reference: dense samples along the line classified by Clipper's point-in-polygon; away from the
        # piece ends (by 1e-6 mm, Clipper's grid) each sample is inside exactly when it is in a piece
        s = np.linspace(0, float(np.hypot(*(ln[1] - ln[0]))), 401)
        pts = ln[0] + s[:, None] * d
        in_piece = np.zeros(len(s), bool)
        near_end = np.zeros(len(s), bool)
        for piece in pieces:
            t0, t1 = float((piece[0] - ln[0]) @ d), float((piece[1] - ln[0]) @ d)
            in_piece |= (s >= t0) & (s <= t1)
            near_end |= (np.abs(s - t0) < 1e-5) | (np.abs(s - t1) < 1e-5)
        ref = np.array([polygons.contains_point(shape, p) for p in pts])
        assert np.array_equal(ref[~near_end], in_piece[~near_end])


def test_region_path_stays_inside_and_jumps_between_chains():
    shape = ring_with_notch()
    cutter = Cutter.ball(4)
    params = SurfaceParams(boundary=polygons.bounds(shape), stepover=1.5, sample_step=0.5, angle_deg=20,
                           region=shape)
    result = compute(WAVY, cutter, params)
    assert result.diagnostics["jumps"] >= 1 and result.diagnostics["passes"] > 27
    tp = compute_surface_toolpath(WAVY, cutter, params, LinkPolicy(safe_height=15, clearance_height=20))
    moves = list(tp)
    edges = region.edges_of(shape)
    for prev, m in zip(moves, moves[1:]):
        if m.kind is MoveKind.FEED:  # every cutting move's tool centre inside the region, all along the move
            a, b = np.array([prev.x, prev.y]), np.array([m.x, m.y])
            assert region.segment_inside(a, b, shape, edges, tol=1e-5), (a, b)
    lifts = sum(1 for m in moves if m.kind is MoveKind.RAPID and m.z == 15)
    assert lifts >= 2 * result.diagnostics["jumps"]       # up and across at the safe height per jump


def test_one_way_in_a_region_enters_each_piece_from_above():
    shape = ring_with_notch()
    params = SurfaceParams(boundary=polygons.bounds(shape), stepover=2.0, sample_step=0.5, region=shape,
                           pattern="oneway")
    result = compute(WAVY, Cutter.ball(4), params)
    assert all(not s.joined for s in result.segments)
    assert len(result.segments) == result.diagnostics["passes"]


def test_spiral_covers_the_region_within_the_step_over():
    shape = ring_with_notch()
    stepover, step = 1.2, 0.1
    pieces = spiral.spiral_pieces(shape, stepover, step)
    pts = np.vstack(pieces)
    assert inside(shape, pts[:: max(1, len(pts) // 400)]).all()
    for p in pieces:  # ends on the boundary, points no farther apart than the sample step
        assert np.hypot(*np.diff(p, axis=0).T).max() <= step + 1e-5   # Clipper rounds to 1e-6 mm
    x0, y0, x1, y1 = polygons.bounds(shape)
    g = np.array([(x, y) for x in np.arange(x0, x1, 0.7) for y in np.arange(y0, y1, 0.7)])
    g = g[inside(shape, g)]
    worst = max(float(np.sqrt(((pts - q) ** 2).sum(axis=1)).min()) for q in g)
    assert worst <= stepover + step / 2
    # inward: the same curve the other way round
    back = spiral.spiral_pieces(shape, stepover, step, inward=True)
    assert np.allclose(np.vstack(back)[::-1], pts)


def test_spiral_pattern_cuts_a_box_from_its_centre():
    params = SurfaceParams(boundary=(10, 10, 50, 40), stepover=2.0, sample_step=0.5, pattern="spiral")
    result = compute(WAVY, Cutter.ball(6), params)
    first = result.segments[0].tips[0]
    assert np.hypot(first[0] - 30, first[1] - 25) < 1.0   # from the centre out
    tips = result.cutting_points()
    assert tips[:, 0].min() >= 10 - 1e-6 and tips[:, 0].max() <= 50 + 1e-6
    assert tips[:, 1].min() >= 10 - 1e-6 and tips[:, 1].max() <= 40 + 1e-6


def sphere_mesh(radius: float) -> object:
    return grid_mesh(lambda x, y: np.sqrt(np.maximum(radius ** 2 - x ** 2 - y ** 2, 0.0)), 160, 160,
                     (-radius - 8, -radius - 8, radius + 8, radius + 8), "sphere")


def test_slope_filter_against_the_spheres_known_slope():
    S, R = 25.0, 3.0
    mesh = sphere_mesh(S)
    lo, hi = 15.0, 40.0
    params = SurfaceParams(boundary=(-30, -30, 30, 30), stepover=1.5, sample_step=0.4, slope_min_deg=lo,
                           slope_max_deg=hi)
    result = compute(mesh, Cutter.ball(2 * R), params)
    tips = result.cutting_points()
    r = np.hypot(tips[:, 0], tips[:, 1])
    # a ball on a sphere: its centre on the sphere of radius S + R, so the slope at the contact is
    # asin(r / (S + R)) (r from the axis)
    exact = np.degrees(np.arcsin(np.clip(r / (S + R), 0, 1)))
    assert exact.min() >= lo - 1.5 and exact.max() <= hi + 1.5
    assert result.diagnostics["slope_filtered"] > 0
    # what is kept covers the band: every pass point well inside it is cut
    full = compute(mesh, Cutter.ball(2 * R), SurfaceParams(boundary=(-30, -30, 30, 30), stepover=1.5,
                                                          sample_step=0.4))
    all_tips = full.cutting_points()
    band = np.degrees(np.arcsin(np.clip(np.hypot(all_tips[:, 0], all_tips[:, 1]) / (S + R), 0, 1)))
    want = all_tips[(band > lo + 1.5) & (band < hi - 1.5)]
    kept = {(round(x, 6), round(y, 6)) for x, y in tips[:, :2]}
    found = sum((round(x, 6), round(y, 6)) in kept for x, y in want[:, :2])
    assert found >= 0.98 * len(want)


def test_simulated_region_cut_no_gouge_and_outside_untouched():
    shape = ring_with_notch()
    cutter = Cutter.ball(4)
    params = SurfaceParams(boundary=polygons.bounds(shape), stepover=0.8, sample_step=0.4, region=shape)
    tp = compute_surface_toolpath(WAVY, cutter, params, LinkPolicy(safe_height=15, clearance_height=20))
    grid = Grid.covering(2, 2, 58, 58, 0.25)
    design = mesh_heights(WAVY, grid)
    top = 12.0
    res = simulate(tp, cutter, grid, box_heights(grid, top))
    cmp = compare(res, design, tolerance=0.01)
    # the moves between CL points may dip params.gouge_tol below the exact drop height (raster_refine)
    assert not cmp.gouged and cmp.overall.min_deviation >= -params.gouge_tol - 1e-4
    centres = grid.centres()
    grown = polygons.offset(shape, cutter.radius + grid.cell, arc_tol=0.001)
    outside = ~inside(grown, centres)
    assert outside.sum() > 1000
    assert np.all(res.heights.ravel()[outside] == top)                 # untouched beyond the tool's reach
    inner = inside(polygons.offset(shape, -0.5), centres)
    left = (res.heights.ravel() - design.ravel())[inner]
    assert left.max() < 0.1                                              # and the region is finished


def test_bad_region_input_is_refused_by_name():
    far = [polygons.rectangle(200, 200, 220, 230)]
    with pytest.raises(TmmError, match=r"machining region \(x 200..220, y 200..230\) does not overlap the model"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(200, 200, 220, 230), region=far))
    sliver = [polygons.rectangle(10, 10.2, 40, 10.3)]
    with pytest.raises(TmmError, match="no pass reaches the machining region .* narrower than the step-over 5 mm"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(10, 0, 40, 60), stepover=5, region=sliver))
    with pytest.raises(TmmError, match="slope range: minimum 50 deg is above the maximum 20 deg"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(0, 0, 60, 60), slope_min_deg=50, slope_max_deg=20))
    with pytest.raises(TmmError, match=r"slope maximum must be .*got 95"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(0, 0, 60, 60), slope_max_deg=95))
    with pytest.raises(TmmError, match="no reachable point: no tool position .* slope range 60..90 deg"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(0, 0, 60, 60), stepover=3, slope_min_deg=60))
    with pytest.raises(TmmError, match="with the spiral pattern use the step-over or cusp mode"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(0, 0, 60, 60), pattern="spiral",
                                                    stepover_mode="adaptive"))
    with pytest.raises(TmmError, match="region polygon 1 must be 3 or more XY points"):
        compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=(0, 0, 60, 60), region=[np.zeros((2, 2))]))
    with pytest.raises(TmmError, match="loop 1 encloses no area"):
        region.loops_region([np.array([[0, 0], [1, 1], [2, 2]])], "sketch 'S'")


def test_spiral_work_is_estimated_before_it_is_made():
    from tmm_workbench.core import limits

    shape = ring_with_notch()
    old = limits.set_limits(max_points=20000)
    try:
        # the spiral out to the farthest vertex (r 20): 20^2 pi / 0.1 / 0.1 = 1.3e5 points
        with pytest.raises(TmmError, match=r"gives about 1\.3\d*e\+05 CL points .* more than this machine's limit"):
            compute(WAVY, Cutter.ball(4), SurfaceParams(boundary=polygons.bounds(shape), stepover=0.1,
                                                        sample_step=0.1, region=shape, pattern="spiral"))
    finally:
        limits.set_limits(max_points=old.max_points)


def test_cusp_and_adaptive_spacing_work_in_a_region():
    shape = ring_with_notch()
    for mode in ("cusp", "adaptive"):
        params = SurfaceParams(boundary=polygons.bounds(shape), stepover=1.0, sample_step=0.5, region=shape,
                               stepover_mode=mode, cusp=0.03)
        result = compute(WAVY, Cutter.ball(6), params)
        assert result.diagnostics["stepover"] < 1.0 and result.diagnostics["passes"] > 40


def test_loops_nest_into_holes_and_islands():
    outer = polygons.rectangle(0, 0, 10, 10)
    hole = polygons.rectangle(2, 2, 8, 8)
    island = polygons.rectangle(4, 4, 6, 6)
    shape = region.loops_region([outer, hole[::-1], island])   # the orientation given does not matter
    assert polygons.area(shape) == pytest.approx(100 - 36 + 4)
    assert polygons.contains_point(shape, (5, 5)) and not polygons.contains_point(shape, (3, 3))
    tris = np.array([[[0, 0], [4, 0], [0, 4]], [[4, 0], [4, 4], [0, 4]], [[0, 0], [0, 0], [1, 1]]])
    assert polygons.area(region.triangles_region(tris)) == pytest.approx(16)
