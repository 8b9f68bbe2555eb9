"""Side step from a scallop height (core.strategies.multipoint_scallop, issue 14 item 5): the placed passes'
scallop read again by the independent Python z-map (tests/core/zmap_reference.py, its own line-torus solves) on needle
lines the placement did not use, no gouge, the design heights, the frame, bad input and the work estimate."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SEED_JSON
from tmm_workbench.core import limits
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.strategies import multipoint
from tmm_workbench.core.strategies.multipoint import STATUS_FAILED, BezierFace, MultipointParams
from tmm_workbench.core.strategies.multipoint_meter import END_INSET, DesignHeights, Frame
from tmm_workbench.core.strategies.multipoint_scallop import estimate_passes
from tmm_workbench.core.tools.cutter import Cutter
from tests.core.zmap_reference import ZTool, simulate

TORUS = Cutter.torus(6.7, 6.0)
BOX = (30.0, 40.0, 85.0, 70.0)  # a part of the seed patch: 4-5 passes, a few seconds


@pytest.fixture(scope="module")
def convex_net() -> np.ndarray:
    return bezier.load_seed_patch(SEED_JSON, "convex")


@pytest.fixture(scope="module", params=["round_insert", "bull_nose"])
def placed(convex_net, request):
    """The seed's round insert (two contacts) at 0.3 mm, and a solid bull-nose (its flat bottom: one contact,
    away from the tip) at 0.05 mm."""
    face = BezierFace.from_net(convex_net)
    h, box = (0.3, BOX) if request.param == "round_insert" else (0.05, (30.0, 40.0, 50.0, 70.0))
    params = MultipointParams(pass_spacing="scallop", scallop=h, side_step=10.0, forward_step=2.0,
                              boundary=box, between_tol=0.0, shape=request.param)
    return multipoint.compute(face, TORUS, params), params


def design(net: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The seed nets have x = 50 i, y = 50 j: x(u) = 150 u, y(v) = 150 v exactly (linear precision)."""
    return bezier.evaluate(net, x / 150.0, y / 150.0)[..., 2]


def test_design_heights_invert_the_face(convex_net):
    face = BezierFace.from_net(convex_net)
    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 150, size=(200, 2))
    z = DesignHeights(face)(xy)
    assert np.allclose(z, design(convex_net, xy[:, 0], xy[:, 1]), atol=1e-6)
    assert np.isnan(DesignHeights(face)(np.array([[-5.0, 20.0], [20.0, 151.0]]))).all()  # off the face


@pytest.mark.parametrize("angle", [90.0, 0.0, 30.0, -120.0])
def test_frame_is_a_rotation_starting_at_the_corner(angle):
    rect = (10.0, 20.0, 60.0, 45.0)
    fr = Frame.of(rect, angle)
    assert abs(fr.c @ fr.f) < 1e-12 and np.allclose([fr.c @ fr.c, fr.f @ fr.f], 1.0)
    assert np.allclose(fr.f, (np.cos(np.radians(angle)), np.sin(np.radians(angle))))  # along the feed
    p = np.array([[1.0, 2.0, 3.0], [-4.0, 5.0, -6.0]])
    assert np.allclose(fr.to_world(fr.to_frame(p)), p)
    corner = np.array([rect[0], rect[1]]) @ fr.c
    assert abs(corner - fr.a0) <= abs(corner - fr.a1)  # the first pass nearest (xmin, ymin), as FIXED
    if angle == 90.0:
        assert np.allclose(fr.c, (1, 0)) and np.allclose((fr.a0, fr.a1), (10.0, 60.0))


