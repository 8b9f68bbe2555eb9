"""Adaptive 5-axis step-over (core.strategies.mesh5.stepover): the half-widths of the tilted cutter's effective
profile against closed forms on a plane, and the passes' scallop checked on the real tool positions by the
slow reference (the solid cylinder swept between the CL points, material measured along the normals)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.scallop5_reference import remaining, surface_samples, swept_positions
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, world_placement
from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath, cc_paths
from tmm_workbench.core.strategies.mesh5.optimal import PassPostures, smooth_postures
from tmm_workbench.core.strategies.mesh5.coverage import Coverage
from tmm_workbench.core.strategies.mesh5.stepover import (HOLD, _hold, _Planes, _on_mesh, _split, adaptive_passes,
                                                        half_widths, reach_widths,
                                                        tilt_reached, widest_cspace)
from tmm_workbench.core.strategies.mesh5.tool_moves import (BETWEEN_TOL, OVERRUN_STEPS, between_positions,
                                                           clear_lifts, overrun_positions)
from tmm_workbench.core.strategies.mesh5.unfinished import list_ends
from tmm_workbench.core.strategies.mesh5.widths import end_by_tools, path_bending
from tmm_workbench.core.tools.cutter import Cutter

TOL = 0.05


def plane_widths(cutter: Cutter, lam_deg: float, omg_deg: float = 0.0) -> np.ndarray:
    plane = grid_mesh(lambda x, y: 0.0 * x, 20, 20, (-20, -20, 20, 20), "plane")
    w, _ = half_widths(MeshReach(plane), cutter, np.zeros((1, 3)), np.eye(3)[None], np.radians([lam_deg]),
                       np.radians([omg_deg]), np.zeros(1), TOL)
    return w[0]


@pytest.mark.parametrize("lam", [3.0, 9.0, 30.0])
def test_tilted_flat_end_half_width_on_a_plane_is_the_ellipse(lam):
    # the rim seen along the feed: R sin(lambda) (1 - sqrt(1 - y^2 / R^2)) above the plane (seed Fig. 3-12)
    R = 6.0
    k = 1.0 - TOL / (R * math.sin(math.radians(lam)))
    expect = R * math.sqrt(1.0 - k * k)
    assert plane_widths(Cutter.flat(2 * R), lam) == pytest.approx([expect, expect], abs=2e-3)


def test_bull_nose_half_width_on_a_plane_is_the_flat_plus_the_corner():
    R, r = 6.0, 2.0
    expect = (R - r) + math.sqrt(r * r - (r - TOL) ** 2)
    assert plane_widths(Cutter.bull(2 * R, r), 0.0) == pytest.approx([expect, expect], abs=2e-3)


def test_a_yawed_tool_is_wider_on_the_side_of_its_body():
    # yawed towards +LY, the lowest rim point moves to +LY and the body (behind it along -TX) to -LY
    w = plane_widths(Cutter.flat(12.0), 9.0, 30.0)
    assert w[1] > w[0] + 0.1
    assert plane_widths(Cutter.flat(12.0), 9.0, -30.0) == pytest.approx(w[::-1], abs=1e-6)


def cylinder(shear: float):
    """A convex cylinder patch (radius 60 mm, axis along the feed), its ends slanted by `shear` (x += shear y)."""
    mesh = grid_mesh(lambda x, y: np.sqrt(60.0 ** 2 - y * y), 8, 80, (-12, -20, 12, 20), "cylinder")
    v = mesh.vertices.copy()
    v[:, 0] += shear * v[:, 1]
    return TriMesh(v, mesh.triangles, "cylinder")


@pytest.fixture(scope="module", params=[0.0, 0.8], ids=["square", "slanted"])
def cylinder_plan(request):
    """The cylinder cut by a flat D 10 at tolerance 0.05 mm; slanted, the planes' paths end at different x."""
    mesh = cylinder(request.param)
    plan = adaptive_passes(mesh, Cutter.flat(10.0), TOL, (1, 0), grid=PostureGrid.degrees((0, 24), (-30, 30)),
                           forward_step=3.0)
    return mesh, plan, request.param


