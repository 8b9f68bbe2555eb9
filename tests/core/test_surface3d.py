"""3-axis raster finishing: path structure, gouge-free cutting moves, stock to leave, errors, cancel."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import closest_distances, grid_mesh
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.verify.linear_moves import deepest_cut
from tmm_workbench.core.strategies.raster_drop import OFF_MODEL_SKIP, ONEWAY, SurfaceParams, compute_surface_toolpath
from tmm_workbench.core.toolpath import MoveKind


def params(**kw) -> dict:
    """Strategy parameters and heights of a test case (run() splits them)."""
    base = dict(boundary=(2.0, 2.0, 38.0, 28.0), stepover=2.0, sample_step=0.5, safe_height=10.0,
                clearance_height=15.0)
    base.update(kw)
    return base


def run(mesh, cutter, case: dict, progress=None):
    case = dict(case)
    policy = LinkPolicy(case.pop("safe_height"), case.pop("clearance_height"))
    return compute_surface_toolpath(mesh, cutter, SurfaceParams(**case), policy, progress)


def test_zigzag_structure_and_gouge_free(wavy_mesh):
    cutter = Cutter.ball(4.0)
    tp = run(wavy_mesh, cutter, params())
    kinds = [m.kind for m in tp]
    assert kinds[:3] == [MoveKind.RAPID, MoveKind.RAPID, MoveKind.PLUNGE]
    assert tp.moves[0].z == 15.0 and tp.moves[1].z == 10.0 and tp.moves[-1].z == 15.0
    assert kinds.count(MoveKind.PLUNGE) == 1  # zig-zag: one plunge, linked passes
    cut = tp.cutting_points()
    assert cut[:, 0].min() == pytest.approx(2.0) and cut[:, 0].max() == pytest.approx(38.0)
    assert cut[:, 1].min() == pytest.approx(2.0) and cut[:, 1].max() == pytest.approx(28.0)
    # Between CL points the straight moves stay above the exact drop height within the gouge tolerance
    # (checked every 0.02 mm; points are inserted where a move would cut in: raster_refine).
    surface = DropSurface(wavy_mesh)
    moving = np.array([m.kind is not MoveKind.RAPID for m in tp])
    deepest, _ = deepest_cut(surface, cutter, tp.points(), moving, step=0.02)
    assert deepest <= 0.01  # the tolerance (0.005 mm) is checked at 4 points a move; the target is 0.01 mm
    p = dict(boundary=(2.0, 2.0, 38.0, 28.0), stepover=2.0, sample_step=0.5, gouge_tol=0.0)
    plain = compute_surface_toolpath(wavy_mesh, cutter, SurfaceParams(**p), LinkPolicy(10.0, 15.0))
    unrefined, _ = deepest_cut(surface, cutter, plain.points(),
                               np.array([m.kind is not MoveKind.RAPID for m in plain]), step=0.02)
    assert unrefined > max(0.005, 1.5 * deepest)  # without the check the wavy mesh's ridges are cut deeper
    # Every CL point: the ball centre lies one radius from the mesh (touching, no gouge), but for the few
    # corners where a move crosses a crease too steep to refine (across at the upper height, then down),
    # which stay clear of it.
    d = closest_distances(cut + [0, 0, cutter.radius], wavy_mesh)
    assert (d >= cutter.radius - 1e-9).all()
    assert np.mean(np.abs(d - cutter.radius) < 1e-9) > 0.98


def test_oneway_retracts_between_passes(wavy_mesh):
    tp = run(wavy_mesh, Cutter.flat(4.0), params(pattern=ONEWAY, stepover=3.0))
    plunges = [i for i, m in enumerate(tp.moves) if m.kind is MoveKind.PLUNGE]
    passes = int(np.ceil((28.0 - 2.0) / 3.0)) + 1
    assert len(plunges) == passes
    for i in plunges[1:]:  # lift to the safe height, cross over, plunge
        assert tp.moves[i - 1].kind is MoveKind.RAPID and tp.moves[i - 1].z == 10.0
        assert tp.moves[i - 2].kind is MoveKind.RAPID and tp.moves[i - 2].z == 10.0
    # All passes run the same way (+X).
    for i in plunges:
        assert tp.moves[i + 1].x > tp.moves[i].x


def test_raster_angle_rotates_passes(wavy_mesh):
    tp = run(wavy_mesh, Cutter.ball(3.0), params(angle_deg=90.0, pattern=ONEWAY))
    i = next(i for i, m in enumerate(tp.moves) if m.kind is MoveKind.PLUNGE)
    assert tp.moves[i + 1].x == pytest.approx(tp.moves[i].x) and tp.moves[i + 1].y > tp.moves[i].y


def test_stock_to_leave_offsets_the_surface():
    plate = grid_mesh(lambda x, y: 0 * x + 5.0, 10, 10, (0, 0, 20, 20), "plate")
    for cutter in (Cutter.ball(4.0), Cutter.flat(4.0), Cutter.bull(6.0, 1.0)):
        tp = run(plate, cutter, params(boundary=(4, 4, 16, 16), stock_to_leave=0.3))
        np.testing.assert_allclose(tp.cutting_points()[:, 2], 5.3, atol=1e-12)


def test_negative_stock_to_leave_cuts_into_the_model_also_at_its_lowest_point():
    """Below the model's lowest point too (the default floor follows it; an explicit floor is a final depth)."""
    plate = grid_mesh(lambda x, y: 0 * x + 5.0, 10, 10, (0, 0, 20, 20), "plate")
    for cutter in (Cutter.ball(4.0), Cutter.bull(6.0, 1.0)):
        tp = run(plate, cutter, params(boundary=(4, 4, 16, 16), stock_to_leave=-0.3))
        np.testing.assert_allclose(tp.cutting_points()[:, 2], 4.7, atol=1e-12)
        floored = run(plate, cutter, params(boundary=(4, 4, 16, 16), stock_to_leave=-0.3, floor_z=4.9))
        np.testing.assert_allclose(floored.cutting_points()[:, 2], 4.9, atol=1e-12)
    with pytest.raises(TmmError, match="negative stock to leave -0.3 mm exceeds the corner radius 0 mm"):
        run(plate, Cutter.flat(4.0), params(boundary=(4, 4, 16, 16), stock_to_leave=-0.3))


