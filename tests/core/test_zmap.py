"""Z-map simulation (core.zmap) against closed forms and brute force."""
import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tests.core import zmap_reference as zmap
from tests.core.zmap_reference import (ZTool, _torus_lowest, cut, interpolate_axis, lowest_z, move_instances,
                                    simulate, substeps)

Z = np.array([0.0, 0.0, 1.0])


def tilted_axis(beta_deg, azimuth_deg):
    b, c = math.radians(beta_deg), math.radians(azimuth_deg)
    return np.array([math.sin(b) * math.cos(c), math.sin(b) * math.sin(c), math.cos(b)])


def profile(rho, Ro, Ri):
    """Height of the round insert's lower surface above the tip at distance rho from the axis (vertical)."""
    rho = np.abs(rho)
    out = Ri - np.sqrt(np.maximum(Ri * Ri - (rho - Ro) ** 2, 0.0))
    out = np.where(rho < Ro - Ri, Ri, out)
    return np.where(rho <= Ro + Ri, out, np.inf)


def test_vertical_tool_single_position_is_the_profile():
    tool = ZTool(6.7, 6.0)
    tip = np.array([3.0, -2.0, 10.0])
    x = np.linspace(-14, 14, 2801)
    xy = np.column_stack([tip[0] + x, np.full_like(x, tip[1])])
    z = lowest_z(tool, np.repeat(tip[None], len(x), 0), np.repeat(Z[None], len(x), 0), xy)
    want = tip[2] + profile(x, 6.7, 6.0)
    # Away from the two vertical tangents (rho = Ro - Ri and Ro + Ri), where a height is ill-conditioned: a line
    # within TANGENT_TOL (1e-7 mm) of the tool counts as touching it.
    inside = (np.abs(x) <= 12.7 - 1e-3) & (np.abs(np.abs(x) - 0.7) > 1e-3)
    assert np.all(np.isinf(z[np.abs(x) > 12.7]))
    assert np.max(np.abs(z[inside] - want[inside])) < 1e-6
    # The hollow centre is closed by the body at the centre plane: height tip + Ri.
    assert z[1400] == pytest.approx(16.0, abs=1e-9)


def test_vertical_tool_moving_over_a_plane_closed_form():
    """A vertical torus fed along Y over a plane: needles within Ro of the path are cut to the tip height,
    beyond it to tip + profile(|dx|); sub-stepping may leave at most s^2 / (8 Ri)."""
    tool = ZTool(6.7, 6.0)
    tips = np.array([[0.0, 0.0, 5.0], [0.0, 20.0, 5.0]])
    axes = np.array([Z, Z])
    x = np.linspace(-13, 13, 521)
    needles = np.column_stack([x, np.full_like(x, 10.0)])
    step = 0.4
    rep = simulate(tool, needles, 50.0, [(tips, axes)], max_step=step, verify_tol=None)
    want = 5.0 + np.where(np.abs(x) <= 6.7, 0.0, profile(x, 6.7, 6.0))
    cut_ = np.isfinite(want)
    err = rep.z[cut_] - want[cut_]
    assert err.min() > -1e-9                       # never below the exact envelope
    assert err.max() <= step ** 2 / (8 * 6.0) + 1e-9
    assert np.all(rep.z[~cut_] == 50.0)


def test_ball_moving_horizontally_over_a_flat_is_exact():
    tool = ZTool(0.0, 3.0)
    tips = np.array([[0.0, 0.0, 1.0], [10.0, 0.0, 1.0]])
    axes = np.array([Z, Z])
    y = np.linspace(-3.5, 3.5, 141)
    needles = np.column_stack([np.full_like(y, 5.0), y])   # across the move, mid-way
    rep = simulate(tool, needles, 20.0, [(tips, axes)], max_step=0.5, verify_tol=None)
    want = np.where(np.abs(y) <= 3.0, 1.0 + 3.0 - np.sqrt(np.maximum(9.0 - y * y, 0.0)), 20.0)
    # Needles on a sub-step position are exact; the swept envelope of a ball moving across is the same
    # profile (the ball's lowest point over the needle at any time is reached when it passes over it).
    assert np.max(np.abs(rep.z - want)) < 1e-9