def test_passes_cover_the_surface_in_order_with_the_scallop_at_the_tolerance(cylinder_plan):
    mesh, plan, shear = cylinder_plan
    offsets = [p.offset for p in plan.passes]
    assert offsets == sorted(offsets) and 3 <= len(offsets) <= 16
    assert plan.passes[0].band[0] == pytest.approx(-20.0) and plan.passes[-1].band[1] == pytest.approx(20.0)
    # the slow check: surface points 5 mm and more from the ends of the feed (at the ends themselves the
    # overrun covers the surface, measured up to 0.054 mm), the tools of all passes swept over them
    sw = [swept_positions(t, a, 8) for t, a in plan.tool_positions()]
    tips, axes = np.concatenate([s[0] for s in sw]), np.concatenate([s[1] for s in sw])
    xs, ys = np.meshgrid(np.linspace(-7, 7, 8), np.linspace(-19.5, 19.5, 391), indexing="ij")
    q, nrm, hit = surface_samples(mesh, np.column_stack([(xs + shear * ys).ravel(), ys.ravel()]))
    assert hit.all()
    h = remaining(q, nrm, tips, axes, 5.0, 20.0)
    assert np.isfinite(h).all()
    assert h.min() >= -2e-3                                                 # no gouge
    assert h.max() <= TOL + 2e-3                                            # the scallop within the tolerance
    assert h.max() >= 0.7 * TOL                                             # and not far below it: adaptive


def test_the_tools_go_on_an_overrun_beyond_the_ends_along_the_feed(cylinder_plan):
    _, plan, _ = cylinder_plan
    assert plan.overrun == pytest.approx(5.0)                               # the cutter's radius
    n = OVERRUN_STEPS
    for p in plan.passes:
        for path, q, (tips, axes) in zip(p.paths, p.postures, p.tool_positions()):
            assert len(tips) == len(q.tips) + 2 * n and np.array_equal(tips[n:-n], q.tips)
            # on this convex patch nothing rises beyond the ends: straight on along the end tangents
            # (a radius and as far as the end was moved inside the mesh)
            for end, cc, lx, inset in ((tips[:n][::-1], q.tips[0], -path.frames[0, 0], path.inset[0]),
                                       (tips[-n:], q.tips[-1], path.frames[-1, 0], path.inset[1])):
                along = (end - cc) @ lx
                assert 0.0 < inset < 0.5
                assert along == pytest.approx((5.0 + inset) * np.arange(1, n + 1) / n, abs=0.01)
                assert np.linalg.norm(end - cc - along[:, None] * lx, axis=1).max() <= 0.05
            assert np.array_equal(axes[:n + 1], np.repeat(q.axes[:1], n + 1, 0))
            assert np.array_equal(axes[-n - 1:], np.repeat(q.axes[-1:], n + 1, 0))


def test_the_overrun_clears_a_surface_that_rises_beyond_the_end_of_the_path():
    # a trough curving up along the feed (radius 80 mm) and a path along its floor that ends at x = 0 while the
    # mesh goes on, as where the mesh's boundary runs slanted across the planes (seed 000's concave surface):
    # straight on along the end's tangent at its lift, the tool runs into the rise
    mesh = grid_mesh(lambda x, y: x * x / 160.0, 40, 20, (-20, -10, 20, 10), "trough")
    cutter = Cutter.flat(10.0)
    full = cc_paths(mesh, (1, 0), np.array([0.0]), 2.0, 0.01)[0]
    keep = (full.points[:, 0] >= -10.0) & (full.points[:, 0] <= 1e-9)
    path = full.take(keep)
    cs = build_cspace(mesh, cutter, path.points, path.frames, PostureGrid.degrees((0, 24), (-30, 30)), TOL, 1.0)
    q = smooth_postures(cs, cutter, path.points, path.frames)
    tips, axes, _ = overrun_positions(MeshReach(mesh), cutter, path, q, 5.0)
    n = OVERRUN_STEPS
    assert len(tips) == len(q.tips) + 2 * n and np.array_equal(tips[n:-n], q.tips)
    xs, ys = np.meshgrid(np.arange(-4.0, 14.0, 0.25), np.arange(-9.5, 9.6, 0.5), indexing="ij")
    pts, nrm, hit = surface_samples(mesh, np.column_stack([xs.ravel(), ys.ravel()]))
    end = np.arange(len(tips) - n - 1, len(tips))                          # from the last CL point on

    def least(t: np.ndarray, a: np.ndarray) -> float:
        st, sa = swept_positions(t, a, 8)
        return float(remaining(pts[hit], nrm[hit], st, sa, 5.0, 20.0).min())

    straight = q.tips[-1] + np.linspace(0.0, 5.0, n + 1)[:, None] * path.frames[-1, 0]
    assert least(straight, axes[end]) < -0.1                                # the gouge the lift prevents
    assert -2e-3 <= least(tips[end], axes[end]) <= 0.02                     # clear, and in contact: not lifted more
    assert tips[-1] @ path.frames[-1, 2] > q.tips[-1] @ path.frames[-1, 2] + 0.1


