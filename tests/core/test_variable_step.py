"""Variable side step (core.strategies.surface.variable_step, issue 14 item 4): the raster's pass set cut into the stock
simulation, extra partial passes where its cusp exceeds the tolerance. Checked independently: the final path
and a dense raster cut again into a grid of finer cells than the verification used (core.sim.cusp_field's
measure), the design compared with the simulated stock for gouges, the extra passes counted and located."""
from __future__ import annotations

import numpy as np
import pytest

from benchmarks.seed000_surfaces import INCH, seed000_mesh
from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.strategies.surface.variable_step import VerifyReport, measure_cell
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.segments import SegmentKind
from tmm_workbench.core.strategies.surface.reference import cusp_field
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute
from tmm_workbench.core.tools.cutter import Cutter

BALL = Cutter.ball(6)
TOL = 0.01


def _verify_reports(notes: list) -> list:
    """The VerifyReports among the notes (the cusp check's report of the final measurement follows each)."""
    return [n for n in notes if isinstance(n, VerifyReport)]


def _path(mesh, result):
    top = float(mesh.bounds[1][2])
    return link(result.segments, LinkPolicy(top + 6, top + 10))


_FIELDS: dict = {}


def _field(mesh, cutter, boundary, tol, cell):
    """The independent measure's field (a dense raster on a grid of `cell` mm, from scratch): it depends on these
    only, not on the path measured (CuspField.cut starts from a fresh stock), so a test's two paths share it."""
    key = (id(mesh), cutter, tuple(boundary), tol, cell)
    if key not in _FIELDS:
        _FIELDS.clear()  # one test's meshes at a time
        _FIELDS[key] = (mesh, cusp_field(mesh, cutter, boundary, tol, cell, sample_step=cell))
    return _FIELDS[key][1]


def _independent(mesh, cutter, boundary, tol, path, cell):
    """(max cusp, deepest cut below the design) of `path` on a grid of `cell` mm, from scratch."""
    field = _field(mesh, cutter, boundary, tol, cell)
    heights = field.cut(path, cutter)
    on = np.isfinite(field.design)
    return field.max_cusp(heights), float(np.max(field.design[on] - heights[on]))


def _passes(result):
    return [s for s in result.segments if s.kind is SegmentKind.PASS]


def test_constant_cusp_mode_on_seed000_concave_window_is_brought_within_the_tolerance():
    mesh, _ = seed000_mesh("concave", nt=201, ns=21)  # a coarse mesh: the surface itself is not the point
    lo, hi = mesh.bounds
    c = 0.5 * (lo + hi)
    box = (float(c[0] - 20), float(c[1] - 20), float(c[0] + 20), float(c[1] + 20))
    ball, tol = Cutter.ball(0.5 * INCH), 0.002 * INCH
    # the planar rule on the level plane: it ignores this window's slope and curvature (with the mesh wound upside
    # down, steepest_crossing_deg read 0 deg here and constant cusp mode used exactly this step)
    planar = stepover_for_cusp(ball, tol, 0.0)
    plain = compute(mesh, ball, SurfaceParams(boundary=box, stepover=planar, cusp=tol, sample_step=0.25))
    notes: list = []
    checked = compute(mesh, ball, SurfaceParams(boundary=box, stepover=planar, cusp=tol, sample_step=0.25,
                                                verify_cusp=True, verify_notes=notes))
    cell = 0.5 * measure_cell(ball, tol)  # finer than the verification's own cells
    before, _ = _independent(mesh, ball, box, tol, _path(mesh, plain), cell)
    after, deepest = _independent(mesh, ball, box, tol, _path(mesh, checked), cell)
    assert before > tol                                   # the planar rule undershoots this surface
    assert after <= tol
    assert deepest < 0.005                                # no gouge (the raster's own gouge tolerance)
    (report,) = _verify_reports(notes)
    assert report.within and report.max_cusp_after <= tol and report.unreachable == 0
    n_plain, n_extra = len(_passes(plain)), len(_passes(checked)) - len(_passes(plain))
    assert n_extra == report.passes_added > 0
    assert n_extra < n_plain                              # at most one extra pass per gap here (cusp ~ 1.03 tol)
    assert checked.diagnostics["verify"]["passes_added"] == n_extra
    # the pass set itself is unchanged: the extra passes come after it
    for a, b in zip(plain.segments, checked.segments):
        assert np.array_equal(a.tips, b.tips)


def _bump():
    """A 4 mm bump on a plate (slopes to 39 deg) under a 24 x 16 mm box."""
    return grid_mesh(lambda x, y: 4.0 * np.exp(-((x - 12) ** 2 + (y - 8) ** 2) / 18.0), 96, 64, (-6, -6, 30, 22),
                     "bump")