def test_ball_moving_on_an_inclined_line_capsule_bound():
    """Ball of radius r moving along an inclined segment: the envelope is the capsule; the sampled one is above
    it by at most s^2 / (8 r) (s = centre displacement per sub-step)."""
    r = 2.0
    tool = ZTool(0.0, r)
    a, b = np.array([0.0, 0.0, 0.0]), np.array([10.0, 3.0, 4.0])
    tips = np.array([a, b])
    rng = np.random.default_rng(3)
    needles = rng.uniform([1, -1.5], [9, 4.5], (1200, 2))
    step = 0.5
    rep = simulate(tool, needles, 100.0, [(tips, np.array([Z, Z]))], max_step=step, verify_tol=None)
    # Closed form: lowest z of the capsule (centres a + r z .. b + r z) on each vertical line, by minimising
    # over the segment parameter analytically on a fine grid refined by golden search is avoided: the capsule's
    # lowest point on a line at horizontal distance d(t) from the centre c(t) is c_z(t) - sqrt(r^2 - d(t)^2),
    # minimised over t in [0, 1] (a convex problem: dense grid + local parabola is exact to 1e-9 here).
    ca, cb = a + [0, 0, r], b + [0, 0, r]
    t = np.linspace(0, 1, 50001)
    cx = ca[0] + t * (cb[0] - ca[0])
    cy = ca[1] + t * (cb[1] - ca[1])
    cz = ca[2] + t * (cb[2] - ca[2])
    want = np.empty(len(needles))
    for k, (x, y) in enumerate(needles):
        d2 = (x - cx) ** 2 + (y - cy) ** 2
        v = np.where(d2 <= r * r, cz - np.sqrt(np.maximum(r * r - d2, 0.0)), np.inf)
        want[k] = v.min()
    # Lateral distance of each needle from the path's vertical plane: the capsule's slope across is
    # asin(d / r); the cusp s^2 / (8 r) is along the normal, the vertical error grows by 1 / cos of the slope
    # (across and along the path), so the check is kept to d <= 0.8 r.
    u = (b - a)[:2] / np.linalg.norm((b - a)[:2])
    d = np.abs((needles - a[:2]) @ np.array([-u[1], u[0]]))
    hit = np.isfinite(want) & (want < 99) & (d <= 0.8 * r)
    err = rep.z[hit] - want[hit]
    n = substeps(tool, a, Z, b, Z, step)
    s = np.linalg.norm(b - a) / n
    incline = math.atan2((b - a)[2], np.linalg.norm((b - a)[:2]))
    factor = 1.0 / (math.cos(incline) * math.sqrt(1 - 0.8 ** 2))
    assert err.min() > -1e-6
    assert err.max() <= factor * s * s / (8 * r) + 1e-6
    assert hit.sum() > 400


def test_tilted_torus_single_position_vs_brute_force():
    """The lowest point of a tilted torus on vertical lines vs the brute-force minimum over a dense sampling of
    the torus as a union of balls of radius Ri on its major circle (1e5 centres), where the torus governs."""
    Ro, Ri = 6.7, 6.0
    tool = ZTool(Ro, Ri)
    tip = np.array([1.0, 2.0, 3.0])
    a = tilted_axis(25.0, 40.0)
    C = tip + Ri * a
    e1 = np.cross(a, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    phi = np.linspace(0, 2 * np.pi, 100000, endpoint=False)
    circ = C + Ro * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2)
    rng = np.random.default_rng(7)
    needles = C[:2] + rng.uniform(-12, 12, (300, 2))
    z = lowest_z(tool, np.repeat(tip[None], len(needles), 0), np.repeat(a[None], len(needles), 0), needles)
    zt = _torus_lowest(C[None].repeat(len(needles), 0), a[None].repeat(len(needles), 0), needles - C[:2],
                       Ro, Ri) + C[2]
    brute = np.empty(len(needles))
    for k, (x, y) in enumerate(needles):
        d2 = (x - circ[:, 0]) ** 2 + (y - circ[:, 1]) ** 2
        v = np.where(d2 <= Ri * Ri, circ[:, 2] - np.sqrt(np.maximum(Ri * Ri - d2, 0.0)), np.inf)
        brute[k] = v.min()
    both = np.isfinite(brute)
    assert both.sum() > 150
    assert np.array_equal(np.isfinite(zt), both)
    assert np.max(np.abs(zt[both] - brute[both])) < 2e-5
    # The whole solid (torus, body over the hollow, shank) is never higher than the torus alone.
    assert np.all(z[both] <= zt[both] + 1e-12)