def test_a_move_that_would_cut_in_between_two_cl_points_gets_a_position_lifted_clear():
    # a saddle z = x y / 60: along a pass the least lift curves, and the straight move between two CL points 3 mm
    # apart sags into the surface (up to about 3^2 / (8 x 60) = 0.019 mm; here, with the tilt held to 6 deg, 0.01)
    mesh = grid_mesh(lambda x, y: x * y / 60.0, 40, 40, (-20, -20, 20, 20), "saddle")
    cutter = Cutter.flat(10.0)
    path = cc_paths(mesh, (1, 0), np.array([-4.0]), 3.0, 0.01)[0]
    keep = np.abs(path.points[:, 0]) <= 9.0
    path = path.take(keep)
    cs = build_cspace(mesh, cutter, path.points, path.frames, PostureGrid.degrees((0, 6), (-30, 30)), TOL, 1.0)
    q = smooth_postures(cs, cutter, path.points, path.frames)
    reach = MeshReach(mesh)
    tips, axes = between_positions(reach, cutter, q.tips, q.axes, path.frames)
    assert len(tips) > len(q.tips)
    # the CL points stay, in order; every inserted one is clear of the mesh (its lift 0 now)
    at = [int(np.flatnonzero(np.all(tips == t, axis=1))[0]) for t in q.tips]
    assert at == sorted(at)
    new = np.setdiff1d(np.arange(len(tips)), at)
    frames = path.frames[np.searchsorted(at, new) - 1]
    assert np.allclose(clear_lifts(reach, cutter, tips[new], axes[new], frames), 0.0, atol=1e-6)
    xs, ys = np.meshgrid(np.arange(-8.0, 8.0, 0.25), np.arange(-12.0, 4.0, 0.25), indexing="ij")
    pts, nrm, hit = surface_samples(mesh, np.column_stack([xs.ravel(), ys.ravel()]))

    def least(t: np.ndarray, a: np.ndarray) -> float:
        st, sa = swept_positions(t, a, 8)
        return float(remaining(pts[hit], nrm[hit], st, sa, 5.0, 20.0).min())

    assert least(q.tips, q.axes) < -0.006                                    # the straight moves cut in
    assert least(tips, axes) >= -BETWEEN_TOL


def test_a_move_whose_middle_is_clear_but_not_its_last_quarter_gets_a_position_there():
    # a long move (6 radii) over a plane with a bump near its end: both ends and the middle stand clear of the
    # bump, the tool at three quarters stands on it (seed 000's complex surface: an overrun off a steep edge,
    # the tool's side over the mesh's edge at 3/4 of a move, -0.0137 mm in the slow check, the middle clear)
    cutter = Cutter.flat(10.0)
    bump = grid_mesh(lambda x, y: np.clip(1.0 - np.abs(x - 22.0) / 1.5, 0.0, None), 400, 10, (-10, -5, 40, 5),
                     "bump")
    reach = MeshReach(bump)
    tips = np.array([[0.0, 0.0, 0.0], [30.0, 0.0, 0.0]])
    axes = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    ident = np.repeat(np.eye(3)[None], 3, axis=0)
    ends_mid = np.array([tips[0], [15.0, 0.0, 0.0], tips[1]])
    assert np.allclose(clear_lifts(reach, cutter, ends_mid, np.repeat(axes[:1], 3, 0), ident), 0.0)
    got, got_a = between_positions(reach, cutter, tips, axes, ident[:2])
    assert len(got) > 2 and np.allclose(got_a, axes[0])
    # along the moves now (tip linear), the tool stands at most BETWEEN_TOL into the bump
    s = np.linspace(0.0, 1.0, 33)[:-1]
    along = np.concatenate([a + s[:, None] * (b - a) for a, b in zip(got[:-1], got[1:])])
    lift = clear_lifts(reach, cutter, along, np.repeat(axes[:1], len(along), 0),
                       np.repeat(np.eye(3)[None], len(along), axis=0))
    assert lift.max() <= BETWEEN_TOL + 1e-6