def test_stock_to_leave_on_a_slope_is_a_normal_offset():
    # Plane at 30 degrees: the ball centre must be R + s from the plane, i.e. tip raised by s / cos(30).
    t = np.tan(np.radians(30))
    slope = grid_mesh(lambda x, y: t * x, 20, 20, (0, 0, 40, 40), "slope")
    a = run(slope, Cutter.ball(6.0), params(boundary=(10, 10, 30, 30), safe_height=40,
                                                                 clearance_height=45))
    b = run(slope, Cutter.ball(6.0), params(boundary=(10, 10, 30, 30), stock_to_leave=0.5,
                                                                 safe_height=40, clearance_height=45))
    np.testing.assert_allclose(b.cutting_points()[:, 2] - a.cutting_points()[:, 2],
                               0.5 / np.cos(np.radians(30)), atol=1e-9)


@pytest.mark.parametrize("change,message", [
    (dict(stepover=0.0), "step-over must be a positive length"),
    (dict(stepover=-1.0), "step-over must be a positive length"),
    (dict(sample_step=0.0), "sample step must be a positive length"),
    (dict(sample_step=float("nan")), "sample step must be a positive length"),
    (dict(boundary=(100, 100, 120, 120)), "lies outside the model"),
    (dict(safe_height=1.0, clearance_height=15.0), "safe height 1 mm is not above the highest tool position"),
    (dict(clearance_height=5.0), "clearance height 5 mm is below the safe height 10 mm"),
    (dict(pattern="helix"), "pattern must be"),  # spiral is a pattern since issue 14 item 3
])
def test_bad_parameters_raise_clear_errors(wavy_mesh, change, message):
    with pytest.raises(TmmError, match=message):
        run(wavy_mesh, Cutter.ball(4.0), params(**change))