def test_extra_passes_go_only_where_the_cusp_exceeds():
    """A step-over that keeps the cusp on the plate but not on the bump's slopes: extra passes over the bump
    only, partial (shorter than the box), and the whole box within the tolerance afterwards."""
    mesh, box = _bump(), (0.0, 0.0, 24.0, 16.0)
    step = stepover_for_cusp(BALL, 0.8 * TOL, 0.0)
    params = dict(boundary=box, stepover=step, sample_step=0.25)
    plain = compute(mesh, BALL, SurfaceParams(**params))
    notes: list = []
    checked = compute(mesh, BALL, SurfaceParams(**params, verify_cusp=True, verify_notes=notes))
    cell = 0.6 * measure_cell(BALL, TOL)  # finer than the verification's own cells
    before, _ = _independent(mesh, BALL, box, TOL, _path(mesh, plain), cell)
    after, deepest = _independent(mesh, BALL, box, TOL, _path(mesh, checked), cell)
    assert before > 1.2 * TOL and after <= TOL and deepest < 0.005
    extra = _passes(checked)[len(_passes(plain)):]
    (report,) = _verify_reports(notes)
    assert len(extra) == report.passes_added
    assert len(extra) > 0
    tips = np.vstack([s.tips for s in extra])
    # only over the bump's slopes steeper than 23 deg (within 6.2 mm of its top: 0.8 / cos^2 of the tolerance and
    # more), the tips a radius downhill of their contacts, and a pass's run-on
    assert np.all(np.hypot(tips[:, 0] - 12, tips[:, 1] - 8) < 6.2 + BALL.radius + 1.0)
    assert all(np.ptp(s.tips[:, 0]) < 24.0 - 1.0 for s in extra)  # partial passes
    # a uniform step-over for the steepest slope would double the raster's length; a third of it is added
    assert report.length_added < 0.35 * len(_passes(plain)) * 24.0
    # consecutive partial passes are joined on the surface (dropped, gouge-checked links; `deepest` above covers
    # them) instead of lifting between them
    added = checked.segments[len(plain.segments):]
    assert report.links > 0 and sum(s.kind is SegmentKind.LINK for s in added) == report.links
    assert sum(not s.joined for s in added) == len(extra) - report.links


def test_3d_offset_on_a_relief_patch_is_brought_within_the_tolerance():
    """The 3D offset's loops on a 12 x 12 mm patch of mount_rush.stl (the relief whose concave detail the field's
    step misses: tests/core/test_offset3d.py) verified: extra passes are pieces of the arrival field's level sets
    half way between two loops, and the patch is within the tolerance afterwards, measured independently on finer
    cells with a dense raster sampled a cell apart."""
    from tmm_workbench.core.footprint.offset_field import arrival
    from tmm_workbench.core.footprint.region import box_region
    from tmm_workbench.core.geometry.mesh import load_stl
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.shared_data import shared_dir

    mesh = load_stl(shared_dir() / "benchmarks" / "stl" / "mount_rush.stl")
    box = (-8.0, 0.0, 4.0, 12.0)
    params = dict(boundary=box, sample_step=0.25, stepover_mode="offset3d", cusp=TOL, gouge_tol=5e-4)
    plain = compute(mesh, BALL, SurfaceParams(**params))
    notes: list = []
    checked = compute(mesh, BALL, SurfaceParams(**params, verify_cusp=True, verify_notes=notes))
    cell = 0.05
    before, _ = _independent(mesh, BALL, box, TOL, _path(mesh, plain), cell)
    assert before > 1.4 * TOL                         # measured 0.0161 mm
    fld = _field(mesh, BALL, box, TOL, cell)
    heights = fld.cut(_path(mesh, checked), BALL)
    cusp = fld.cusp(heights)
    # within the tolerance everywhere but beside the region out of the ball's reach, where the two measures'
    # dense rasters (0.05 and 0.061 mm apart) disagree on what it reaches: one cell at 0.01003 mm there, the
    # verification's grid 0.0089 mm with its neighbours unreachable
    from scipy.ndimage import binary_dilation
    beside = binary_dilation(fld.unreachable, iterations=2)
    assert np.nanmax(np.where(beside, np.nan, cusp)) <= TOL
    assert np.nanmax(cusp) <= 1.01 * TOL
    on = np.isfinite(fld.design)
    assert float(np.max(fld.design[on] - heights[on])) < 5e-4   # no gouge beyond the gouge tolerance asked
    (report,) = _verify_reports(notes)
    assert report.within and report.passes_added > 0
    # the loops are unchanged, the extra passes come after them
    assert all(np.array_equal(a.tips, b.tips) for a, b in zip(plain.segments, checked.segments))
    extra = _passes(checked)[len(_passes(plain)):]
    assert len(extra) == report.passes_added
    # each extra pass lies on a level set of the field strictly between two loops' levels: T at its tips is
    # nearly constant and not an integer (the same field as the strategy's: same region, drop and rule)
    surface, floor = DropSurface(mesh), float(mesh.bounds[0][2])
    field, _ = arrival(box_region(box), lambda xy: np.maximum(surface.drop(BALL, xy, floor), floor), BALL, TOL, 75.0)
    for seg in extra:
        t = field.at(seg.tips[:, :2])
        t = t[np.isfinite(t)]
        assert np.ptp(t) < 0.1
        assert 0.1 < np.median(t) % 1.0 < 0.9