def test_bad_tolerance_and_tool_are_refused_by_name():
    plane = grid_mesh(lambda x, y: 0.0 * x, 4, 4, (0, 0, 10, 10), "plane")
    with pytest.raises(TmmError, match="tolerance must be a positive number of mm, got 0"):
        adaptive_passes(plane, Cutter.flat(6.0), 0)
    with pytest.raises(TmmError, match="ball, flat or bull-nose"):
        adaptive_passes(plane, Cutter.vbit(6.0, 90.0), 0.01)


def test_interior_points_catch_a_groove_between_the_cc_point_and_the_side_step():
    # a groove 0.2 mm deep halfway to the side step: the ends of the step pass, the tool leaves the groove's
    # depth of material above it
    groove = grid_mesh(lambda x, y: -0.2 * np.exp(-((y - 1.5) / 0.3) ** 2), 16, 200, (-8, -5, 8, 5), "groove")
    grid = PostureGrid.degrees((0, 6), (-6, 6))
    args = (groove, Cutter.flat(10.0), np.zeros((1, 3)), np.eye(3)[None], grid, TOL, 3.0)
    assert build_cspace(*args).available.any()
    assert build_cspace(*args, interior=3).empty.all()


def test_a_groove_no_pass_can_finish_is_reported_and_the_passes_go_on_beyond_it():
    # a V groove 2 mm wide and 1 mm deep along the feed: no posture of a flat D 10 finishes it
    mesh = grid_mesh(lambda x, y: -np.clip(1.0 - np.abs(y), 0, None), 10, 120, (-10, -15, 10, 15), "groove")
    plan = adaptive_passes(mesh, Cutter.flat(10.0), TOL, (1, 0), grid=PostureGrid.degrees((0, 12), (-12, 12)),
                           forward_step=4.0)
    assert len(plan.unfinished) >= 1
    strips = np.array(plan.unfinished)
    # all along the feed (the bins get stuck where the passes before left them, not all at once)
    assert strips[:, 0].min() <= -9.0 and strips[:, 1].max() >= 9.0
    assert (strips[:, 2] < 1.0).all() and (strips[:, 3] > -1.0).all()      # across: over the groove
    assert any(p.offset > 1.0 for p in plan.passes) and plan.passes[-1].band[1] == pytest.approx(15.0)
    assert "left unfinished" in plan.report()


def test_the_finished_level_moves_only_in_the_bins_a_pass_runs_through():
    # a plane with vertices 10 mm apart along the feed (2 mm bins): every bin still knows the mesh's extent
    # across, and a pass along part of the feed leaves the other bins as they were
    plane = grid_mesh(lambda x, y: 0.0 * x, 4, 4, (0, 0, 40, 20), "plane")
    m, feed = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    cover = Coverage(plane, m, feed, 2.0, 1e-3, 3.0)
    assert np.allclose(cover.lo, 0.0) and np.allclose(cover.hi, 20.0) and cover.open.all()
    xs = np.arange(0.0, 16.1, 2.0)
    frames = np.tile(np.eye(3), (len(xs), 1, 1))
    path = CCPath(0, 4.0, np.column_stack([xs, np.full(len(xs), 4.0), np.zeros(len(xs))]), frames[:, 2], frames)
    ends = np.stack([path.points + [0.0, 5.0, 0.0], path.points - [0.0, 5.0, 0.0]], axis=1)
    level, short = cover.advanced([path], ends)
    reached = cover.bin(np.array([0.0, 16.0 + 3.0]))                        # the path and its overrun
    assert short == 0
    assert np.allclose(level[reached[0]:reached[1] + 1], 9.0)
    assert np.allclose(level[reached[1] + 1:], 0.0)
    # a CC point whose right side falls short keeps the bins of its segments for the next pass
    ends[4, 1, 1] = 1.0
    level, short = cover.advanced([path], ends)
    assert short == 3 and np.allclose(level[cover.bin(np.array([6.0, 10.0]))], 0.0)
    assert np.allclose(level[cover.bin(np.array([2.0, 14.0]))], 9.0)