def test_lowest_point_lies_on_the_kernel_tool_solid():
    """Against the kernel's signed distance to the same tool solid: the found point is on the boundary and the
    line below it is outside; missed lines stay outside the solid."""
    from tmm_workbench.core.strategies.multipoint import BezierFace, make_positioner
    net = np.zeros((2, 2, 3))
    net[..., 0] = [[0, 0], [100, 100]]
    net[..., 1] = [[0, 100], [0, 100]]
    mp = make_positioner(BezierFace.from_net(net), 6.7, 6.0)
    tool = ZTool(6.7, 6.0)
    tip = np.array([10.0, 20.0, 5.0])
    a = tilted_axis(30.0, 53.0)
    rng = np.random.default_rng(1)
    xy = tip[:2] + rng.uniform(-16, 16, (4000, 2))
    z = lowest_z(tool, np.repeat(tip[None], len(xy), 0), np.repeat(a[None], len(xy), 0), xy)
    hit = np.isfinite(z)
    pts = np.column_stack([xy[hit], z[hit]])
    assert np.max(np.abs(mp.tool_distance(tip, a, pts))) < 1e-6
    assert mp.tool_distance(tip, a, pts - [0, 0, 1e-4]).min() > 0
    miss = xy[~hit][:100]
    zs = np.linspace(-20, 60, 1601)
    line = np.column_stack([np.repeat(miss, len(zs), 0), np.tile(zs, len(miss))])
    assert mp.tool_distance(tip, a, line).min() > 0


def test_substeps_bound_every_tool_point_displacement():
    tool = ZTool(6.7, 6.0)
    t0, t1 = np.array([0.0, 0.0, 0.0]), np.array([0.5, 2.0, -0.3])
    a0, a1 = tilted_axis(10, 0), tilted_axis(14, 30)
    step = 0.25
    T, A = move_instances(tool, np.array([t0, t1]), np.array([a0, a1]), step)
    assert len(T) == substeps(tool, t0, a0, t1, a1, step) + 1
    # Points of the torus in each instance's frame (same material point: frame carried by the rotation).
    phi = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    P, Th = np.meshgrid(phi, th)
    n = np.cross(a0, a1)
    n /= np.linalg.norm(n)

    def rot(v, ang):  # Rodrigues about n: the slerp rotation carries the tool's frame
        return v * math.cos(ang) + np.cross(n, v) * math.sin(ang) + n * np.dot(n, v) * (1 - math.cos(ang))

    f1 = np.cross(a0, [0.0, 1.0, 0.0])
    f1 /= np.linalg.norm(f1)
    f2 = np.cross(a0, f1)
    rho = 6.7 + 6.0 * np.cos(Th)
    h = 6.0 * np.sin(Th)
    worst = 0.0
    prev = None
    for tip, ax in zip(T, A):
        ang = math.atan2(np.dot(np.cross(a0, ax), n), np.dot(a0, ax))
        e1, e2, aa = rot(f1, ang), rot(f2, ang), rot(a0, ang)
        assert np.allclose(aa, ax, atol=1e-9)
        pts = (tip + 6.0 * ax + (rho * np.cos(P))[..., None] * e1 + (rho * np.sin(P))[..., None] * e2
               + h[..., None] * ax)
        if prev is not None:
            worst = max(worst, float(np.max(np.linalg.norm(pts - prev, axis=-1))))
        prev = pts
    assert worst <= step + 1e-9


