"""The posture of each CC point chosen in its C-space for the Tarus motion time (core.strategies.mesh5.optimal):
in the C-space, gouge-free by a brute-force check, within the machine's limits, and never slower than the
seed's point-by-point nearest-to-ideal choice (much faster on a wavy pass)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tests.core.scallop5_reference import remaining, surface_samples
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace
from tmm_workbench.core.strategies.mesh5.optimal import (nearest_ideal, pair_times, pass_motion_time,
                                                         smooth_postures)
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, tool_rotation, world_placement
from tmm_workbench.core.tools.cutter import Cutter

CUTTER = Cutter.flat(10.0)


@pytest.fixture(scope="module")
def wavy():
    """A pass over waves along the feed on a slope across it, and its C-space (tolerance 0.1, half step 1.5)."""
    mesh = grid_mesh(lambda x, y: 2.0 * np.sin(x / 12.0) + 0.15 * y, 60, 24, (-30, -12, 30, 12), "wavy")
    path = cc_paths(mesh, (1, 0), np.array([0.0]), 3.0, 0.01)[0]
    cs = build_cspace(mesh, CUTTER, path.points, path.frames, PostureGrid.degrees(), 0.1, 1.5)
    assert not cs.empty.any()
    return mesh, path, cs


def test_chosen_postures_lie_in_the_cspace_and_reproduce_their_cl_points(wavy):
    mesh, path, cs = wavy
    p = smooth_postures(cs, CUTTER, path.points, path.frames)
    n = len(path)
    il, io = p.index[:, 0], p.index[:, 1]
    assert cs.available[np.arange(n), il, io].all()
    assert np.allclose(p.delta, cs.lift[np.arange(n), il, io])
    assert (p.delta <= cs.top[np.arange(n), il, io]).all()
    tips, axes = world_placement(CUTTER, path.points, path.frames, p.lam, p.omg, p.delta)
    assert np.allclose(tips, p.tips) and np.allclose(axes, p.axes)
    machine = TarusMachine()
    for j, t, u in zip(p.joints, p.tips, p.axes):
        tip, axis = machine.forward(j)
        assert np.allclose(tip, t, atol=1e-9) and np.allclose(axis, u, atol=1e-12)
        assert machine.c_limits[0] - 1e-12 <= j[4] <= machine.c_limits[1] + 1e-12


def test_chosen_postures_never_gouge_brute_force(wavy):
    mesh, path, cs = wavy
    p = smooth_postures(cs, CUTTER, path.points, path.frames)
    # every mesh point under the tools: the material left along its normal by the solid cylinder
    xs, ys = np.meshgrid(np.linspace(-29, 29, 233), np.linspace(-6, 6, 49), indexing="ij")
    q, nrm, hit = surface_samples(mesh, np.column_stack([xs.ravel(), ys.ravel()]))
    h = remaining(q[hit], nrm[hit], p.tips, p.axes, CUTTER.radius, 2 * CUTTER.diameter)
    assert h.min() >= -1e-3                       # touching (the lift S2 is exact), never cutting in
    assert np.isfinite(h).sum() > 1000            # the check reached many points under the tools


def test_motion_time_is_never_above_the_nearest_to_ideal_choice_and_far_below_on_waves(wavy):
    mesh, path, cs = wavy
    machine = TarusMachine()
    seed = nearest_ideal(cs, CUTTER, path.points, path.frames, machine)
    dp = smooth_postures(cs, CUTTER, path.points, path.frames, machine)
    t_seed, t_dp = pass_motion_time(machine, seed), pass_motion_time(machine, dp)
    assert t_dp <= t_seed + 1e-9
    # the point-by-point choice flips the yaw where the slope turns; the pass held to one side is faster
    assert t_dp < 0.5 * t_seed
    # the vectorised pair times are the machine's motion_time
    k = [machine.motion_time(a, b) for a, b in zip(dp.joints[:-1], dp.joints[1:])]
    assert np.allclose([pair_times(machine, a[None], b[None])[0, 0] for a, b in zip(dp.joints[:-1], dp.joints[1:])],
                       k)


def test_the_machines_tilt_limit_bounds_the_choice_and_an_unreachable_point_is_named(wavy):
    mesh, path, cs = wavy
    free = smooth_postures(cs, CUTTER, path.points, path.frames)
    assert free.joints[:, 4].max() > math.radians(12.0)                   # the limit below binds
    tight = TarusMachine(c_limits=(0.0, math.radians(12.0)))
    p = smooth_postures(cs, CUTTER, path.points, path.frames, tight)
    assert (p.joints[:, 4] <= math.radians(12.0) + 1e-12).all()
    unreachable = r"33 of 33 CC points have no available posture within the limits of the Tarus .* \(C 0\.\.1 deg\): #0 "
    with pytest.raises(TmmError, match=unreachable):
        smooth_postures(cs, CUTTER, path.points, path.frames, TarusMachine(c_limits=(0.0, math.radians(1.0))))
    with pytest.raises(TmmError, match="ideal weight"):
        smooth_postures(cs, CUTTER, path.points, path.frames, ideal_weight=-1.0)


def test_a_held_pass_turns_its_posture_against_the_surface_less(wavy):
    # the motion time alone keeps the machine's joints steady while the surface turns under the pass; held,
    # the posture keeps to the surface (where a side's edge is formed a radius along the pass: stepover._hold)
    _, path, cs = wavy
    m = TarusMachine()

    def turned(p) -> float:
        a = tool_rotation(p.lam, p.omg)[:, 2, :]
        return float(np.arccos(np.clip(np.einsum("ij,ij->i", a[:-1], a[1:]), -1.0, 1.0)).sum())

    free = smooth_postures(cs, CUTTER, path.points, path.frames, m)
    zero = smooth_postures(cs, CUTTER, path.points, path.frames, m, hold=np.zeros(len(path)))
    held = smooth_postures(cs, CUTTER, path.points, path.frames, m, hold=np.full(len(path), 100.0))
    assert np.array_equal(zero.index, free.index)
    assert turned(free) > 0.05 and turned(held) < 0.5 * turned(free)
    assert cs.available[np.arange(len(path)), held.index[:, 0], held.index[:, 1]].all()