def test_cc_points_beyond_the_machine_tilt_are_left_out_and_their_bins_reported():
    # flat for x < 4, then falling along the feed at 30 deg: with the tool leaning along the feed, every
    # posture there tilts the axis 30 deg or more from vertical, beyond a machine tilt of 20 deg
    mesh = grid_mesh(lambda x, y: -np.clip(x - 4.0, 0, None) * math.tan(math.radians(30)), 24, 40,
                     (-12, -10, 12, 10), "drop")
    machine = TarusMachine(c_limits=(0.0, math.radians(20.0)))
    grid = PostureGrid.degrees((0, 12), (-12, 12))
    assert not tilt_reached(machine, cc_paths(mesh, (1, 0), np.array([0.0]), 3.0, 0.01)[0].frames[-1:],
                            grid).any()
    plan = adaptive_passes(mesh, Cutter.flat(10.0), TOL, (1, 0), machine, grid, forward_step=3.0)
    pts = np.concatenate([p.points for q in plan.passes for p in q.paths])
    assert pts[:, 0].max() < 6.0                                            # none on the slope
    assert all(p.cut_short == (False, True) for q in plan.passes for p in q.paths)
    strips = np.array(plan.unfinished)
    # slivers the tools leave along the mesh's sides y = -10 and 10 (edge_by_tools: next to the cut end the
    # rim that forms the profile there is beyond the path's last tool) are listed too, under a mm across
    sliver = np.abs(strips[:, 3] - strips[:, 2]) < 1.0
    assert (np.minimum(np.abs(strips[sliver, 2]), np.abs(strips[sliver, 3])) >= 9.0).all()
    strips = strips[~sliver]
    # on the slope (or in the bin of the crease, x 3-6, whose ends the pass sweeps bent over it)
    assert len(strips) and (strips[:, 1] >= 6.0).all() and (strips[:, 0] >= 2.0).all()
    assert strips[:, 2].min() <= -9.0 and strips[:, 3].max() >= 9.0        # all across
    assert plan.passes[-1].band[1] == pytest.approx(10.0)                  # the flat part finished


def test_paired_lifts_are_the_diagonal_of_the_masked_call():
    mesh = grid_mesh(lambda x, y: 0.02 * x * x - 0.01 * y * y, 10, 10, (-10, -10, 10, 10), "saddle")
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 3.0, 0.01)[0]
    n = len(path)
    lam, omg = np.radians(np.linspace(0, 30, n)), np.radians(np.linspace(-20, 20, n))
    cutter = Cutter.flat(8.0)
    reach = MeshReach(mesh)
    both = lifts(reach, cutter, path.points, path.frames, lam, omg, 4.0, np.eye(n, dtype=bool))
    one = lifts(reach, cutter, path.points, path.frames, lam, omg, 4.0, paired=True)
    assert one.shape == (n,) and np.array_equal(one, np.diagonal(both)) and (one > 0).any()
    with pytest.raises(TmmError, match="paired lifts take one posture per CC point"):
        lifts(reach, cutter, path.points, path.frames, lam[:2], omg[:2], 4.0, paired=True)


def test_a_move_over_a_ridge_higher_than_a_radius_is_lifted_over_it_or_refused():
    # two clear positions either side of a narrow ridge: the straight move between them would cut through it;
    # its middle needs a lift above the tool's radius (clear_lifts' first limit), never a silent gouge
    cutter = Cutter.flat(10.0)
    tips = np.array([[-8.0, 0.0, 0.0], [8.0, 0.0, 0.0]])
    axes = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    frames = np.repeat(np.eye(3)[None], 2, axis=0)
    for height in (8.0, 30.0):
        ridge = grid_mesh(lambda x, y, h=height: np.clip(h - 20.0 * np.abs(x), 0.0, None), 400, 20,
                          (-10, -5, 10, 5), "ridge")
        reach = MeshReach(ridge)
        assert np.allclose(clear_lifts(reach, cutter, tips, axes, frames), 0.0)     # the ends are clear
        if height < 4 * cutter.radius:
            got, _ = between_positions(reach, cutter, tips, axes, frames)
            mid = got[np.argmin(np.abs(got[:, 0]))]
            assert len(got) >= 3 and mid[0] == 0.0 and mid[2] == pytest.approx(height, abs=0.05)   # over the top
            ident = np.repeat(np.eye(3)[None], len(got), axis=0)
            assert np.allclose(clear_lifts(reach, cutter, got, np.repeat(axes[:1], len(got), 0), ident), 0.0)
        else:
            with pytest.raises(TmmError, match="no lift of 4 tool radii clears it"):
                between_positions(reach, cutter, tips, axes, frames)


