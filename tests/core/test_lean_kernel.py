"""Lean passes fitted in the kernel (core.strategies.lean_kernel over native.lean_profiles),
against independent references with the real kernel: every move of the lean path sampled every 0.005 mm lies
within +-tol of the exact drop height there (dense drops: the reference), the kernel's fit uses no more moves
than the Python fit (tests/core/lean_reference.py, the slow reference) on the same samples, at least
the lower bound it reports, and the off-model (skip) moves stay as sampled; with arcs, the same band with fewer
moves. The simulated stock against the
design is checked in tests/core/test_raster_lean.py (lines: the kernel path)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core import lean_reference
from tests.core.test_raster_lean import TOL, arcs_of, bump, move_points
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import load_stl
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.shared_data import shared_dir
from tmm_workbench.core.strategies.lean_kernel import ExactDrop, lean_segments_kernel
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter


@pytest.fixture(scope="module")
def bump_mesh():
    return grid_mesh(bump, 160, 80, (0, 0, 40, 20))


@pytest.fixture(scope="module")
def sphere_on_plate():
    return load_stl(str(shared_dir() / "benchmarks" / "stl" / "sphere_on_plate.stl"))


def worst(mesh, cutter, segments) -> float:
    pts = move_points(segments)
    exact = DropSurface(mesh).drop(cutter, pts[:, :2], float(mesh.bounds[0][2]))
    return float(np.abs(pts[:, 2] - exact).max())


def both_fits(mesh, cutter, params):
    """(kernel segments, its stats, Python segments, its stats) from the same unthinned samples."""
    sampled = compute(mesh, cutter, replace(params, forward_step="sample", chord_tol=0.0)).segments
    surface = DropSurface(mesh)
    floor = float(mesh.bounds[0][2])
    kern, kstats = lean_segments_kernel(sampled, ExactDrop(surface.index, cutter, floor, 0.0, floor), TOL,
                                        params.sample_step / 2, lower_bound=True)  # as raster_drop

    def drop(p):
        return np.maximum(surface.drop(cutter, p, floor), floor), np.zeros(len(p), dtype=bool)

    py, pstats = lean_reference.lean_segments(sampled, drop, TOL, False, min(params.sample_step / 4, 0.05))
    return kern, kstats, py, pstats


@pytest.mark.parametrize("angle", [0.0, 90.0, 30.0])
def test_kernel_fit_within_tolerance_and_not_more_moves_than_python(bump_mesh, angle):
    cutter = Cutter.ball(4.0)
    params = SurfaceParams(boundary=(2, 2, 38, 18), stepover=1.0, sample_step=0.25, angle_deg=angle,
                           forward_step="tolerance", chord_tol=TOL)
    kern, kstats, py, pstats = both_fits(bump_mesh, cutter, params)
    assert worst(bump_mesh, cutter, kern) <= TOL + 1e-6
    n_k, n_p = sum(len(s) for s in kern), sum(len(s) for s in py)
    assert n_k <= n_p, (n_k, n_p)
    assert kstats["lower_bound"] <= n_k and kstats["points_out"] == n_k
    # the op's path (compute with forward_step "tolerance", lines) is the kernel's
    res = compute(bump_mesh, cutter, params)
    assert sum(len(s) for s in res.segments) == n_k and res.diagnostics["lean"]["checked"] > 0


def test_bull_nose_on_sphere_on_plate(sphere_on_plate):
    """A real STL (2-3 mm facets) with the demo's other cutter kind: within the band, fewer moves than the
    Python fit, and a fraction of the samples."""
    cutter = Cutter.bull(4.0, 1.0)
    params = SurfaceParams(boundary=(20, 30, 56, 40), stepover=2.0, sample_step=0.2, forward_step="tolerance",
                           chord_tol=TOL)
    kern, kstats, py, _ = both_fits(sphere_on_plate, cutter, params)
    assert worst(sphere_on_plate, cutter, kern) <= TOL + 1e-6
    n_k, n_p = sum(len(s) for s in kern), sum(len(s) for s in py)
    assert kstats["lower_bound"] <= n_k < n_p and n_k < kstats["points_in"] / 2, (n_k, n_p, kstats)


@pytest.mark.parametrize("angle", [0.0, 90.0])
def test_kernel_arcs_within_tolerance_and_fewer_moves(sphere_on_plate, angle):
    """ArcFitting in the kernel (moves merged into G18 / G19 arcs where they hold the band and its checks) on a
    real STL with the demo's ball: every move, arcs as circles, within +-tol of the exact drop every 0.005 mm;
    fewer moves than the kernel's lines and no more than the Python arc fit on the same samples (the slow
    reference, whose checks every 0.05 mm missed bumps of the exact path: +0.0027 mm on mount_rush)."""
    cutter = Cutter.ball(6.0)
    params = SurfaceParams(boundary=(20, 30, 56, 40), stepover=2.0, sample_step=0.25, angle_deg=angle,
                           forward_step="tolerance", chord_tol=TOL, arcs=True)
    sampled = compute(sphere_on_plate, cutter, replace(params, forward_step="sample", chord_tol=0.0)).segments
    surface = DropSurface(sphere_on_plate)
    floor = float(sphere_on_plate.bounds[0][2])
    exact = ExactDrop(surface.index, cutter, floor, 0.0, floor)
    segs, stats = lean_segments_kernel(sampled, exact, TOL, params.sample_step / 2, arcs=True)
    lines, _ = lean_segments_kernel(sampled, exact, TOL, params.sample_step / 2)
    arcs = arcs_of(segs)

    def drop(p):
        return np.maximum(surface.drop(cutter, p, floor), floor), np.zeros(len(p), dtype=bool)

    py, _ = lean_reference.lean_segments(sampled, drop, TOL, True, min(params.sample_step / 4, 0.05))
    pts = move_points(segs)
    assert np.abs(pts[:, 2] - np.maximum(surface.drop(cutter, pts[:, :2], floor), floor)).max() <= TOL + 1e-6
    assert stats["arcs"] == len(arcs) > 20 and not arcs_of(lines) and arcs_of(py)
    assert ("XZ" if angle == 0.0 else "YZ") in {a.plane for a in arcs}  # (links run across: the other)
    n_a, n_l, n_p = (sum(len(s) for s in x) for x in (segs, lines, py))
    assert n_a < n_l and n_a <= n_p, (n_a, n_l, n_p)
    res = compute(sphere_on_plate, cutter, params)  # the op's path is the kernel's, arcs included
    assert sum(len(s) for s in res.segments) == n_a and arcs_of(res.segments) == arcs


def feed_points(tp, step=0.005) -> np.ndarray:
    """Points every `step` mm along every FEED move of the linked path `tp` (arcs as 1e-6 mm chords): also the
    moves the linker makes between segments it joins, which no segment holds."""
    tp = tp.chorded(1e-6)
    p, out = tp.points(), []
    for i in range(1, len(p)):
        if tp.moves[i].kind is MoveKind.FEED:
            n = max(1, int(math.ceil(math.hypot(*(p[i, :2] - p[i - 1, :2])) / step)))
            out.append(p[i - 1] + np.arange(n + 1)[:, None] / n * (p[i] - p[i - 1]))
    return np.vstack(out)


@pytest.mark.parametrize("arcs", [False, True])
def test_moves_between_joined_segments_within_tolerance(bump_mesh, arcs):
    """The zig-zag links cross the dome's slopes (the boundary's edges at x 10 and 30) with one sample between
    two passes: the moves into and out of a link are fitted and checked like the passes' (they were not, and
    left the band: -0.0047 mm on mount_rush). Every arc of the segments, the one into a joined segment's first
    tip included, is an arc move of the linked path."""
    cutter = Cutter.ball(4.0)
    params = SurfaceParams(boundary=(10, 2, 30, 18), stepover=0.6, sample_step=0.5, forward_step="tolerance",
                           chord_tol=TOL, arcs=arcs)
    res = compute(bump_mesh, cutter, params)
    assert sum(s.kind.name == "LINK" for s in res.segments) > 20
    tp = link(res.segments, LinkPolicy(50.0, 55.0))
    assert list(tp.arcs.values()) == arcs_of(res.segments) and (len(tp.arcs) > 100 or not arcs)
    assert not arcs or any(s.joined and s.arc(0) is not None for s in res.segments)
    pts = feed_points(tp)
    floor = float(bump_mesh.bounds[0][2])
    exact = np.maximum(DropSurface(bump_mesh).drop(cutter, pts[:, :2], floor), floor)
    assert np.abs(pts[:, 2] - exact).max() <= TOL + 1e-6


def test_segment_ends_are_the_samples_bit_for_bit(bump_mesh):
    """A lean segment ends (and unless joined, starts) exactly where its samples did (both fits, a raster at 30
    deg): the linker joins segments at these points (a last point rebuilt as origin + s u is an ulp off)."""
    cutter = Cutter.ball(4.0)
    params = SurfaceParams(boundary=(2, 2, 38, 18), stepover=1.0, sample_step=0.25, angle_deg=30.0,
                           forward_step="tolerance", chord_tol=TOL)
    kern, _, py, _ = both_fits(bump_mesh, cutter, params)
    sampled = compute(bump_mesh, cutter, replace(params, forward_step="sample", chord_tol=0.0)).segments
    def ends(segments):  # a joined segment starts with a move from the one before: its first point may go
        return [(s.tips[-1].tolist(), None if s.joined else s.tips[0].tolist()) for s in segments]

    assert ends(kern) == ends(sampled) and ends(py) == ends(sampled)


def test_stock_to_leave_and_air_are_the_raster_s(bump_mesh):
    """Off-model skip and a stock to leave: the kernel's exact height is the raster's (drop of the grown cutter
    raised by the stock), so the path stays within the band of that; moves beside air keep their samples."""
    cutter = Cutter.ball(4.0)
    params = SurfaceParams(boundary=(-6, 2, 46, 18), stepover=2.0, sample_step=0.25, forward_step="tolerance",
                           chord_tol=TOL, stock_to_leave=0.3, off_model="skip")
    res = compute(bump_mesh, cutter, params)
    pts = move_points(res.segments)
    grown = cutter.offset(0.3)
    floor = float(bump_mesh.bounds[0][2])
    exact = DropSurface(bump_mesh).drop(grown, pts[:, :2], floor - 1e6) + 0.3
    on = exact > floor - 10  # off the model there is no exact path; beside it the raster's floor holds the tool
    assert np.abs(pts[on, 2] - np.maximum(exact[on], floor)).max() <= TOL + 1e-6
    sampled = compute(bump_mesh, cutter, replace(params, forward_step="sample", chord_tol=0.0))
    # (fewer only: the ball rolling off the model's edges is a tight circle, many moves within the band)
    assert sum(len(s) for s in res.segments) < 0.8 * sum(len(s) for s in sampled.segments)


def test_bad_tolerance_refused(bump_mesh):
    cutter = Cutter.ball(4.0)
    surface = DropSurface(bump_mesh)
    segs = compute(bump_mesh, cutter, SurfaceParams(boundary=(2, 2, 38, 18), stepover=4.0, sample_step=0.5)).segments
    for tol in (0.0, -1.0, math.nan):
        with pytest.raises(TmmError, match="tolerance"):
            lean_segments_kernel(segs, ExactDrop(surface.index, cutter, -10.0), tol)
    with pytest.raises(TmmError, match="lean tolerance"):
        lean_segments_kernel(segs, ExactDrop(surface.index, cutter, -10.0), 5.0)


def test_cancel(bump_mesh):
    from tmm_workbench.core.errors import Cancelled

    cutter = Cutter.ball(4.0)
    surface = DropSurface(bump_mesh)
    segs = compute(bump_mesh, cutter, SurfaceParams(boundary=(2, 2, 38, 18), stepover=0.5, sample_step=0.25,
                                                    chord_tol=0.0)).segments
    with pytest.raises(Cancelled):
        lean_segments_kernel(segs, ExactDrop(surface.index, cutter, -10.0), TOL, progress=lambda f: False)


def test_too_much_work_refused_before_dropping(bump_mesh):
    from tmm_workbench.core.segments import CutSegment

    surface = DropSurface(bump_mesh)
    run = CutSegment(np.array([[0.0, 5.0, 0.0], [1e6, 5.0, 0.0]]))
    with pytest.raises(TmmError, match="lean work"):
        lean_segments_kernel([run], ExactDrop(surface.index, Cutter.ball(4.0), -10.0), TOL, max_step=0.01)
