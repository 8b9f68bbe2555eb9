"""The whole tool on a multipoint path (core.strategies.multipoint_holder), against an independent reference:
the face sampled densely on its parameter grid, and every pose along the output moves (tip on its line, axis
by slerp) measured by the exact distance from those points to each frustum of the assembly."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.machine import TarusMachine
from tmm_workbench.core.strategies import multipoint_holder as mh
from tmm_workbench.core.strategies.multipoint import (STATUS_FAILED, MultipointParams, compute, make_positioner)
from tmm_workbench.core.strategies.multipoint_refine import move_deviation
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

CUTTER = Cutter.torus(2.0, 3.0)
WALL = 80.0


def wall_face() -> BezierFace:
    """A flat floor (x 0..50) running into a fillet and a vertical wall 80 mm high at x = 60 (two patches)."""
    ys = np.linspace(0.0, 60.0, 4)

    def net(xs, zs):
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        return np.stack([X, Y, np.repeat(np.asarray(zs, float)[:, None], len(ys), 1)], -1)

    return BezierFace([net([0, 20, 40, 50], [0, 0, 0, 0]), net([50, 60, 60, 60], [0, 0, WALL / 2, WALL])], 2, 1)


def assembly(stick_out: float = 16.0) -> ToolAssembly:
    return ToolAssembly(CUTTER, shank_diameter=10, stick_out=stick_out, flute_length=10, holder="ER32 nut")


def params(**kw) -> MultipointParams:
    base = dict(side_step=15.0, forward_step=4.0, pass_spacing="even", beta_max_deg=60.0, feed_angle_deg=0.0)
    base.update(kw)
    return MultipointParams(**base)


# --- the reference ------------------------------------------------------------------------------------------
def dense_face(face: BezierFace, n: int = 250) -> np.ndarray:
    u0, u1, v0, v1 = face.domain
    U, V = np.meshgrid(np.linspace(u0, u1, 2 * n + 1), np.linspace(v0, v1, n + 1), indexing="ij")
    return face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]


def frustum_distance(p: np.ndarray, tip: np.ndarray, axis: np.ndarray, body) -> np.ndarray:
    """Exact distance of points p (k, 3) to the solid frustum (z0, z1, r0, r1) on the axis (0 inside), each
    point with its own pose (tip, axis: (3,) or (k, 3)): the distance in the (radius, height) half plane to
    the trapezoid, a convex polygon."""
    z0, z1, r0, r1 = body[:4]
    v = p - tip
    axis = np.broadcast_to(axis, v.shape)
    h = np.einsum("ij,ij->i", v, axis)
    rho = np.linalg.norm(v - h[:, None] * axis, axis=1)
    q = np.column_stack([rho, h])
    poly = np.array([[0.0, z0], [r0, z0], [r1, z1], [0.0, z1]])
    best = np.full(len(p), np.inf)
    inside = np.ones(len(p), bool)   # counter-clockwise in (rho, h): inside is left of every edge
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        e = b - a
        t = np.clip(((q - a) @ e) / (e @ e), 0.0, 1.0) if e @ e > 0 else np.zeros(len(q))
        best = np.minimum(best, np.linalg.norm(q - a - np.outer(t, e), axis=1))
        inside &= (e[0] * (q[:, 1] - a[1]) - e[1] * (q[:, 0] - a[0])) >= 0
    return np.where(inside, 0.0, best)


def poses_along(segments, step: float = 0.4, turn_step: float = math.radians(0.5)):
    """Every segment's positions and poses between them: tip on its line, axis by slerp."""
    tips, axes = [], []
    for seg in segments:
        for k in range(len(seg.tips) - 1):
            t0, t1, a0, a1 = seg.tips[k], seg.tips[k + 1], seg.axes[k], seg.axes[k + 1]
            th = math.acos(float(np.clip(a0 @ a1, -1, 1)))
            n = max(1, math.ceil(np.linalg.norm(t1 - t0) / step), math.ceil(th / turn_step))
            for s in np.arange(n + 1) / n:
                tips.append(t0 + s * (t1 - t0))
                if th < 1e-12:
                    axes.append(a0)
                else:
                    a = (math.sin((1 - s) * th) * a0 + math.sin(s * th) * a1) / math.sin(th)
                    axes.append(a / np.linalg.norm(a))
    return np.array(tips), np.array(axes)