def test_every_postures_reach_is_its_half_widths_and_the_widest_are_kept():
    # a plane sloping across the feed: the reach along m of each available posture is where half_widths
    # ends its side at the same posture and lift (the section point's share of m); widest_cspace keeps the
    # widest
    mesh = grid_mesh(lambda x, y: 0.2 * y, 20, 20, (-20, -20, 20, 20), "slope")
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 4.0, 0.01)[0]
    pts, frm = path.points[2:4], path.frames[2:4]
    cutter, grid, reach = Cutter.flat(10.0), PostureGrid.degrees((0, 18), (-9, 9)), MeshReach(mesh)
    cs = build_cspace(reach, cutter, pts, frm, grid, TOL, 1.0)
    m = np.array([0.0, 1.0, 0.0])
    left, right = reach_widths(reach, cutter, pts, frm, cs, TOL, m)
    lam, omg = (g.ravel() for g in grid.mesh())
    for i in range(len(pts)):
        ps = np.flatnonzero(cs.available[i].ravel())
        assert ps.size > 10
        w, ends = half_widths(reach, cutter, np.repeat(pts[i:i + 1], ps.size, 0), np.repeat(frm[i:i + 1], ps.size, 0),
                              lam[ps], omg[ps], cs.lift[i].ravel()[ps], TOL)
        # to the section's samples (2 R / 96 apart), never beyond the exact crossing
        for got, exact in ((left[i, ps], (ends[:, 0] - pts[i]) @ m), (right[i, ps], (pts[i] - ends[:, 1]) @ m)):
            assert (got <= exact + 5e-3).all() and (got >= exact - 10.0 / 96 - 5e-3).all()
    kept, short = widest_cspace(reach, cutter, TOL, pts, frm, cs, np.full(len(pts), 0.5), m)
    assert not short.any()
    for i in range(len(pts)):
        k = kept.available[i].ravel()
        assert k.any() and (k <= cs.available[i].ravel()).all()
        assert left[i, k].min() >= 0.97 * np.nanmax(left[i]) - 1e-9 or left[i, k].min() >= 0.97 * np.nanmin(
            np.nanmax(left, axis=1)) - 1e-9


def test_the_half_widths_follow_what_the_tool_sweeps_along_a_bending_pass():
    # a cylinder convex along the feed (axis across it, radius 40 mm): the tool's point that forms the profile
    # at 0.7 R lies ~1.9 mm behind the CC point, swept there by the tool 1.9 mm further on, raised by kappa x^2
    # / 2 ~ 0.045 mm against the straight sweep; the widths measured with the pass's bending end where the slow
    # reference (the tool at dense positions along the real pass) leaves tau, the straight ones where it leaves
    # 0.045 mm more
    tol, R, rho = 0.1, 6.35, 40.0
    mesh = grid_mesh(lambda x, y: np.sqrt(rho * rho - x * x), 80, 40, (-20, -20, 20, 20), "bend")
    reach, cutter = MeshReach(mesh), Cutter.flat(2 * R)
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 1.0, 0.001)[0]
    n = len(path)
    lam = np.full(n, math.radians(3.0))
    tips, axes = world_placement(cutter, path.points, path.frames, lam, np.zeros(n), np.zeros(n))
    i = int(np.argmin(np.abs(path.points[:, 0])))
    args = (reach, cutter, path.points[i:i + 1], path.frames[i:i + 1], lam[:1], np.zeros(1), np.zeros(1), tol)
    straight = half_widths(*args)[0][0]
    bent = half_widths(*args, bend=path_bending([path])[i:i + 1])[0][0]
    assert (straight - bent > 0.3).all()
    st, sa = swept_positions(tips, axes, 64)
    p = path.points[i]
    for w, expect in ((bent, tol), (straight, tol + 0.045)):
        q = np.array([[p[0], y, p[2]] for y in (w[0], -w[1])])
        left = remaining(q, np.tile([0.0, 0.0, 1.0], (2, 1)), st, sa, R, 4 * R)
        assert left == pytest.approx([expect, expect], abs=0.008)