def test_partial_passes_are_lean_with_the_tolerance_forward_step():
    """With ForwardStep Tolerance the verification's partial passes get the kernel's lean fit too: every move
    within +-chord_tol of the exact drop (sampled every 0.01 mm); sampled partial passes are not."""
    from tmm_workbench.core.query.drop import DropSurface

    mesh, box = _bump(), (0.0, 0.0, 24.0, 16.0)
    params = dict(boundary=box, stepover=stepover_for_cusp(BALL, 0.8 * TOL, 0.0), sample_step=0.25, chord_tol=0.001)
    surface, floor = DropSurface(mesh), float(mesh.bounds[0][2])

    def extra_deviation(forward_step: str) -> float:
        n = len(compute(mesh, BALL, SurfaceParams(**params, forward_step=forward_step)).segments)
        extra = compute(mesh, BALL, SurfaceParams(**params, forward_step=forward_step, verify_cusp=True)).segments[n:]
        assert len(extra) > 5
        worst = 0.0
        for seg in (s for s in extra if len(s.tips) >= 2):
            a, b = seg.tips[:-1], seg.tips[1:]
            k = np.maximum(np.ceil(np.hypot(*(b - a)[:, :2].T) / 0.01), 1).astype(int)
            t = np.concatenate([np.arange(m) / m for m in k])
            p = np.repeat(a, k, axis=0) + t[:, None] * np.repeat(b - a, k, axis=0)
            worst = max(worst, float(np.max(np.abs(p[:, 2] - np.maximum(surface.drop(BALL, p[:, :2], floor), floor)))))
        return worst

    assert extra_deviation("tolerance") <= 0.001 + 1e-6
    assert extra_deviation("sample") > 0.002


def test_a_path_within_the_tolerance_is_left_as_it_is():
    mesh, box = _bump(), (0.0, 0.0, 24.0, 16.0)
    params = dict(boundary=box, stepover=stepover_for_cusp(BALL, 0.5 * TOL, 45.0), sample_step=0.25)
    plain = compute(mesh, BALL, SurfaceParams(**params))
    notes: list = []
    checked = compute(mesh, BALL, SurfaceParams(**params, verify_cusp=True, verify_notes=notes))
    assert len(checked.segments) == len(plain.segments) and _verify_reports(notes)[0].passes_added == 0 \
        and _verify_reports(notes)[0].rounds == 0


def test_unreachable_cells_are_counted_not_chased():
    """A groove narrower than the ball: its bottom is out of reach, reported, and no pass is added for it."""
    def groove(x, y):
        return np.where(np.abs(y - 8) < 1.0, -2.0, 0.0)
    mesh, box = grid_mesh(groove, 48, 320, (-6, -6, 30, 22), "groove"), (0.0, 0.0, 24.0, 16.0)
    notes: list = []
    compute(mesh, BALL, SurfaceParams(boundary=box, stepover=stepover_for_cusp(BALL, 0.8 * TOL, 0.0),
                                      sample_step=0.25, verify_cusp=True, verify_notes=notes))
    (report,) = _verify_reports(notes)
    assert report.unreachable > 0 and report.within


@pytest.mark.parametrize("extra, words", [
    (dict(pattern="spiral"), "spiral"),
    (dict(stepover_mode="offset3d", cusp=0.01, pattern="spiral"), "spiral"),
    (dict(slope_min_deg=10.0), "slope range"),
    (dict(cusp=4.0), "cusp height"),
])
def test_bad_input_is_refused_with_the_parameter(extra, words):
    mesh = _bump()
    with pytest.raises(TmmError, match=words):
        compute(mesh, BALL, SurfaceParams(boundary=(0.0, 0.0, 24.0, 16.0), verify_cusp=True, **extra))


def test_the_work_is_estimated_before_the_simulation():
    from tmm_workbench.core import limits
    from tmm_workbench.core.errors import WorkLimitError

    previous = limits.set_limits(max_points=20000)
    try:
        # the raster itself is about 3,000 points; the verification's dense raster 0.06 mm apart 140,000
        with pytest.raises(WorkLimitError, match="verify cusp: cusp height 0.01 mm measured on 0.0612 mm cells"):
            compute(_bump(), BALL, SurfaceParams(boundary=(0.0, 0.0, 24.0, 16.0), stepover=0.5, sample_step=0.25,
                                                 verify_cusp=True))
    finally:
        limits.set_limits(previous.max_points, previous.max_memory_bytes / 1e9, previous.max_positions)


def test_cancel_stops_the_verification():
    from tmm_workbench.core.errors import Cancelled

    calls: list = []

    def progress(f: float) -> bool:
        calls.append(f)
        return len(calls) < 5  # the raster's drop reports 3 times; cancelled in the verification's dense raster

    with pytest.raises(Cancelled):
        compute(_bump(), BALL, SurfaceParams(boundary=(0.0, 0.0, 24.0, 16.0), stepover=0.5, sample_step=0.25,
                                             verify_cusp=True), progress)
    assert len(calls) == 5
