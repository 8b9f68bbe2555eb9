"""Multipoint positioning (seed 001) through the core API, checked independently of the kernel:
the face against the numpy Bézier evaluator and de Boor, contacts against the torus' own formula, and no
penetration by dense numpy sampling of the surface under the tool."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tests.conftest import SEED_JSON
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.geometry.bspline import bspline_to_bezier, flat_knots
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.strategies.multipoint import (STATUS_FAILED, STATUS_ONE, STATUS_TWO, BezierFace, MultipointParams,
                                           compute_multipoint_toolpath, multipoint_footprint, position_points)
from tmm_workbench.core.toolpath import MoveKind

SEEDS = SEED_JSON
RO, RI = 6.7, 6.0


def bspline_point(poles, degree_u: int, degree_v: int, U: np.ndarray, V: np.ndarray, u: float, v: float) -> np.ndarray:
    """S(u, v) of a non-rational B-spline by de Boor's algorithm: independent of the knot insertion that
    core.geometry.bspline converts with, which is what it checks."""
    P = np.asarray(poles, dtype=float)

    def de_boor(ctrl, knots, p, t):
        n = len(ctrl)
        k = p
        while k < n - 1 and knots[k + 1] <= t:
            k += 1
        d = [np.array(ctrl[j + k - p], dtype=float) for j in range(p + 1)]
        for r in range(1, p + 1):
            for j in range(p, r - 1, -1):
                i = j + k - p
                den = knots[i + p - r + 1] - knots[i]
                a = 0.0 if den == 0 else (t - knots[i]) / den
                d[j] = (1 - a) * d[j - 1] + a * d[j]
        return d[p]

    rows = np.array([de_boor(P[i], V, degree_v, v) for i in range(P.shape[0])])
    return de_boor(rows, U, degree_u, u)


def seed_net(kind: str) -> np.ndarray:
    if kind == "saddle":  # seed 001 table 1, not in the shared file
        return bezier.load_seed_patch(SEEDS, "saddle")
    if SEEDS.exists():
        z = json.loads(SEEDS.read_text())["singh2020_bezier"]["z"][kind]
    else:  # seed 001, table 1
        z = {"convex": [80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80],
             "concave": [80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80]}[kind]
    net = np.zeros((4, 4, 3))
    net[..., 0] = 50.0 * np.arange(4)[:, None]
    net[..., 1] = 50.0 * np.arange(4)[None, :]
    net[..., 2] = np.asarray(z, dtype=float).reshape(4, 4)
    return net


def torus_distance(tip, axis, pts):
    """Signed distance to the round-insert tool from the torus' definition: distance to the major circle
    minus Ri, and the body above the centre plane (rho <= Ro + Ri)."""
    c = tip + RI * axis
    d = pts - c
    h = d @ axis
    rho = np.linalg.norm(d - h[:, None] * axis, axis=1)
    torus = np.sqrt((rho - RO) ** 2 + h ** 2) - RI
    body = np.where((h >= 0) & (rho <= RO + RI), -np.minimum(h, RO + RI - rho), np.inf)
    return np.minimum(torus, body)


def dense_penetration(net, tip, axis, step=0.05):
    """Deepest point of the surface inside the tool, sampling the surface every `step` mm under the tool
    (x = 150 u, y = 150 v on the seed patches)."""
    c = tip + RI * axis
    r = RO + RI + 1.0
    xs = np.arange(max(0.0, c[0] - r), min(150.0, c[0] + r) + 1e-9, step)
    ys = np.arange(max(0.0, c[1] - r), min(150.0, c[1] + r) + 1e-9, step)
    if len(xs) == 0 or len(ys) == 0:
        return 0.0
    S = bezier.evaluate_grid(net, xs / 150.0, ys / 150.0).reshape(-1, 3)
    return max(0.0, float(-torus_distance(tip, axis, S).min()))


def assert_same_positions(a, b):
    """Two contacts in both: the same solution. Otherwise (near-osculating, sphere-like regions where the
    second contact and the curvature limit at P arrive within 1e-4 rad of each other) the same pose within
    what the tolerance allows."""
    assert (a.status != STATUS_FAILED).all() and (b.status != STATUS_FAILED).all()
    two = (a.status == STATUS_TWO) & (b.status == STATUS_TWO)
    np.testing.assert_allclose(a["beta"][two], b["beta"][two], atol=1e-7)
    np.testing.assert_allclose(a["tip"][two], b["tip"][two], atol=1e-5)
    np.testing.assert_allclose(a["beta"], b["beta"], atol=1e-3)
    np.testing.assert_allclose(a["tip"], b["tip"], atol=1e-2)


@pytest.fixture(scope="module", params=["convex", "concave"])
def seed_run(request):
    net = seed_net(request.param)
    face = BezierFace.from_net(net, name=request.param)
    params = MultipointParams(side_step=18.0, forward_step=2.0, margin=0.0)
    path, res = compute_multipoint_toolpath(face, Cutter.torus(RO, RI), params)
    return request.param, net, face, path, res


def test_face_evaluates_like_the_numpy_reference():
    net = seed_net("convex")
    face = BezierFace.from_net(net)
    rng = np.random.default_rng(0)
    uv = rng.uniform(0, 1, size=(200, 2))
    got = face.evaluate(uv)
    ref = bezier.derivatives(net, uv[:, 0], uv[:, 1])
    for k in ("S", "Su", "Sv", "Suu", "Suv", "Svv"):
        np.testing.assert_allclose(got[k], ref[k], atol=1e-9)


def test_bspline_split_is_exact_and_seamless_in_the_kernel():
    rng = np.random.default_rng(1)
    p, q = 3, 2
    ku, mu = [0.0, 0.3, 0.5, 1.2, 2.0], [4, 1, 2, 1, 4]
    kv, mv = [0.0, 1.0, 2.5, 3.0], [3, 1, 1, 3]
    nu, nv = sum(mu) - p - 1, sum(mv) - q - 1
    gx, gy = np.meshgrid(np.arange(nu) * 10.0, np.arange(nv) * 10.0, indexing="ij")
    poles = np.stack([gx, gy, np.zeros_like(gx)], -1) + rng.normal(size=(nu, nv, 3))
    face = BezierFace.from_bspline(poles, p, q, ku, mu, kv, mv)
    assert (face.native.nu, face.native.nv) == (4, 3)
    U, V = flat_knots(ku, mu), flat_knots(kv, mv)
    uv = np.array([(u, v) for u in np.linspace(0, 2, 17) for v in np.linspace(0, 3, 13)])
    got = face.evaluate(uv)["S"]
    ref = np.array([bspline_point(poles, p, q, U, V, u, v) for u, v in uv])
    np.testing.assert_allclose(got, ref, atol=1e-10)
    # C1 across the seams (interior knots of multiplicity 1 in u at 0.3 and 1.2 for the cubic: C2).
    for s in (0.3, 1.2):
        a = face.evaluate(np.array([[s - 1e-9, 1.7]]))
        b = face.evaluate(np.array([[s + 1e-9, 1.7]]))
        np.testing.assert_allclose(a["Su"], b["Su"], rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(a["Suu"], b["Suu"], rtol=1e-5, atol=1e-4)


def test_rational_and_periodic_bsplines_are_refused_clearly():
    poles = np.zeros((4, 4, 3))
    poles[..., 0], poles[..., 1] = np.meshgrid(np.arange(4.0), np.arange(4.0), indexing="ij")
    w = np.ones((4, 4))
    w[1, 1] = 2.0
    with pytest.raises(TmmError, match="rational"):
        bspline_to_bezier(poles, 3, 3, [0, 1], [4, 4], [0, 1], [4, 4], weights=w)
    with pytest.raises(TmmError, match="periodic"):
        bspline_to_bezier(poles, 3, 3, [0, 1], [4, 4], [0, 1], [4, 4], periodic_u=True)
    # Weights all 1 are a polynomial surface: accepted.
    pieces = bspline_to_bezier(poles, 3, 3, [0, 1], [4, 4], [0, 1], [4, 4], weights=np.ones((4, 4)))
    np.testing.assert_allclose(pieces.nets[0], poles)


def test_seed_footprint_matches_the_seed():
    face = BezierFace.from_net(seed_net("convex"))
    passes = multipoint_footprint(face, MultipointParams(side_step=18.0, forward_step=2.0, zigzag=False))
    xs = [p[0, 0] for p in passes]
    assert len(passes) == 10 and xs[0] == pytest.approx(0.0) and xs[-1] == pytest.approx(150.0)
    assert np.allclose(np.diff(xs), 150.0 / 9)  # evenly spread, <= the side step
    assert all(np.allclose(np.diff(p[:, 1]), np.diff(p[:, 1])[0]) for p in passes)
    assert all(np.diff(p[:, 1]).max() <= 2.0 + 1e-9 for p in passes)


def test_fixed_pass_spacing_is_the_seeds_footprint():
    """pass_spacing "fixed": 18 mm from the start edge and a last pass on the far edge - the seed's 760 points
    (benchmarks.seed.experiment.seed_footprint, written out independently), whatever the side the feed starts."""
    from benchmarks.seed.experiment import seed_footprint
    face = BezierFace.from_net(seed_net("convex"))
    passes = multipoint_footprint(face, MultipointParams(pass_spacing="fixed"))
    seed = seed_footprint()
    assert len(passes) == len(seed) == 10
    for got, want in zip(passes, seed):
        np.testing.assert_allclose(got, want, atol=1e-9)
    # Feed along X (side step along Y), and a side step that divides the extent: no doubled last pass.
    for angle, step, count in ((0.0, 18.0, 10), (0.0, 15.0, 11), (180.0, 18.0, 10)):
        passes = multipoint_footprint(face, MultipointParams(feed_angle_deg=angle, side_step=step,
                                                             pass_spacing="fixed", zigzag=False))
        across = np.array([p[0, 1] for p in passes])
        assert len(passes) == count, (angle, step, across)
        expected = np.minimum(np.arange(count) * step, 150.0)
        np.testing.assert_allclose(np.sort(across), expected, atol=1e-9)
        np.testing.assert_allclose(across[0], 0.0, atol=1e-9)  # from the (xmin, ymin) corner's side
    with pytest.raises(TmmError, match="pass spacing"):
        multipoint_footprint(face, MultipointParams(pass_spacing="tight"))


def test_seed_surfaces_contacts_touch_and_nothing_penetrates(seed_run):
    kind, net, face, path, res = seed_run
    st = res.status
    assert (st == STATUS_FAILED).sum() == 0, [r for r in res.records() if r["status"] == "failed"][:3]
    assert (st == STATUS_TWO).sum() >= 0.75 * len(st)
    uvP, uvQ = res["uvP"], res["uvQ"]
    np.testing.assert_allclose(bezier.evaluate(net, uvP[:, 0], uvP[:, 1]), res["P"], atol=1e-9)
    np.testing.assert_allclose(bezier.evaluate(net, uvQ[:, 0], uvQ[:, 1]), res["Q"], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(res["axis"], axis=1), 1.0, atol=1e-12)
    for i in range(len(res)):
        tip, axis = res["tip"][i], res["axis"][i]
        gP = torus_distance(tip, axis, res["P"][i:i + 1])[0]
        gQ = torus_distance(tip, axis, res["Q"][i:i + 1])[0]
        assert abs(gP) < 1e-3 and abs(gQ) < 1e-3, (kind, res.xy[i], gP, gQ)
    # Dense sampling on a spread of positions (all passes, every 7th point).
    for i in range(0, len(res), 7):
        pen = dense_penetration(net, res["tip"][i], res["axis"][i])
        assert pen < 1e-3, (kind, res.xy[i], pen, res.reason_texts()[i])


def test_toolpath_moves_carry_tip_and_axis(seed_run):
    kind, net, face, path, res = seed_run
    ok = res.status != STATUS_FAILED
    good = int(ok.sum())
    tips = {tuple(t) for t in res["tip"][ok]}
    cutting = [m for m in path if m.kind is not MoveKind.RAPID and (m.x, m.y, m.z) in tips]
    assert len(cutting) == good
    # the other fed moves are the approaches and exits along the axis (below the safe height: never rapid)
    assert all(m.kind is MoveKind.PLUNGE for m in path if m.kind is not MoveKind.RAPID and (m.x, m.y, m.z) not in tips)
    assert path.is_five_axis()
    ax = path.axes()
    np.testing.assert_allclose(np.linalg.norm(ax, axis=1), 1.0, atol=1e-12)
    assert (ax[:, 2] > math.cos(math.radians(45.0)) - 1e-12).all()
    assert path.moves[0].kind is MoveKind.RAPID and path.moves[-1].kind is MoveKind.RAPID


def test_drd_agrees_with_vcrf():
    for kind in ("convex", "concave"):
        face = BezierFace.from_net(seed_net(kind))
        xy = np.array([[40.0, 60.0], [75.0, 75.0], [110.0, 30.0], [30.0, 120.0]])
        a = position_points(face, RO, RI, xy, method="vcrf")
        b = position_points(face, RO, RI, xy, method="drd")
        assert_same_positions(a, b)


def test_seed_global_x_rotation_differs_from_the_exact_one():
    face = BezierFace.from_net(seed_net("concave"))
    xy = np.column_stack([np.arange(20.0, 131.0, 10.0), np.full(12, 40.0)])
    exact = position_points(face, RO, RI, xy)
    seed = position_points(face, RO, RI, xy, MultipointParams(rotation="global_x"))
    two = exact.status == STATUS_TWO
    np.testing.assert_allclose(exact["beta"][two], seed["beta"][two], atol=1e-12)
    assert exact["seed_axis_angle"][two].max() > math.radians(1.0)
    # The exact tilt keeps both contacts; the seed's does not.
    assert np.abs(exact["gap_Q"][two]).max() < 1e-6
    assert max(np.abs(seed["gap_Q"][two]).max(), seed["penetration"][two].max()) > 1e-2


def test_ball_is_one_contact_flat_and_bad_radii_refused():
    face = BezierFace.from_net(seed_net("convex"))
    res = position_points(face, 0.0, 5.0, np.array([[60.0, 70.0]]))
    assert res.status[0] == STATUS_ONE and "ball" in res.reason_texts()[0]
    assert np.linalg.norm(res["centre"][0] - res["P"][0]) == pytest.approx(5.0, abs=1e-6)
    with pytest.raises(TmmError, match="flat end mill"):
        position_points(face, 6.0, 0.0, np.array([[60.0, 70.0]]))
    with pytest.raises(TmmError, match="Ro"):
        position_points(face, -1.0, 2.0, np.array([[60.0, 70.0]]))
    with pytest.raises(TmmError, match="method"):
        position_points(face, 6.7, 6.0, np.array([[60.0, 70.0]]), method="newton")
    with pytest.raises(TmmError, match="side step"):
        compute_multipoint_toolpath(face, Cutter.torus(6.7, 6.0), MultipointParams(side_step=0.0))


def test_bull_nose_on_convex_keeps_one_contact_without_gouge():
    net = seed_net("convex")
    face = BezierFace.from_net(net)
    res = position_points(face, RO, RI, np.array([[75.0, 75.0], [40.0, 60.0]]), MultipointParams(shape="bull_nose"))
    assert (res.status != STATUS_FAILED).all()
    assert (res["penetration"] < 1e-3).all()


def test_any_feed_direction_and_margin():
    face = BezierFace.from_net(seed_net("concave"))
    params = MultipointParams(side_step=25.0, forward_step=5.0, feed_angle_deg=30.0, margin=-10.0)
    path, res = compute_multipoint_toolpath(face, Cutter.torus(RO, RI), params)
    assert len(res) > 20
    assert res.xy[:, 0].min() >= 10.0 - 1e-9 and res.xy[:, 0].max() <= 140.0 + 1e-9
    assert (res.status != STATUS_FAILED).all()
    first = res.xy[res.passes == res.passes[0]]  # inserted positions (multipoint_refine) come last: sorted
    d = np.diff(first[np.argsort(first @ [np.cos(np.radians(30)), np.sin(np.radians(30))])], axis=0)
    ang = np.degrees(np.arctan2(d[:, 1], d[:, 0]))
    assert np.allclose(ang, 30.0, atol=1e-6)


def test_progress_and_cancel():
    face = BezierFace.from_net(seed_net("convex"))
    seen = []

    def progress(f):
        seen.append(f)
        return True

    compute_multipoint_toolpath(face, Cutter.torus(RO, RI), MultipointParams(side_step=10.0, forward_step=1.0), progress=progress)
    assert seen and seen[-1] == 1.0
    with pytest.raises(Cancelled):
        compute_multipoint_toolpath(face, Cutter.torus(RO, RI), MultipointParams(side_step=5.0, forward_step=0.5),
                                    progress=lambda f: False)


def test_multi_patch_face_positions_like_the_single_patch_across_seams():
    """The seed patch cut into 3 x 2 Bézier pieces (uneven breakpoints): same surface, so the same positions,
    including where P or Q lie across a seam from the footprint point."""
    from tmm_workbench.core.kernel import native
    net = seed_net("concave")
    bu, bv = [0.0, 0.3, 0.55, 1.0], [0.0, 0.48, 1.0]
    nets = [native.bezier_subpatch(net, bu[i], bu[i + 1], bv[j], bv[j + 1]) for i in range(3) for j in range(2)]
    whole = BezierFace.from_net(net)
    split = BezierFace(nets, 3, 2, bu, bv)
    xy = np.array([[45.0, 72.0], [82.5, 72.0], [45.0, 60.0], [60.0, 100.0], [120.0, 40.0]])
    a = position_points(whole, RO, RI, xy)
    b = position_points(split, RO, RI, xy)
    np.testing.assert_allclose(a["P"], b["P"], atol=1e-6)
    assert_same_positions(a, b)


def test_seed_saddle_surface_no_failures_no_gouge():
    """Seed 001 table 1's saddle (concave and convex regions, transitions): every position placed, none
    gouging by dense sampling, DRD agreeing with VCRF."""
    net = seed_net("saddle")
    face = BezierFace.from_net(net)
    xs = list(np.arange(0.0, 150.0, 18.0)) + [150.0]
    xy = np.array([(x, y) for x in xs for y in np.arange(0.0, 151.0, 4.0)])
    res = position_points(face, RO, RI, xy)
    assert (res.status != STATUS_FAILED).all(), [r for r in res.records() if r["status"] == "failed"][:3]
    for i in range(0, len(res), 6):
        assert dense_penetration(net, res["tip"][i], res["axis"][i], 0.1) < 1e-3, res.xy[i]
    sub = xy[::9]
    assert_same_positions(position_points(face, RO, RI, sub), position_points(face, RO, RI, sub, method="drd"))


def test_extend_and_anchor_options_are_validated():
    face = BezierFace.from_net(seed_net("concave"))
    for bad in (MultipointParams(extend=-1.0), MultipointParams(extend=float("nan")),
                MultipointParams(anchor="cc"), MultipointParams(anchor_iterations=0)):
        with pytest.raises(TmmError):
            position_points(face, RO, RI, np.array([[50.0, 50.0]]), bad)


@pytest.mark.parametrize("method", ["vcrf", "drd"])
def test_extension_on_the_concave_rim_touches_the_continued_bowl_without_gouging_the_patch(method):
    """A pass on the concave patch's rim x = 0: without extension the tool rests on the boundary curve
    (u = 0 at both contacts); with the face extended by Ro + Ri the first contact lies on the continuation
    (u < 0; at the section both do), both touch the tool, and the real patch, sampled densely and
    independently, is not entered."""
    net = seed_net("concave")
    face = BezierFace.from_net(net)
    xy = np.array([[0.0, 26.0], [0.0, 28.0], [0.0, 60.0]])
    plain = position_points(face, RO, RI, xy, MultipointParams(), method)
    ext = position_points(face, RO, RI, xy, MultipointParams(extend=RO + RI), method)
    assert (plain.status == STATUS_TWO).all() and (ext.status == STATUS_TWO).all()
    np.testing.assert_allclose(plain["uvP"][:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(plain["uvQ"][:, 0], 0.0, atol=1e-12)
    assert (ext["on_extension"][:2] == 3).all() and (plain["on_extension"] == 0).all()
    assert (ext["on_extension"] & 1).all() and (ext["uvP"][:, 0] < 0).all() and (ext["uvQ"][:2, 0] < 0).all()
    Pext = bezier.evaluate(net, ext["uvP"][:, 0], ext["uvP"][:, 1])      # the polynomial, continued
    np.testing.assert_allclose(Pext, ext["P"], atol=1e-9)
    for i in range(len(xy)):
        tip, axis = ext["tip"][i], ext["axis"][i]
        assert abs(torus_distance(tip, axis, ext["P"][i:i + 1])[0]) < 1e-3
        assert abs(torus_distance(tip, axis, ext["Q"][i:i + 1])[0]) < 1e-3
        assert dense_penetration(net, tip, axis) < 1e-3
        assert ext["penetration_real"][i] <= 1e-3
        # the wedge beside the rim (x = 6.44 at the section): material left by the tool on the rim, cut by
        # the tool on the extension
        w = bezier.evaluate(net, np.array([6.44 / 150]), np.array([xy[i, 1] / 150]))
        assert torus_distance(plain["tip"][i], plain["axis"][i], w)[0] > 1.2
        assert torus_distance(tip, axis, w)[0] < 0.6


def test_tip_anchor_lands_the_tilted_tip_on_the_footprint():
    net = seed_net("concave")
    face = BezierFace.from_net(net)
    xy = np.array([[18.0, 27.0], [36.0, 27.0], [108.0, 90.0]])
    a = position_points(face, RO, RI, xy, MultipointParams(anchor="axis"))
    t = position_points(face, RO, RI, xy, MultipointParams(anchor="tip"))
    assert np.linalg.norm(a["tip"][:, :2] - xy, axis=1).max() > 0.5     # the tilt moves the tip
    np.testing.assert_allclose(a["axis_xy"], xy)
    assert np.linalg.norm(t["tip"][:, :2] - xy, axis=1).max() < 1e-3
    np.testing.assert_allclose(t["anchor_error"], np.linalg.norm(t["tip"][:, :2] - xy, axis=1), atol=1e-12)
    again = position_points(face, RO, RI, t["axis_xy"], MultipointParams(anchor="axis"))
    np.testing.assert_allclose(again["tip"], t["tip"], atol=1e-9)
    for i in range(len(xy)):
        assert dense_penetration(net, t["tip"][i], t["axis"][i]) < 1e-3