def test_a_path_is_split_where_cc_points_are_left_out_and_the_pieces_cut_short_there():
    mesh = grid_mesh(lambda x, y: 0.0 * x, 20, 4, (-20, -2, 20, 2), "strip")
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 2.0, 0.01)[0]
    n = len(path)
    drop = np.zeros(n, dtype=bool)
    drop[[1, 5, 6]] = True                                                  # a lone point, a pair inside
    pieces, keep = _split([path], drop)
    assert [len(p) for p in pieces] == [3, n - 7] and keep.tolist() == [2, 3, 4] + list(range(7, n))
    assert [p.cut_short for p in pieces] == [(True, True), (True, False)]  # the first point alone: dropped
    assert np.array_equal(np.concatenate([p.points for p in pieces]), path.points[keep])


def test_the_right_step_reaches_a_slanted_edge_of_the_mesh_to_the_bisection():
    # a plane whose edge runs slanted (y = -5 - 0.3 x): from CC points at y = 0 the section along -LY leaves
    # the mesh at the edge, found to d / 8 / 2^14, not at the last of 8 samples before it
    mesh = grid_mesh(lambda x, y: 0.0 * x, 20, 20, (-10, -10, 10, 10), "plane")
    v = mesh.vertices.copy()
    below = v[:, 1] < 0                                                     # the lower half squeezed to the edge
    v[below, 1] = (-5 - 0.3 * v[below, 0]) * (1 - (v[below, 1] + 10) / 10)
    mesh = TriMesh(v, mesh.triangles, "slanted")
    x = np.array([-6.0, -1.3, 0.0, 4.7])
    pts = np.column_stack([x, np.zeros(4), np.zeros(4)])
    frm = np.repeat(np.eye(3)[None], 4, axis=0)
    got = _on_mesh(MeshReach(mesh), pts, frm, np.full(4, 12.0))
    assert got == pytest.approx(5 + 0.3 * x, abs=1e-3)


def ramp_end():
    """A plane falling 40 deg along the feed (x), its plane-0 path as the planner moves its ends in, and a flat
    D 10 at lambda 1 deg (the bottom near the surface) at every CC point: (mesh, cutter, reach, cover, path,
    postures)."""
    slope = math.tan(math.radians(40.0))
    mesh = grid_mesh(lambda x, y: -slope * x, 40, 20, (-20, -10, 20, 10), "ramp")
    cutter, reach = Cutter.flat(10.0), MeshReach(mesh)
    cover = Coverage(mesh, np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 2.0, 5e-3, 5.0)
    grid = PostureGrid.degrees((0, 24), (-30, 30))
    path = _Planes(mesh, (1, 0), cover, 1.0, 0.01, 5.0, TarusMachine(), grid).paths(0.0)[0]
    n = len(path)
    lam, omg = np.full(n, math.radians(1.0)), np.zeros(n)
    tips, axes = world_placement(cutter, path.points, path.frames, lam, omg, np.zeros(n))
    q = PassPostures(np.zeros((n, 2), dtype=np.int64), lam, omg, np.zeros(n), tips, axes, np.zeros((n, 5)))
    return mesh, cutter, reach, cover, path, q


def test_an_end_moved_inside_passes_no_cc_point_and_its_overrun_reaches_the_edge():
    # a plane falling 40 deg along the feed: the planner moves each path's end in by the section's drift (LZ's
    # share of the feed, 0.64 R), past CC points 1 mm apart. Before: those points kept (the tool went on, back,
    # on again) and the overrun a radius from the moved end: the tool's centre stopped short of the mesh's edge
    # and its bottom's chord there reached short of 4.4 of 5 mm to the side (seed 000's complex surface: 1.69 mm
    # left between two passes at the path ends)
    mesh, cutter, reach, _, path, q = ramp_end()
    feed = path.points[:, 0]
    assert np.all(np.diff(feed) > 0)                                        # no CC point passed
    assert path.inset == pytest.approx((0.1 + 5.0 * math.sin(math.radians(40.0)),) * 2, abs=0.05)
    assert feed[-1] < 20.0 - 2.0 and not any(path.cut_short)
    run_t, run_a, _ = overrun_positions(reach, cutter, path, q, 5.0)
    xs, ys = np.meshgrid(np.arange(16.0, 19.8, 0.25), (-4.4, 4.4), indexing="ij")
    pts, nrm, hit = surface_samples(mesh, np.column_stack([xs.ravel(), ys.ravel()]))
    st, sa = swept_positions(run_t, run_a, 8)
    h = remaining(pts[hit], nrm[hit], st, sa, 5.0, 20.0)
    # the corners at the edge cut within the tolerance (before: 9 mm, and uncut, over the last 0.75 mm)
    assert hit.all() and h.min() >= -2e-3 and h.max() <= TOL + 2e-3