def row_deviations(result, params: MultipointParams, net: np.ndarray, ys, spacing: float
                   ) -> tuple[list[float], float]:
    """The independent z-map of every pass's positions on needle lines across the boundary at each y, needles
    `spacing` apart from the first pass's first contact to the last pass's last contact (what lies beyond
    them is the boundary's, not the side step's): per line its highest value above the design, and the
    lowest value of all."""
    res = result.diagnostics["results"]
    tool = ZTool(6.7, 6.0, params.shape)
    paths, bands = [], []
    for k in range(int(res.passes.max()) + 1):
        idx = np.flatnonzero((res.passes == k) & (res.status != STATUS_FAILED))
        paths.append((res["tip"][idx], res["axis"][idx]))
        P, Q = res["P"][idx], res["Q"][idx]
        qx = np.where(np.isfinite(Q[:, 0]), Q[:, 0], P[:, 0])
        order = np.argsort(res["tip"][idx, 1])
        bands.append((res["tip"][idx, 1][order], np.minimum(P[:, 0], qx)[order], np.maximum(P[:, 0], qx)[order]))
    worst, lowest = [], math.inf
    for y in ys:
        lo, hi = np.interp(y, bands[0][0], bands[0][1]), np.interp(y, bands[-1][0], bands[-1][2])
        xs = np.arange(lo, hi, spacing)
        needles = np.column_stack([xs, np.full_like(xs, y)])
        sim = simulate(tool, needles, 200.0, paths, 0.25, "slerp", 2e-3)
        dev = sim.z - design(net, xs, np.full_like(xs, y))
        worst.append(float(dev.max()))
        lowest = min(lowest, float(dev.min()))
    return worst, lowest


def test_placed_passes_leave_the_scallop_by_an_independent_simulation(placed, convex_net):
    result, params = placed
    rep, res = result.diagnostics["scallop"], result.diagnostics["results"]
    h = params.scallop
    box = params.boundary
    assert rep.offsets[0] == pytest.approx(box[0]) and rep.offsets[-1] == pytest.approx(box[2])
    assert len(rep.offsets) == res.passes.max() + 1 >= 3
    assert all(0 < v <= h for v in rep.scallops[1:]), rep.scallops
    assert not rep.unreached
    # the independent z-map: every pass's positions, needle lines across the box at y the placement's rows
    # (every 4 mm from the passes' ends) do not use
    worst, lowest = row_deviations(result, params, convex_net, (47.3, 62.9), 0.02)
    # within the tolerance (2 % for the needles' spacing and the rows the placement read), and not far
    # below it: each pass was placed at the largest step the tolerance allows
    assert max(worst) <= 1.02 * h, worst
    assert max(worst) >= 0.8 * h, worst
    assert lowest >= -0.01, lowest  # no gouge


def test_the_scallop_holds_between_the_rows_and_to_the_pass_ends(convex_net):
    """A coarse forward step (6 mm) on passes from the face's edge: the placement reads its rows of needles
    4 mm apart and at the ends; the independent z-map reads the strips every 0.5 mm along the passes, to
    END_INSET inside their ends (where the torus's round front alone cuts and the scallop rises), within the
    scallop asked + 2 % (the z-map's needles 0.05 mm apart and its own sub-steps)."""
    h, box = 0.5, (30.0, 0.0, 85.0, 30.0)
    params = MultipointParams(pass_spacing="scallop", scallop=h, side_step=18.0, forward_step=6.0, boundary=box,
                              between_tol=0.0)
    result = multipoint.compute(BezierFace.from_net(convex_net), TORUS, params)
    ys = np.arange(box[1] + END_INSET, box[3] - END_INSET + 1e-9, 0.5)
    worst, _ = row_deviations(result, params, convex_net, ys, 0.05)
    over = {float(y): round(v, 4) for y, v in zip(ys, worst) if v > 1.02 * h}
    assert not over, over

def test_fewer_passes_than_the_fixed_step_of_the_same_largest_scallop(placed):
    """The fixed step that keeps every strip within the tolerance is the placement's smallest step: a fixed
    footprint at it needs at least as many passes."""
    result, params = placed
    rep = result.diagnostics["scallop"]
    steps = rep.steps[:-1] or rep.steps  # the last strip is what remains to the far edge
    fixed_passes = math.ceil((params.boundary[2] - params.boundary[0]) / min(steps) - 1e-9) + 1
    assert len(rep.offsets) <= fixed_passes
    assert max(steps) > min(steps)  # the step follows the surface, not a constant