def test_interpolation_modes_and_verification():
    a0, a1 = tilted_axis(0, 0), tilted_axis(30, 90)
    s = np.linspace(0, 1, 7)
    sl = interpolate_axis(a0, a1, s, "slerp")
    nl = interpolate_axis(a0, a1, s, "nlerp")
    ang = np.degrees(np.arccos(np.clip(sl @ a0, -1, 1)))
    assert np.allclose(ang, 30 * s, atol=1e-9)          # slerp: constant angular rate
    assert np.allclose(np.linalg.norm(nl, axis=1), 1.0)
    assert np.allclose(nl[[0, -1]], sl[[0, -1]])
    with pytest.raises(TmmError):
        interpolate_axis(a0, a1, s, "cubic")
    # Verification converges below its tolerance.
    tool = ZTool(6.7, 6.0)
    tips = np.array([[0.0, 0.0, 0.0], [0.0, 4.0, 0.5], [0.0, 8.0, 0.0]])
    axes = np.array([tilted_axis(5, 0), tilted_axis(15, 10), tilted_axis(5, 0)])
    x = np.linspace(-12, 12, 241)
    rep = simulate(tool, np.column_stack([x, np.full_like(x, 4.0)]), 30.0, [(tips, axes)], max_step=1.0,
                   verify_tol=1e-3)
    assert rep.last_change <= 1e-3 and rep.refine >= 2


def test_cut_keeps_the_minimum_and_rejects_downward_axes():
    tool = ZTool(6.7, 6.0)
    needles = np.array([[0.0, 0.0], [100.0, 0.0]])
    z = np.array([-1.0, 5.0])
    cut(tool, needles, z, np.array([[0.0, 0.0, 0.0]]), np.array([Z]))
    assert z[0] == -1.0 and z[1] == 5.0                  # already lower; out of reach
    with pytest.raises(TmmError):
        lowest_z(tool, np.zeros((1, 3)), np.array([[0, 0, -1.0]]), np.zeros((1, 2)))


def test_closed_form_quartic_matches_eigenvalues():
    """The Ferrari roots (with the eigenvalue fallback for doubtful lines) give the same lowest points as the
    companion-matrix eigenvalues alone, on random tilted tori and lines."""
    rng = np.random.default_rng(5)
    n = 40000
    b, c = np.radians(rng.uniform(0, 45, n)), rng.uniform(0, 2 * np.pi, n)
    b[:5000] = 0.0                                        # vertical axes: Q = 0, the biquadratic case
    a = np.column_stack([np.sin(b) * np.cos(c), np.sin(b) * np.sin(c), np.cos(b)])
    q = rng.uniform(-13, 13, (n, 2))
    z1 = _torus_lowest(np.zeros((n, 3)), a, q, 6.7, 6.0)
    az, qa, qq = a[:, 2], q[:, 0] * a[:, 0] + q[:, 1] * a[:, 1], (q ** 2).sum(1)
    R2 = 6.7 ** 2
    K = qq + R2 - 36.0
    P, Q, R = 2 * K - 4 * R2 * (1 - az * az), 8 * R2 * qa * az, K * K - 4 * R2 * (qq - qa * qa)
    t, _ = zmap._accept(zmap._eig_roots(P, Q, R), P, Q, R, qa, qq, az, 6.7, 6.0)
    z2 = t.min(axis=1)
    assert np.array_equal(np.isfinite(z1), np.isfinite(z2))
    f = np.isfinite(z1)
    assert f.sum() > 10000
    assert np.max(np.abs(z1[f] - z2[f])) < 1e-9