def closest_approach(points: np.ndarray, tree: cKDTree, asm: ToolAssembly, tips, axes) -> tuple[float, int]:
    """The least (distance - clearance) over the neck, shank and holder at every pose, and poses measured:
    each body against every face point in a sphere holding it grown by its clearance."""
    bodies = [b for b in asm.bodies() if b[0] >= asm.flute_length - 1e-9]
    worst = np.inf
    for body in bodies:
        z0, z1, r0, r1, c = body
        centres = tips + axes * (z0 + z1) / 2
        near = tree.query_ball_point(centres, math.hypot((z1 - z0) / 2, max(r0, r1)) + c + 0.5)
        for lo in range(0, len(tips), 64):
            pose = np.concatenate([np.full(len(near[i]), i, dtype=np.int64) for i in range(lo, min(lo + 64, len(tips)))])
            idx = np.concatenate([np.asarray(near[i], dtype=np.int64) for i in range(lo, min(lo + 64, len(tips)))])
            if len(idx):
                d = frustum_distance(points[idx], tips[pose], axes[pose], body)
                worst = min(worst, float(d.min()) - c)
    return worst, len(tips)


@pytest.fixture(scope="module")
def face():
    return wall_face()


@pytest.fixture(scope="module")
def reference(face):
    pts = dense_face(face)
    return pts, cKDTree(pts)


@pytest.fixture(scope="module")
def bare(face):
    """The path without a holder (read only: two tests compare against it)."""
    return compute(face, CUTTER, params())


def test_frustum_distance_reference():
    """The reference's own distance on cases worked by hand."""
    tip, axis = np.zeros(3), np.array([0.0, 0.0, 1.0])
    body = (10.0, 20.0, 5.0, 5.0, 1.0)
    p = np.array([[8.0, 0, 15], [0, 0, 5], [3, 0, 15], [8, 0, 24], [0, 0, 25]])
    assert np.allclose(frustum_distance(p, tip, axis, body), [3.0, 5.0, 0.0, 5.0, 5.0])
    cone = (0.0, 10.0, 0.0, 10.0, 0.0)   # 45 degrees
    assert np.allclose(frustum_distance(np.array([[10.0, 0, 0]]), tip, axis, cone), [10 / math.sqrt(2)])


# --- the guard ------------------------------------------------------------------------------------------------
def test_tilt_away_keeps_the_holder_clear(face, reference, bare):
    asm = assembly()
    pts, tree = reference
    before, _ = closest_approach(pts, tree, asm, np.vstack([s.tips for s in bare.segments]),
                                 np.vstack([s.axes for s in bare.segments]))
    assert before < -0.5, "the case must need tilting: the holder runs into the wall without it"
    result = compute(face, CUTTER, params(assembly=asm))
    report = result.diagnostics["holder"]
    assert report.tilted > 0 and report.pieces.get("holder", 0) > 0
    worst, n = closest_approach(pts, tree, asm, *poses_along(result.segments))
    assert n > 500
    assert worst >= -1e-9, f"a body comes {-worst:.4f} mm closer than its clearance"
    # every tilted position is a contact without gouge, within the tilt limit
    res = result.diagnostics["results"]
    positioner = make_positioner(face, *CUTTER.torus_radii, params())
    tips = np.vstack([s.tips for s in result.segments])
    axes = np.vstack([s.axes for s in result.segments])
    clearance = positioner.clearance(tips, axes)
    assert clearance.min() >= -1e-3
    tilted = res.data["reason"] == res.reasons.index(mh.TILTED)
    assert tilted.sum() == report.tilted
    tc = positioner.clearance(res["tip"][tilted], res["axis"][tilted])
    assert np.all((tc >= 0) & (tc <= 0.5e-3 + 1e-12)), "a tilted position must touch the face"
    assert np.degrees(mh._tilt(axes)).max() <= 60.0 + 1e-6
    # no move to or from a tilted or inserted position gouges deeper than the tolerance between positions (the
    # others are the positioner's own, refined and reported by multipoint_refine as before)
    moved = {res.reasons.index(mh.TILTED), res.reasons.index(mh.INSERTED)}
    checked = 0
    for seg in result.segments:
        rows = [int(np.flatnonzero(np.all(res["tip"] == t, axis=1))[0]) for t in seg.tips]
        for k in range(len(seg.tips) - 1):
            if not {res.data["reason"][rows[k]], res.data["reason"][rows[k + 1]]} & moved:
                continue
            g, _ = move_deviation(positioner, seg.tips[k], seg.axes[k], seg.tips[k + 1], seg.axes[k + 1], (0, 0))
            assert g <= 0.005 + 1e-9
            checked += 1
    assert checked > 20