def test_cancel(wavy_mesh):
    with pytest.raises(Cancelled):
        run(wavy_mesh, Cutter.ball(4.0), params(sample_step=0.001),
                                 progress=lambda f: False)


def two_islands() -> TriMesh:
    """Two bumpy plates with 10 mm of air between them: x 0..10 and 20..30 (y 0..20), no base."""
    left = grid_mesh(lambda x, y: 4.0 + 0.3 * np.sin(x) * np.cos(y / 2), 10, 20, (0, 0, 10, 20))
    right = grid_mesh(lambda x, y: 6.0 + 0.3 * np.cos(x / 2) * np.sin(y), 10, 20, (20, 0, 30, 20))
    v = np.vstack([left.vertices, right.vertices])
    f = np.vstack([left.triangles, right.triangles + len(left.vertices)])
    return TriMesh(v, f, "two islands")


@pytest.mark.parametrize("pattern", ["zigzag", ONEWAY])
def test_off_model_skip_cuts_only_over_the_model(pattern):
    mesh, cutter = two_islands(), Cutter.ball(4.0)
    p = params(boundary=(0.0, 1.0, 30.0, 19.0), stepover=3.0, sample_step=0.5, pattern=pattern)
    floor = run(mesh, cutter, p)
    skip = run(mesh, cutter, params(**{**p, "off_model": OFF_MODEL_SKIP}))
    # Floor: the tool runs along the model's lowest point between the islands (the ball touches nothing there).
    across = [(a, b) for a, b in zip(floor.moves, floor.moves[1:]) if b.kind is MoveKind.FEED
              and min(a.x, b.x) < 12.5 and max(a.x, b.x) > 17.0]
    assert across and all(a.z == b.z == mesh.bounds[0][2] for a, b in across)
    # Skip: no cutting point where the ball's footprint misses both islands (x 12..18); every one touches the
    # model (the ball's centre one radius from it) or, over an island's edge below the floor, rests on the
    # floor clear of it.
    moves = skip.moves
    cut = skip.cutting_points()
    assert len(cut) and not ((cut[:, 0] > 12.0) & (cut[:, 0] < 18.0)).any()
    d = closest_distances(cut + [0, 0, cutter.radius], mesh)
    on_floor = cut[:, 2] == mesh.bounds[0][2]
    assert (d[~on_floor] >= cutter.radius - 1e-9).all()  # touching, or a refinement corner above (raster_refine)
    assert np.mean(np.abs(d[~on_floor] - cutter.radius) < 1e-9) > 0.98
    assert (d[on_floor] >= cutter.radius - 1e-9).all() and on_floor.sum() < 0.1 * len(cut)
    # ... no cutting move crosses the gap ...
    assert not [b for a, b in zip(moves, moves[1:]) if b.kind is not MoveKind.RAPID
                and min(a.x, b.x) < 12.0 and max(a.x, b.x) > 18.0]
    # ... and every island piece is reached by a vertical lift, a rapid at the safe height and a plunge.
    plunges = [i for i, m in enumerate(moves) if m.kind is MoveKind.PLUNGE]
    passes = int(np.ceil((19.0 - 1.0) / 3.0)) + 1
    assert len(plunges) == (2 * passes if pattern == ONEWAY else passes + 1)
    for i in plunges[1:]:
        lift, over, down = moves[i - 2], moves[i - 1], moves[i]
        before = moves[i - 3]
        assert lift.kind is over.kind is MoveKind.RAPID and lift.z == over.z == 10.0
        assert (lift.x, lift.y) == (before.x, before.y) and (over.x, over.y) == (down.x, down.y)


def test_off_model_skip_with_no_model_under_the_boundary_is_an_error():
    p = params(boundary=(13.0, 1.0, 17.0, 19.0), off_model=OFF_MODEL_SKIP)
    with pytest.raises(TmmError, match="over no part of the model"):
        run(two_islands(), Cutter.ball(4.0), p)


def test_off_model_must_be_floor_or_skip(wavy_mesh):
    with pytest.raises(TmmError, match="off-model must be"):
        run(wavy_mesh, Cutter.ball(4.0), params(off_model="air"))
