"""The step-over's step control replayed on known widths (core.strategies.mesh5.step_replay): on uniform widths
the planes a gap apart by the rule, and on a cylinder patch the step-over's own plane offsets reproduced from the
widths its passes finished."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.strategies.mesh5 import finish
from tmm_workbench.core.strategies.mesh5.cc_paths import plane_normal
from tmm_workbench.core.strategies.mesh5.coverage import Coverage
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.step_replay import WidthField, replay_planes
from tmm_workbench.core.strategies.mesh5.stepover import MARGIN, SHRINK, half_widths
from tmm_workbench.core.tools.cutter import Cutter


def test_uniform_widths_place_the_planes_two_half_widths_apart() -> None:
    # half-width 1.5 mm everywhere on 0..20 mm, radius 4: the first plane 1 mm in (0.125 D), finishing 0..2.5
    # (its right side ends at the edge); the next half that width beyond 2.5 (half the GAP_QUANTILE of the
    # widths), finishing to 5.25; then a half-width beyond (half of the 3 mm widths), but the C-space asks its
    # right side a little further back (1.01x): no posture, so rebuilt SHRINK x the gap nearer, and so on: 1,
    # 3.75, 6.45, ..., the last the first whose far side reaches 20
    field = WidthField.symmetric(0.5, 1.0, np.full((20, 7), 1.5))
    lo, hi = field.extent()
    assert np.allclose(lo, 0.0) and np.allclose(hi, 20.0)
    planes = replay_planes(field, lo, hi, 4.0, 2.0, 2.0)
    assert planes[0] == pytest.approx(1.0)
    assert planes[1] == pytest.approx(3.75)
    assert np.allclose(np.diff(planes[1:-1]), 1.5 * (1 + SHRINK))
    assert planes[-1] + 1.5 >= 20.0 - 1e-3 > planes[-2] + 1.5


def test_a_narrow_place_holds_the_planes_back_where_it_runs() -> None:
    # one bin along the feed narrower (half-width 0.6 mm) across its middle rows: the planes crossing it come
    # closer (the least finished level and the right side reaching back to it), the others stay 3 mm apart
    half = np.full((20, 7), 1.5)
    half[8:12, 3] = 0.6
    narrow = replay_planes(WidthField.symmetric(0.5, 1.0, half), *WidthField.symmetric(0.5, 1.0, half).extent(),
                           4.0, 2.0, 2.0)
    wide = replay_planes(WidthField.symmetric(0.5, 1.0, np.full((20, 7), 1.5)),
                         np.zeros(7), np.full(7, 20.0), 4.0, 2.0, 2.0)
    assert len(narrow) > len(wide)
    steps = np.diff(narrow)
    assert steps.min() < 0.8 * np.diff(wide).min()


def test_bad_input_is_named() -> None:
    with pytest.raises(ValueError, match="radius"):
        replay_planes(lambda o: (np.ones(2), np.ones(2)), np.zeros(2), np.ones(2), 0.0, 1.0, 1.0)


def _finished(mesh, cutter, params, plan):
    """Per pass, its offset and what it finished per bin of the step-over's own Coverage: (offset, left (nb,),
    right (nb,)) along the plane normal, measured as the step-over measures them (half_widths at its postures),
    the least of the pass's CC points in each bin, NaN where it does not run."""
    m = plane_normal(params.direction())
    cover = Coverage(mesh, m, np.array([m[1], -m[0], 0.0]), params.forward_step, 1e-3 * cutter.radius, plan.overrun)
    reach, out = MeshReach(mesh), []
    for p in plan.passes:
        pts = np.concatenate([q.points for q in p.paths])
        frm = np.concatenate([q.frames for q in p.paths])
        cat = lambda name: np.concatenate([getattr(q, name) for q in p.postures])  # noqa: E731
        _, ends = half_widths(reach, cutter, pts, frm, cat("lam"), cat("omg"), cat("delta"),
                              MARGIN * params.tolerance)
        left = np.where(np.isnan(ends[:, 0, 0]), np.inf, ends[:, 0] @ m - p.offset)
        right = np.where(np.isnan(ends[:, 1, 0]), np.inf, p.offset - ends[:, 1] @ m)
        b = cover.bin(pts @ cover.feed)
        lb, rb = np.full(len(cover.lo), np.inf), np.full(len(cover.lo), np.inf)
        np.minimum.at(lb, b, left)
        np.minimum.at(rb, b, right)
        seen = np.isin(np.arange(len(lb)), b)
        out.append((p.offset, np.where(seen, lb, np.nan), np.where(seen, rb, np.nan)))
    return cover, out


@pytest.mark.parametrize("valley", [False, True])
def test_the_step_overs_planes_are_replayed_from_the_widths_its_passes_finished(valley: bool) -> None:
    # the convex and concave cylinder patches of test_mesh5_finish (flat D 10, 0.05 mm): the step-over's plan,
    # then the replay told what each of its passes finished (the pass nearest the offset asked)
    if valley:
        mesh = grid_mesh(lambda x, y: 80.0 - np.sqrt(80.0 ** 2 - y * y), 8, 48, (-12, -20, 12, 20), "valley")
    else:
        mesh = grid_mesh(lambda x, y: np.sqrt(60.0 ** 2 - y * y), 8, 48, (-12, -12, 12, 12), "cylinder")
    cutter = Cutter.flat(10.0)
    params = Mesh5Params(tolerance=0.05, tilt_max_deg=24.0, yaw_limit_deg=30.0, forward_step=3.0)
    plan = finish.compute(mesh, cutter, params).diagnostics["plan"]
    cover, passes = _finished(mesh, cutter, params, plan)
    offsets = np.array([o for o, _, _ in passes])

    def reach(offset: float):
        _, left, right = passes[int(np.argmin(np.abs(offsets - offset)))]
        return left, right

    replayed = replay_planes(reach, cover.lo, cover.hi, cutter.radius, params.forward_step, params.forward_step,
                             widest=False)
    assert len(plan.passes) >= 4, plan.report()
    assert len(replayed) == len(offsets), (replayed, offsets)
    assert np.allclose(replayed, offsets, atol=1e-3 * cutter.radius), (replayed, offsets)


def test_points_binned_into_a_width_field() -> None:
    # points on rows 1 mm apart across and columns 2 mm apart along the feed, the least in each cell; a point
    # with no width known takes the nearest known across in its column; off the points: no model
    m, f = np.meshgrid(np.arange(5.0), np.arange(0.0, 8.0, 2.0), indexing="ij")
    half = np.full(m.shape, 2.0)
    half[1:3, 1] = np.nan
    half[3, 1] = 0.5
    field = WidthField.binned(m, f, half, 1.0, 2.0)
    assert field.left.shape == (5, 4)
    assert field.left[2, 1] == pytest.approx(0.5) and field.left[1, 1] == pytest.approx(2.0)
    lo, hi = field.extent()
    assert np.allclose(lo, -0.5) and np.allclose(hi, 4.5)
    left, right = field(2.5)
    assert left[1] == pytest.approx(0.5) and right[0] == pytest.approx(2.0)
    assert np.all(np.isnan(field(6.0)[0]))
