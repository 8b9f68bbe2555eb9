"""Lean passes (core.strategies.raster_lean): the forward step chosen by the chord tolerance.
Checked against independent references with the real kernel: every move (line or arc) of the lean path
sampled every 0.005 mm lies within the tolerance of the exact drop height there (a dense-sampling
reference), the simulated stock (core.sim) differs from the one a dense sampled path leaves by at most the
tolerance (gouge included), arcs in XZ/YZ have the RS274 sense (core.arcs, independent of the fitting), and
the lean path has fewer moves than the sampled one."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.lean_reference import fit_profile
from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.geometry.mesh import load_stl
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.shared_data import shared_dir
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute, compute_surface_toolpath
from tmm_workbench.core.tools.cutter import Cutter

TOL = 0.001


def bump(x, y):
    """A smooth dome on a plate with a ridge: convex, concave and flat stretches, curvature radii 2-20 mm."""
    r = np.hypot(x - 20, y - 10)
    return np.maximum(np.where(r < 12, 4 * np.cos(np.minimum(r, 12) / 12 * math.pi / 2) ** 2, 0.0),
                      np.where(np.abs(x - 33) < 3, 1.5 - np.abs(x - 33) / 2, 0.0))


@pytest.fixture(scope="module")
def bump_mesh():
    return grid_mesh(bump, 160, 80, (0, 0, 40, 20))


def arcs_of(segments):
    """The arcs of the segments' moves (CutSegment.arcs), in order."""
    return [a for seg in segments for a in (seg.arcs or ()) if a is not None]


def move_points(segments, step=0.005):
    """Points every `step` mm along every cutting move between the tips of each of `segments` (arcs as 1e-6 mm
    chords)."""
    out = []
    for seg in segments:
        t = seg.tips
        for k, (a, b) in enumerate(zip(t[:-1], t[1:])):
            arc = seg.arc(k + 1)
            if arc is not None:
                pts = np.vstack([a, arc.chords(a, b, 1e-6)])
            else:
                pts = np.vstack([a, b])
            for p, q in zip(pts[:-1], pts[1:]):
                n = max(1, int(math.ceil(math.hypot(*(q[:2] - p[:2])) / step)))
                f = np.arange(n + 1)[:, None] / n
                out.append(p + f * (q - p))
    return np.vstack(out)


@pytest.mark.parametrize("angle,arcs", [(0.0, False), (0.0, True), (90.0, True), (30.0, False)])
def test_within_tolerance_of_the_exact_path(bump_mesh, angle, arcs):
    cutter = Cutter.ball(4.0)
    params = SurfaceParams(boundary=(2, 2, 38, 18), stepover=1.0, sample_step=0.25, angle_deg=angle,
                           forward_step="tolerance", chord_tol=TOL, arcs=arcs)
    res = compute(bump_mesh, cutter, params)
    pts = move_points(res.segments)
    exact = DropSurface(bump_mesh).drop(cutter, pts[:, :2], float(bump_mesh.bounds[0][2]))
    dev = pts[:, 2] - exact
    assert np.abs(dev).max() <= TOL + 1e-6, (dev.min(), dev.max())
    sampled = compute(bump_mesh, cutter, replace(params, forward_step="sample"))
    n_lean = sum(len(s) for s in res.segments)
    n_sampled = sum(len(s) for s in sampled.segments)
    assert n_lean < n_sampled
    if arcs and angle in (0.0, 90.0):
        assert res.diagnostics["lean"]["arcs"] > 0
        planes = {a.plane for a in arcs_of(res.segments)}  # zig-zag links run across the passes
        assert ("XZ" if angle == 0.0 else "YZ") in planes and planes <= {"XZ", "YZ"}
    if angle == 30.0:
        assert not arcs_of(res.segments)  # not in a principal plane: lines only


def test_simulated_stock_within_tolerance_of_a_dense_reference(bump_mesh):
    cutter = Cutter.ball(4.0)
    grid = Grid.covering(4, 4, 36, 16, 0.05)
    stock = box_heights(grid, 8.0)
    base = SurfaceParams(boundary=(0, 0, 40, 20), stepover=0.5, sample_step=0.25, chord_tol=TOL)
    policy = LinkPolicy(12.0, 15.0)
    dense = compute_surface_toolpath(bump_mesh, cutter, replace(base, sample_step=0.01, chord_tol=0.0), policy)
    ref = simulate(dense, cutter, grid, stock).heights
    design = mesh_heights(bump_mesh, grid)
    assert (ref - design).min() >= -1e-4  # the dense path gouges nothing (the design: a 1e-4 mm needle)
    for arcs in (False, True):
        lean = compute_surface_toolpath(bump_mesh, cutter, replace(base, forward_step="tolerance", arcs=arcs), policy)
        assert bool(lean.arcs) == arcs
        got = simulate(lean.chorded(1e-5), cutter, grid, stock).heights
        # the band: the surface cut at most TOL below the design (a tool at most TOL below the exact path) ...
        assert (got - design).min() >= -TOL - 1e-4, (got - design).min()
        # ... and no more left than TOL above what the dense path leaves (at a valley the dense path's 0.01 mm
        # chords pass above the exact path, so the lean stock may be lower than the dense one there)
        assert (got - ref).max() <= TOL + 1e-6, (got - ref).max()
        assert len(lean) < len(dense) / 10


