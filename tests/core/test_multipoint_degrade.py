"""5-axis multipoint degrades where the scallop cannot be held: it machines what it reaches and reports the
rest (core.strategies.multipoint_scallop LeftArea, diagnostics "unreached_positions") instead of failing.
Before: 'no side step leaves a scallop within 0.01 mm after the pass at 0 mm from the start edge ... the
tool does not reach the face there' on seed 001's saddle (a strip along its start edge) and on random nets;
no NaN reaches the tool path."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SEED_JSON, random_net
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.strategies import multipoint
from tmm_workbench.core.strategies.multipoint import STATUS_FAILED, MultipointParams
from tmm_workbench.core.strategies.multipoint_scallop import (MAX_TRIALS, NOT_REACHED, OVER_SCALLOP, LeftArea,
                                                               estimate_passes)
from tmm_workbench.core.tools.cutter import Cutter
from tests.core.zmap_reference import ZTool, simulate

TORUS = Cutter.torus(6.7, 6.0)


# (net, boundary): strips along an edge where rows stay above 0.01 mm at any side step
CASES = {"saddle": (lambda: bezier.load_seed_patch(SEED_JSON, "saddle"), (0.0, 100.0, 6.0, 150.0)),
         "random 1": (lambda: random_net(1), (0.0, 0.0, 6.0, 60.0))}


@pytest.fixture(scope="module", params=sorted(CASES))
def degraded(request):
    make, box = CASES[request.param]
    face = BezierFace.from_net(make())
    params = MultipointParams(pass_spacing="scallop", scallop=0.01, side_step=18.0, forward_step=2.0,
                              boundary=box, between_tol=0.0)
    return request.param, box, multipoint.compute(face, TORUS, params)


def test_the_op_machines_what_it_reaches_and_reports_the_rest(degraded):
    name, box, result = degraded
    rep = result.diagnostics["scallop"]
    assert rep.offsets[0] == pytest.approx(box[0]) and rep.offsets[-1] == pytest.approx(box[2])  # covered
    assert result.segments and all(len(s.tips) for s in result.segments)
    assert rep.unreached, name  # the strips it could not hold are reported ...
    for area in rep.unreached:
        assert isinstance(area, LeftArea) and area.height > 0.01 and area.rows >= 1
        assert area.outline.shape == (4, 2) and np.isfinite(area.outline).all()
        x0, y0 = area.outline.min(0)
        x1, y1 = area.outline.max(0)
        assert box[0] - 1e-6 <= x0 <= area.at[0] <= x1 <= box[2] + 1e-6  # ... where they are
        assert y0 <= area.at[1] <= y1
        assert "mm above the face" in area.describe()
    if name == "saddle":  # the rows along its edge no step removes
        assert any(a.reason == NOT_REACHED for a in rep.unreached)
    # the strips the rule could hold keep the tolerance
    held = [v for v, a in zip(rep.scallops[1:], rep.offsets[1:]) if v <= 0.01]
    assert held and all(math.isfinite(v) for v in held)


def test_no_nan_in_the_tool_path(degraded):
    _, _, result = degraded
    for seg in result.segments:
        assert np.isfinite(seg.tips).all() and np.isfinite(seg.axes).all()
        assert np.allclose(np.linalg.norm(seg.axes, axis=1), 1.0)
    res = result.diagnostics["results"]
    failed = res.status == STATUS_FAILED
    assert np.array_equal(result.diagnostics["unreached_positions"], res.xy[failed])


def test_a_position_the_kernel_gives_as_nan_is_not_cut(monkeypatch):
    """A non-finite tip or axis from the kernel is marked failed with its reason, never cut."""
    face = BezierFace.from_net(bezier.load_seed_patch(SEED_JSON, "convex"))
    mp = multipoint.make_positioner(face, 6.7, 6.0, MultipointParams())

    class Poisoned:
        def position_batch(self, pts, threads, progress):
            data = mp.position_batch(pts, threads, progress)
            data["tip"][1] = np.nan
            data["axis"][2] = (0.0, 0.0, 0.0)
            return data

    res = multipoint._position(Poisoned(), np.array([[70.0, 70.0], [72.0, 70.0], [74.0, 70.0]]),
                               MultipointParams())
    assert list(res.status[1:]) == [STATUS_FAILED, STATUS_FAILED] and res.status[0] != STATUS_FAILED
    assert res.reason_texts()[1] == multipoint.NOT_FINITE


# A 12 mm net (random 2 scaled by 12/150, z 5.6-8 mm) under a small torus: the tilted tool touches the face
# millimetres before and behind the row it cuts, so the strips between passes were read between the wrong
# contacts; the placement fell back to the estimate's step (OVER_SCALLOP strips) and reported rows the tool
# reaches. Now every strip holds the scallop and only what dense passes cannot remove either is reported.
SMALL_TORUS = Cutter.torus(2.0, 1.0)
SMALL_H = 0.01


@pytest.fixture(scope="module")
def small_net():
    net = random_net(2) * (12.0 / 150.0)
    face = BezierFace.from_net(net)
    params = MultipointParams(pass_spacing="scallop", scallop=SMALL_H, side_step=1.0, forward_step=0.5,
                              between_tol=0.0)
    return face, params, multipoint.compute(face, SMALL_TORUS, params)


def test_small_net_holds_the_scallop_on_every_strip(small_net):
    _, _, result = small_net
    rep = result.diagnostics["scallop"]
    assert rep.offsets[0] == pytest.approx(0.0) and rep.offsets[-1] == pytest.approx(12.0)
    assert all(b > a for a, b in zip(rep.offsets, rep.offsets[1:]))
    assert not [a for a in rep.unreached if a.reason == OVER_SCALLOP]  # no strip at the estimate's step
    assert all(0.0 <= v <= SMALL_H for v in rep.scallops), rep.scallops
    assert rep.trials <= estimate_passes(12.0, 1.0, SMALL_H) * MAX_TRIALS  # within the work estimate's


def test_small_net_reports_only_what_dense_passes_leave_too(small_net):
    """Each area reported: passes every 0.05 mm (the kernel's positions, cut by the independent Python
    z-map) still leave more than the scallop there, so no side step of this tool could hold it."""
    face, params, result = small_net
    rep = result.diagnostics["scallop"]
    across = np.arange(0.0, 12.0 + 1e-9, 0.05)
    along = np.arange(0.0, 12.0 + 1e-9, params.forward_step)
    xy = np.array([(x, y) for x in across for y in along])
    res = multipoint.position_points(face, 2.0, 1.0, xy, params)
    tool = ZTool(2.0, 1.0, params.shape)
    for area in rep.unreached:
        (x0, y0), (x1, y1) = area.outline.min(0), area.outline.max(0)
        near = np.abs(xy[:, 0] - 0.5 * (x0 + x1)) <= 0.5 * (x1 - x0) + 3.0 + 1e-9  # within the tool's reach
        paths = []
        for x in np.unique(xy[near, 0]):
            idx = np.flatnonzero((xy[:, 0] == x) & (res.status != STATUS_FAILED))
            paths.append((res["tip"][idx], res["axis"][idx]))
        worst = 0.0
        for y in np.arange(math.ceil(y0), y1 + 1e-9, 1.0):
            xs = np.arange(x0, x1 + 1e-9, 0.02)
            sim = simulate(tool, np.column_stack([xs, np.full_like(xs, y)]), 50.0, paths, 0.25, "slerp", 2e-3)
            design = face.evaluate(np.column_stack([xs / 12.0, np.full_like(xs, y / 12.0)]))["S"][:, 2]
            worst = max(worst, float(np.nanmax(sim.z - design)))
        assert worst > SMALL_H, area.describe()