def test_scallop_zigzag_and_segments(placed):
    result, _ = placed
    res = result.diagnostics["results"]
    ys = [res.xy[res.passes == k][:, 1] for k in range(int(res.passes.max()) + 1)]
    assert ys[0][0] < ys[0][-1] and ys[1][0] > ys[1][-1]  # alternate directions
    assert sum(len(s.tips) for s in result.segments) == int((res.status != STATUS_FAILED).sum())


@pytest.mark.parametrize("scallop, words", [(0.0, "scallop height"), (-1.0, "scallop height"),
                                            (6.0, "corner radius 6 mm"), (math.nan, "scallop height")])
def test_bad_scallop_is_refused_by_name(convex_net, scallop, words):
    face = BezierFace.from_net(convex_net)
    with pytest.raises(TmmError, match=words):
        multipoint.compute(face, TORUS, MultipointParams(pass_spacing="scallop", scallop=scallop, boundary=BOX))


def test_footprint_alone_refuses_the_scallop_spacing(convex_net):
    with pytest.raises(TmmError, match="use compute"):
        multipoint.multipoint_footprint(BezierFace.from_net(convex_net), MultipointParams(pass_spacing="scallop"))


def test_tiny_scallop_is_refused_before_any_position(convex_net):
    face = BezierFace.from_net(convex_net)
    passes = estimate_passes(150.0, 6.0, 1e-6)
    assert passes > 1000
    old = limits.current()
    try:
        limits.set_limits(max_positions=100_000)
        with pytest.raises(TmmError, match="scallop 1e-06 mm"):
            multipoint.compute(face, TORUS, MultipointParams(pass_spacing="scallop", scallop=1e-6))
    finally:
        limits.set_limits(max_positions=old.max_positions)


def test_cancel_stops_the_placement(convex_net):
    from tmm_workbench.core.errors import Cancelled

    face = BezierFace.from_net(convex_net)
    calls = []

    def progress(fraction: float) -> bool:
        calls.append(fraction)
        return len(calls) < 2  # cancel at the second question (a placed pass, or a poll of the meter)

    with pytest.raises(Cancelled):
        multipoint.compute(face, TORUS, MultipointParams(pass_spacing="scallop", scallop=0.3, boundary=BOX,
                                                         forward_step=4.0), progress)
    assert len(calls) == 2 and 0 <= calls[0] <= calls[1] < 1   # polls repeat the fraction so far


def test_passes_along_x_mirror_the_passes_along_y(convex_net):
    """The seed's convex net is symmetric in x and y: feeding along X over the mirrored box places the passes
    where feeding along Y does (the frame turns, or mirrors, the tool with the passes)."""
    box = (30.0, 40.0, 60.0, 70.0)
    face = BezierFace.from_net(convex_net)
    along_y = MultipointParams(pass_spacing="scallop", scallop=0.3, side_step=10.0, forward_step=2.0, boundary=box,
                               between_tol=0.0)
    result = multipoint.compute(face, TORUS, along_y)
    mirrored = MultipointParams(pass_spacing="scallop", scallop=0.3, side_step=10.0, forward_step=2.0,
                                boundary=(box[1], box[0], box[3], box[2]), between_tol=0.0, feed_angle_deg=0.0)
    other = multipoint.compute(face, TORUS, mirrored)
    a, b = result.diagnostics["scallop"], other.diagnostics["scallop"]
    np.testing.assert_allclose(b.offsets, a.offsets, atol=0.05)
    res = other.diagnostics["results"]
    first = res.xy[res.passes == 0]
    assert np.allclose(first[:, 1], box[0]) and first[-1, 0] > first[0, 0]  # along X at y = box's xmin