def test_real_model_fewer_moves_within_tolerance():
    """sphere_on_plate.stl with arcs (the kernel's fit): every move, arcs as circles, within the tolerance of the
    exact path."""
    mesh = load_stl(str(shared_dir() / "benchmarks" / "stl" / "sphere_on_plate.stl"))
    cutter = Cutter.ball(6.0)
    params = SurfaceParams(boundary=(20, 30, 56, 46), stepover=2.0, sample_step=0.25, forward_step="tolerance",
                           chord_tol=TOL, arcs=True)
    res = compute(mesh, cutter, params)
    surface = DropSurface(mesh)
    outside = 0
    for seg in res.segments:
        for k, (a, b) in enumerate(zip(seg.tips[:-1], seg.tips[1:])):
            pts = move_points([type(seg)(np.vstack([a, b]), arcs=(None, seg.arc(k + 1)))])
            dev = np.abs(pts[:, 2] - surface.drop(cutter, pts[:, :2], float(mesh.bounds[0][2])))
            outside += dev.max() > TOL + 1e-6
    assert outside == 0 and res.diagnostics["lean"]["arcs"] > 20
    assert sum(len(s) for s in res.segments) < 0.75 * sum(len(s) for s in compute(
        mesh, cutter, replace(params, forward_step="sample")).segments)


def test_fit_profile_circle_is_one_arc_and_lines_stay_in_the_band():
    s = np.arange(8.0, 32.0001, 0.25)  # slopes up to 0.75: arcs are fitted up to 45 deg
    e = np.sqrt(20.0 ** 2 - (s - 20) ** 2)
    fixed = np.zeros(len(s), bool)
    fixed[[0, -1]] = True
    arcs = fit_profile(s, e, TOL, fixed, True)
    assert len(arcs) == 1 and arcs[0].circle is not None
    assert arcs[0].circle[:2] == pytest.approx((20.0, 0.0), abs=1e-9)
    lines = fit_profile(s, e, TOL, fixed, False)
    dense = np.linspace(8, 32, 24001)
    exact = np.sqrt(20.0 ** 2 - (dense - 20) ** 2)
    worst = max(np.abs(p.z_at(dense[(dense >= s[p.a]) & (dense <= s[p.b])], s[p.a], s[p.b])
                       - exact[(dense >= s[p.a]) & (dense <= s[p.b])]).max() for p in lines)
    assert worst <= TOL + 1e-9
    assert lines[0].za == e[0] and lines[-1].zb == e[-1]  # the ends exact
    assert len(lines) < len(s) / 1.3


@pytest.mark.parametrize("plane,expected_g3", [("XZ", True), ("YZ", False)])
def test_arc_sense_over_a_hump(plane, expected_g3):
    """A hump crossed along +X (XZ) or +Y (YZ): RS274 views G18 from +Y (X to the left) and G19 from +X (Y to
    the right), so over the top it is G3 in XZ and G2 in YZ. core.arcs draws it over the top either way."""
    r, half = 5.0, 0.6
    c = np.array([10.0, 10.0, 0.0])
    ax = 0 if plane == "XZ" else 1
    start, end = c.copy(), c.copy()
    start[ax] -= r * math.sin(half)
    end[ax] += r * math.sin(half)
    start[2] = end[2] = r * math.cos(half)
    arc = Arc.through(start, end, c, plane)
    assert arc.clockwise == (not expected_g3)
    assert arc.command(start, end)[0] == ("G3" if expected_g3 else "G2")
    pts = arc.chords(start, end, 1e-6)
    assert np.allclose(np.linalg.norm(pts - c, axis=1), r)
    assert pts[:, 2].max() == pytest.approx(r, abs=1e-5)      # over the top, not the long way round below
    assert np.allclose(pts[:, 1 - ax], c[1 - ax])             # in the plane
    assert np.allclose(pts[-1], end)


def test_chorded_toolpath_keeps_lines_and_expands_arcs():
    from tmm_workbench.core.toolpath import MoveKind, Toolpath

    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0)
    tp.add(MoveKind.FEED, 10, 0, 0, arc=Arc((5.0, 0.0, -5.0), False, "XZ"))  # G3 over the top, radius 5 sqrt 2
    tp.add(MoveKind.FEED, 12, 0, 0)
    out = tp.chorded(1e-4)
    assert tp.arcs == {1: tp.moves[1].arc} and not out.arcs
    pts = out.points()[:-1]
    assert len(out) > 10 and np.allclose(pts[-1], (10, 0, 0)) and out.moves[-1] == tp.moves[-1]
    assert np.allclose(np.hypot(pts[:, 0] - 5, pts[:, 2] + 5), math.sqrt(50))
    assert pts[:, 2].max() > 2.0
