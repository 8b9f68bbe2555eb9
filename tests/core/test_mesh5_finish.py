"""The 5-axis mesh finishing strategy (core.strategies.mesh5.finish): the adaptive plan's postures as cut
segments, linked by the one linker along the tool axis; what no pass finishes reported; bad input named."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import link
from tmm_workbench.core.strategies.mesh5 import finish
from tmm_workbench.core.strategies.mesh5.estimate import surface_sample
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params
from tmm_workbench.core.strategies.mesh5.tool_moves import OVERRUN_STEPS
from tmm_workbench.core.strategies.multipoint import link_policy
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter

TOL, SAFE, CLEAR, RETRACT = 0.05, 70.0, 80.0, 5.0
PARAMS = dict(tolerance=TOL, tilt_max_deg=24.0, yaw_limit_deg=30.0, forward_step=3.0)


def _cylinder():
    """A convex cylinder patch (radius 60 mm, axis along the feed +X)."""
    return grid_mesh(lambda x, y: np.sqrt(60.0 ** 2 - y * y), 8, 48, (-12, -12, 12, 12), "cylinder")


@pytest.fixture(scope="module")
def linked():
    """The convex cylinder patch finished with a flat D 10."""
    mesh = _cylinder()
    cutter = Cutter.flat(10.0)
    result = finish.compute(mesh, cutter, Mesh5Params(**PARAMS))
    return result, link(result.segments, link_policy(cutter, SAFE, CLEAR, RETRACT)), cutter


def test_the_cuts_are_the_plans_postures_in_pass_order_zig_zag(linked):
    result, path, _ = linked
    plan = result.diagnostics["plan"]
    assert result.diagnostics["passes"] == len(plan.passes) >= 2
    expect_tips, expect_axes = [], []
    for k, p in enumerate(plan.passes):
        tips = np.vstack([t for t, _ in p.tool_positions()])
        axes = np.vstack([a for _, a in p.tool_positions()])
        expect_tips.append(tips[::-1] if k % 2 else tips)
        expect_axes.append(axes[::-1] if k % 2 else axes)
    got = np.array([(m.x, m.y, m.z) for m in path.moves if m.kind is not MoveKind.RAPID])
    # every CC point's CL point and the overruns beyond the ends are reached, in order (the first of each
    # segment by the entry along the axis)
    cut = np.vstack(expect_tips)
    i = 0
    for p in got:
        if i < len(cut) and np.allclose(p, cut[i], atol=1e-9):
            i += 1
    assert i == len(cut)
    cc = sum(len(q.tips) for p in plan.passes for q in p.postures)
    assert result.diagnostics["cc_points"] == cc and len(cut) == cc + 2 * OVERRUN_STEPS * len(result.segments)
    assert all(np.linalg.norm(np.array(m.axis)) == pytest.approx(1.0) for m in path.moves)
    # the tool is tilted (a flat end mill upright would gouge the convex cylinder's sides)
    assert max(np.degrees(np.arccos(np.vstack(expect_axes)[:, 2]))) > 1.0


def test_each_pass_is_entered_and_left_along_its_tool_axis_and_crossed_above_the_safe_height(linked):
    result, path, cutter = linked
    moves = path.moves
    tips = [s.tips for s in result.segments]
    axes = [s.axes for s in result.segments]
    starts = [k for k, m in enumerate(moves) if m.kind is MoveKind.PLUNGE
              and any(np.allclose((m.x, m.y, m.z), t[0]) for t in tips)]
    assert len(starts) == len(result.segments)
    for k, (t, a) in zip(starts, zip(tips, axes)):
        above = moves[k - 1]
        assert np.allclose((above.x, above.y, above.z), t[0] + RETRACT * a[0], atol=1e-9)
        assert np.allclose(above.axis, a[0], atol=1e-12) and np.allclose(moves[k].axis, a[0], atol=1e-12)
    # across between passes: at the transit height (the tilted tool's lowest point at the safe height)
    for m0, m1 in zip(moves, moves[1:]):
        if m1.kind is MoveKind.RAPID and np.hypot(m1.x - m0.x, m1.y - m0.y) > 1e-9:
            for m in (m0, m1):
                assert m.z - cutter.lowest_below_tip(m.axis) >= SAFE - 1e-9
    assert moves[0].z == pytest.approx(CLEAR) and moves[-1].z == pytest.approx(CLEAR)
    assert moves[0].axis == moves[-1].axis == (0.0, 0.0, 1.0)


def test_a_groove_no_pass_finishes_is_reported_with_its_cc_points():
    # a V groove 2 mm wide and 1 mm deep along the feed: no posture of a flat D 10 finishes it
    mesh = grid_mesh(lambda x, y: -np.clip(1.0 - np.abs(y), 0, None), 10, 120, (-10, -15, 10, 15), "groove")
    result = finish.compute(mesh, Cutter.flat(10.0), Mesh5Params(tolerance=TOL, tilt_max_deg=12.0,
                                                                 yaw_limit_deg=12.0, forward_step=4.0))
    d = result.diagnostics
    assert d["unfinished"] and len(d["empty_points"]) > 0
    across = d["empty_points"][:, 1]
    assert any(a0 - 1e-9 <= y <= a1 + 1e-9 for y in across for _, _, a0, a1 in d["unfinished"])
    assert abs(across).min() < 3.0          # the groove's bottom lies in what is reported
    text = finish.report(d)
    assert f"{len(d['empty_points'])} CC points with an empty C-space" in text and "clean-up" in text


@pytest.mark.parametrize("cutter, match", [
    (Cutter.ball(10.0), "ball.*not taken by 5-axis mesh finishing"),
    (Cutter.vbit(10.0, 90.0), "not taken by 5-axis mesh finishing"),
])
def test_a_tool_the_method_does_not_take_is_refused_by_name(cutter, match):
    plane = grid_mesh(lambda x, y: 0.0 * x, 4, 4, (0, 0, 10, 10), "plane")
    with pytest.raises(TmmError, match=match):
        finish.compute(plane, cutter, Mesh5Params())


@pytest.mark.parametrize("values, match", [
    (dict(tolerance=0.0), r"tolerance must be in \(0, 10\] mm, got 0"),
    (dict(tolerance=-0.1), r"tolerance must be .*got -0.1"),
    (dict(tilt_max_deg=60.0), "tilt limit 60 deg is outside the machine's tilt range C 0..45 deg"),
    (dict(tilt_min_deg=10.0, tilt_max_deg=5.0), "least tilt 10 deg must not be above the tilt limit 5 deg"),
])
def test_bad_values_are_refused_naming_the_value(values, match):
    plane = grid_mesh(lambda x, y: 0.0 * x, 4, 4, (0, 0, 10, 10), "plane")
    with pytest.raises(TmmError, match=match):
        finish.compute(plane, Cutter.flat(6.0), Mesh5Params(**values))


def test_work_is_estimated_from_the_box_alone():
    params = Mesh5Params(**PARAMS)
    work = finish.estimate_work(params, Cutter.flat(10.0), (-12, -12, 0, 12, 12, 60))
    assert work.what == "CC points" and work.passes == 11 and work.count == pytest.approx(11 * (24 / 3 + 2))
    with pytest.raises(TmmError, match="CC points"):
        finish.estimate_work(Mesh5Params(forward_step=0.01), Cutter.flat(1.0), (0, 0, 0, 1e5, 1e5, 1))
    # with the shank and holder every C-space costs more: the same CC points at a dearer pace
    from tmm_workbench.core.tools.assembly import ToolAssembly

    held = Mesh5Params(**PARAMS)
    held.assembly = ToolAssembly(Cutter.flat(10.0), 10.0, 32.0, flute_length=30.0, holder="ER16 nut")
    more = finish.estimate_work(held, Cutter.flat(10.0), (-12, -12, 0, 12, 12, 60))
    assert more.count == work.count and dict(more.paces)["mesh5"] == finish.HOLDER_COST * dict(work.paces)["mesh5"]
    assert "shank and holder" in more.note


def _told(mesh, cutter, **values):
    """The estimate's passes from the model's needle sample (mesh5.estimate.surface_sample)."""
    lo, hi = mesh.bounds
    return finish.estimate_work(Mesh5Params(**PARAMS), cutter, (*lo, *hi), surface_sample(mesh), **values)


def test_the_passes_are_told_from_the_tilted_cutters_width_over_the_models_curvature(linked):
    # the convex cylinder (the module's) and one concave across the feed: within 1.5x of the plan's passes,
    # where the box alone tells passes a quarter diameter apart (the upper bound the limits refuse on)
    result, _, cutter = linked
    planned = result.diagnostics["passes"]
    assert planned / 1.5 <= _told(_cylinder(), cutter).passes <= planned * 1.5
    valley = grid_mesh(lambda x, y: 80.0 - np.sqrt(80.0 ** 2 - y * y), 8, 48, (-12, -20, 12, 20), "valley")
    told = _told(valley, cutter).passes
    planned = finish.compute(valley, cutter, Mesh5Params(**PARAMS)).diagnostics["passes"]
    assert planned / 1.5 <= told <= planned * 1.5
    box = finish.estimate_work(Mesh5Params(**PARAMS), cutter, (*valley.bounds[0], *valley.bounds[1]))
    assert box.passes > told and "at most" in box.note


def test_the_estimate_counts_the_simulation_of_what_is_left_and_still_refuses_before_allocating():
    mesh = grid_mesh(lambda x, y: 0.01 * x * x, 6, 6, (0, 0, 50, 50), "bowl")
    plain, checked = _told(mesh, Cutter.flat(10.0)), _told(mesh, Cutter.flat(10.0), left_cell=0.25)
    assert checked.count == plain.count and dict(checked.paces)["mesh5_left_cells"] == pytest.approx(52 * 52 / 0.0625)
    assert dict(checked.paces)["mesh5_left_cut"] > 0 and "simulated on 0.25 mm cells" in checked.note
    # the limits refuse on the box's upper bound, before any sample or C-space counts
    with pytest.raises(TmmError, match="CC points"):
        finish.estimate_work(Mesh5Params(forward_step=0.01), Cutter.flat(1.0), (0, 0, 0, 1e5, 1e5, 1),
                             surface_sample(mesh), left_cell=0.25)


def test_progress_is_told_and_a_cancel_stops_the_passes():
    from tmm_workbench.core.errors import Cancelled

    mesh = grid_mesh(lambda x, y: np.sqrt(60.0 ** 2 - y * y), 8, 48, (-12, -12, 12, 12), "cylinder")
    told = []
    result = finish.compute(mesh, Cutter.flat(10.0), Mesh5Params(**PARAMS), lambda f: told.append(f) or True)
    assert told and told == sorted(told) and result.diagnostics["passes"] >= 4   # every pass, not the first only
    with pytest.raises(Cancelled):
        finish.compute(mesh, Cutter.flat(10.0), Mesh5Params(**PARAMS), lambda f: False)