def test_the_stretch_beyond_a_moved_in_end_is_measured_under_the_tools():
    # the ramp above: the overrun carried to the edge finishes the 4.4 mm each side the end CC point claims;
    # one a radius from the moved end leaves the corners where the tool's centre trails its CC point (the last
    # end: the bottom tilted forward touches with its front rim), and the sections between that end and the
    # edge find them, on both sides; the first end's overrun leads with the centre and finishes it
    _, cutter, reach, cover, path, q = ramp_end()
    claim = np.full((2, 2), 4.4)
    full = overrun_positions(reach, cutter, path, q, 5.0)
    assert end_by_tools(reach, cutter, path, full[0], full[1], claim, TOL) == []
    short = overrun_positions(reach, cutter, replace(path, inset=(0.0, 0.0)), q, 5.0)
    found = end_by_tools(reach, cutter, path, short[0], short[1], claim, TOL)
    assert {(e, side) for e, side, _, _ in found} == {(1, 0), (1, 1)}
    for e, side, p, stop in found:
        assert p[0] > 20.0 - path.inset[1] * math.cos(math.radians(40.0)) - 1e-6   # between the end and the edge
        assert 0.0 <= abs(stop[1]) < 4.4 and (stop[1] - p[1]) * (1 if side == 0 else -1) >= 0.0
    ball = overrun_positions(reach, Cutter.bull(10.0, 1.0), path, q, 5.0)
    assert end_by_tools(reach, Cutter.bull(10.0, 1.0), path, ball[0], ball[1], claim, TOL) == []


def test_the_posture_is_held_near_the_cc_points_whose_edge_side_the_tools_leave_short():
    pts = np.column_stack([np.arange(0.0, 30.0, 2.0), np.zeros(15), np.zeros(15)])
    a, b = CCPath(0, 0.0, pts[:8], np.tile([0, 0, 1.0], (8, 1)), np.tile(np.eye(3), (8, 1, 1))), \
        CCPath(0, 0.0, pts[8:], np.tile([0, 0, 1.0], (7, 1)), np.tile(np.eye(3), (7, 1, 1)))
    short = np.zeros(15)
    short[3] = 0.4                                                          # x = 6 on the first path
    hold = _hold([a, b], short, 5.0)
    assert np.array_equal(np.flatnonzero(hold), [0, 1, 2, 3, 4, 5, 6])    # within 7.5 mm along its own path
    assert np.all(hold[:7] == HOLD) and not _hold([a, b], np.zeros(15), 5.0).any()


def test_the_stretch_the_tools_leave_at_a_moved_in_end_is_listed_to_the_edge():
    _, cutter, reach, cover, path, q = ramp_end()
    short = overrun_positions(reach, cutter, replace(path, inset=(0.0, 0.0)), q, 5.0)
    widths = np.full((len(path), 2), 4.4)
    ends = np.stack([path.points + 4.4 * path.frames[:, 1], path.points - 4.4 * path.frames[:, 1]], axis=1)
    listed = []
    list_ends(listed, cover, reach, cutter, [path], [short[:2]], widths, ends, TOL)
    assert len(listed) == 2                                                 # the last end, both sides
    for f0, f1, c0, c1 in listed:
        assert f0 <= 20.0 - path.inset[1] * math.cos(math.radians(40.0)) + 2.0 and f1 >= 20.0
        assert c0 < c1 and (c1 == pytest.approx(4.4, abs=0.01) or c0 == pytest.approx(-4.4, abs=0.01))