def test_tight_machine_limits_report_unreachable_positions(face, reference):
    asm = assembly()
    machine = TarusMachine(c_limits=(0.0, math.radians(20.0)))
    result = compute(face, CUTTER, params(assembly=asm, machine=machine))
    report = result.diagnostics["holder"]
    res = result.diagnostics["results"]
    assert report.tilt_limits_deg == pytest.approx((0.0, 20.0))
    assert len(report.unreachable) > 0 and report.affected >= len(report.unreachable)
    held = res.data["reason"] == res.reasons.index(mh.HOLDER)
    assert held.sum() == len(report.unreachable)
    assert np.all(res.status[held] == STATUS_FAILED)
    assert len(result.diagnostics["unreached_positions"]) >= held.sum()
    # the pass is split there: no segment holds an unreachable tip, and nothing on the path collides
    for seg in result.segments:
        for tip in report.unreachable:
            assert not np.any(np.all(np.abs(seg.tips - tip) < 1e-12, axis=1))
    tilted = res.data["reason"] == res.reasons.index(mh.TILTED)
    assert np.degrees(mh._tilt(res["axis"][tilted])).max(initial=0) <= 20.0 + 1e-6
    worst, _ = closest_approach(*reference, asm, *poses_along(result.segments))
    assert worst >= -1e-9
    assert "unreachable" in report.summary()


def test_leave_out_cuts_nothing_too_close(face, reference):
    asm = assembly()
    result = compute(face, CUTTER, params(assembly=asm, holder_collision="leave_out"))
    report = result.diagnostics["holder"]
    assert report.tilted == 0 and report.inserted == 0 and len(report.unreachable) > 0
    worst, _ = closest_approach(*reference, asm, *poses_along(result.segments))
    assert worst >= -1e-9


def test_a_holder_that_never_comes_close_changes_nothing(face, bare):
    """A long stick-out: the guard checks and keeps every position and segment bit for bit."""
    notes: list = []
    result = compute(face, CUTTER, params(assembly=assembly(stick_out=120.0), holder_notes=notes))
    assert notes == [result.diagnostics["holder"]] and notes[0].affected == 0 and not notes[0].pieces
    assert len(bare.segments) == len(result.segments)
    for a, b in zip(bare.segments, result.segments):
        assert np.array_equal(a.tips, b.tips) and np.array_equal(a.axes, b.axes)
    assert "keep their clearance everywhere" in notes[0].summary()


def test_bad_holder_collision_is_named(face):
    with pytest.raises(TmmError, match="holder collision.*'lift'"):
        compute(face, CUTTER, params(assembly=assembly(), holder_collision="lift"))


def test_tilt_range_from_the_machine():
    assert mh.tilt_range(45.0) == pytest.approx((0.0, math.radians(45)))
    m = TarusMachine(c_limits=(math.radians(-30), math.radians(20)))
    assert mh.tilt_range(45.0, m) == pytest.approx((0.0, math.radians(30)))
    m = TarusMachine(c_limits=(math.radians(5), math.radians(70)))
    assert mh.tilt_range(45.0, m) == pytest.approx((math.radians(5), math.radians(45)))


def test_face_mesh_chord_error_is_measured(face):
    mesh, error = mh.face_mesh(face, edge=1.0)
    coarse, coarse_error = mh.face_mesh(face, edge=8.0)
    assert 0 <= error < coarse_error
    assert len(mesh.triangles) > len(coarse.triangles)


def test_put_down_on_the_floor_matches_the_tilted_torus_lowest_point(face):
    """On the flat floor (z = 0) the tilted torus touches when its tip stands lowest_below_tip above it."""
    positioner = make_positioner(face, *CUTTER.torus_radii, params())
    tilts = np.radians([0.0, 5.0, 20.0, 35.0, 50.0])
    axes = np.column_stack([np.sin(tilts) * np.cos(1.0), np.sin(tilts) * np.sin(1.0), np.cos(tilts)])
    xy = np.tile([[20.0, 30.0]], (len(tilts), 1))
    tips, ok = mh.put_down(positioner, xy, np.full(len(tilts), 7.0), axes, 1e-3, (-20.0, 100.0))
    assert ok.all()
    expected = [CUTTER.lowest_below_tip(tuple(a)) for a in axes]
    assert np.all(tips[:, 2] - expected >= -1e-9) and np.all(tips[:, 2] - expected <= 0.5e-3 + 1e-9)
    assert np.array_equal(tips[:, :2], xy)
    _, off = mh.put_down(positioner, np.array([[500.0, 500.0]]), np.zeros(1), axes[:1], 1e-3, (-20.0, 100.0))
    assert not off.any()   # no face under the tool
