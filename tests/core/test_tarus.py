"""Tarus kinematics: IK/FK identities, branch continuity through the vertical axis, A unwrapping, limits,
motion time (seed 000 eq. 3.121-3.123), the 3-axis machine."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine import JointLimitError, Joints, JointSpeeds, TarusMachine, ThreeAxisMachine
from tmm_workbench.core.machine import rotary
from tmm_workbench.core.machine.rotary import RotaryPlanError

RNG = np.random.default_rng(20261123)


def random_axes(n: int, c_max: float, c_min: float = 0.0) -> np.ndarray:
    c = RNG.uniform(c_min, c_max, n)
    a = RNG.uniform(-math.pi, math.pi, n)
    return np.column_stack([np.sin(c) * np.cos(a), np.sin(c) * np.sin(a), np.cos(c)])


def test_chain_definition():
    m = TarusMachine(pivot_length=150.0, tool_length=100.0)
    # A = C = 0: vertical tool, the pivot 250 mm straight above the tip
    tip, axis = m.forward(Joints(10.0, 20.0, 300.0, 0.0, 0.0))
    np.testing.assert_allclose(axis, [0, 0, 1])
    np.testing.assert_allclose(tip, [10, 20, 50])
    # C = +90 deg, A = 0: the spindle end swings to +X, the tip is 250 mm to -X of the pivot
    tip, axis = m.forward(Joints(0.0, 0.0, 0.0, 0.0, math.pi / 2))
    np.testing.assert_allclose(axis, [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(tip, [-250, 0, 0], atol=1e-12)
    # A = +90 deg turns that counter-clockwise seen from above: axis +Y
    _, axis = m.forward(Joints(0.0, 0.0, 0.0, math.pi / 2, math.pi / 2))
    np.testing.assert_allclose(axis, [0, 1, 0], atol=1e-15)
    assert m.length == 250.0


def test_ik_then_fk_is_identity_on_random_orientations():
    m = TarusMachine(pivot_length=180.0, tool_length=75.0)
    n = 5000
    tips = RNG.uniform(-500, 500, (n, 3))
    axes = random_axes(n, math.radians(45.0))
    for t, u in zip(tips, axes):
        j = m.inverse(t, u)
        assert 0.0 <= j.c <= math.radians(45.0) + 1e-15
        tip, axis = m.forward(j)
        assert np.abs(tip - t).max() < 1e-9
        assert np.abs(axis - u).max() < 1e-12


def test_ik_fk_vectorised_and_with_negative_tilts():
    m = TarusMachine(c_limits=(-math.radians(60), math.radians(60)), a_limits=None)  # random axes: A roams
    n = 3000
    tips = RNG.uniform(-300, 300, (n, 3))
    axes = random_axes(n, math.radians(60.0))
    joints = rotary.solve_path(m, tips, axes)
    ft, fa = m.forward_path(joints)
    assert np.abs(ft - tips).max() < 1e-9
    assert np.abs(fa - axes).max() < 1e-12


def test_fk_then_ik_returns_the_joints():
    m = TarusMachine()
    n = 3000
    js = np.column_stack([RNG.uniform(-400, 400, (n, 3)), RNG.uniform(-math.pi, math.pi, n),
                          RNG.uniform(1e-3, math.radians(45), n)])
    for j in js:
        tip, axis = m.forward(j)
        back = m.inverse(tip, axis, previous=Joints.from_array(j))
        assert np.abs(back.as_array() - j).max() < 1e-9


def test_vertical_axis_holds_a():
    m = TarusMachine()
    prev = Joints(0, 0, 0, 1.234, 0.2)
    j = m.inverse((5, 6, 7), (0, 0, 1), previous=prev)
    assert j.a == 1.234 and j.c == 0.0
    assert (j.x, j.y, j.z) == (5.0, 6.0, 257.0)
    assert m.inverse((5, 6, 7), (0, 0, 1)).a == m.a_home == 0.0


def sweep_through_vertical(n: int = 41, tilt: float = math.radians(30)) -> tuple[np.ndarray, np.ndarray]:
    """Tool axis swinging in the XZ plane from +30 deg through the vertical to -30 deg (about Y)."""
    c = np.linspace(tilt, -tilt, n)
    axes = np.column_stack([np.sin(c), np.zeros(n), np.cos(c)])
    tips = np.column_stack([np.linspace(-20, 20, n), np.full(n, 3.0), np.full(n, -1.0)])
    return tips, axes


def test_sweep_through_vertical_with_negative_tilts_stays_on_one_branch():
    m = TarusMachine(c_limits=(-math.radians(45), math.radians(45)))
    tips, axes = sweep_through_vertical()
    j = rotary.solve_path(m, tips, axes)
    assert np.all(j[:, 3] == 0.0)  # A never moves
    np.testing.assert_allclose(j[:, 4], np.linspace(math.radians(30), -math.radians(30), len(tips)), atol=1e-12)
    ft, fa = m.forward_path(j)
    assert np.abs(ft - tips).max() < 1e-9 and np.abs(fa - axes).max() < 1e-12


def test_sweep_through_vertical_with_positive_tilts_turns_a_once_at_the_pole():
    m = TarusMachine()  # C in 0..45 deg: the head must turn A by 180 deg where the tool is vertical
    tips, axes = sweep_through_vertical()
    j = rotary.solve_path(m, tips, axes)
    assert np.all(j[:, 4] >= 0)
    da = np.diff(j[:, 3])
    assert np.count_nonzero(np.abs(da) > 1e-12) == 1
    assert abs(np.abs(da).max() - math.pi) < 1e-12  # one half turn, not 360 deg
    mid = len(tips) // 2
    assert j[mid, 4] == 0.0 and j[mid, 3] == 0.0  # at the pole A is held
    ft, fa = m.forward_path(j)
    assert np.abs(ft - tips).max() < 1e-9 and np.abs(fa - axes).max() < 1e-12


def test_near_vertical_noise_is_held():
    m = TarusMachine(singular_tol=1e-10)
    prev = Joints(0, 0, 0, 2.0, 0.1)
    j = m.inverse((0, 0, 0), (1e-12, -1e-12, 1.0), previous=prev)
    assert j.a == 2.0
    tip, axis = m.forward(j)
    assert np.abs(axis - np.array([1e-12, -1e-12, 1.0])).max() < 1e-11


def spiral(turns: float, n: int, tilt_deg: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    az = np.linspace(0.0, turns * 2 * math.pi, n)
    c = math.radians(tilt_deg)
    axes = np.column_stack([math.sin(c) * np.cos(az), math.sin(c) * np.sin(az), np.full(n, math.cos(c))])
    return np.column_stack([30 * np.cos(az), 30 * np.sin(az), np.zeros(n)]), axes


def test_a_unwrapping_on_a_spiral_has_no_jumps():
    m = TarusMachine(a_limits=None)  # a continuous A
    tips, axes = spiral(3, 721)      # three full turns of the axis azimuth, 1.5 deg per step
    c = math.radians(20)
    j = rotary.solve_path(m, tips, axes)
    assert np.abs(np.diff(j[:, 3])).max() < math.radians(1.5) + 1e-9
    assert j[-1, 3] == pytest.approx(6 * math.pi, abs=1e-9)
    # the other way round too, starting next to -180 deg
    j2 = rotary.solve_path(m, tips[::-1], axes[::-1], start=Joints(0, 0, 0, 6 * math.pi, c))
    assert np.abs(np.diff(j2[:, 3])).max() < math.radians(1.5) + 1e-9
    assert j2[-1, 3] == pytest.approx(0.0, abs=1e-9)


def test_a_limits_never_unwind_inside_a_cut():
    """The old planner put a whole turn of A into a cutting move to stay inside the limits; now a cut that
    cannot fit is refused, naming its moves, and one that fits gets the turn that keeps it inside."""
    with pytest.raises(RotaryPlanError) as err:
        rotary.solve_path(TarusMachine(), *spiral(3, 721))   # 1080 deg of A, limits +-360
    assert "moves 0..720" in str(err.value) and "1080 deg" in str(err.value)
    narrow = TarusMachine(a_limits=(-math.pi, math.pi))
    with pytest.raises(RotaryPlanError):
        rotary.solve_path(narrow, *spiral(0.75, 400))          # 270 deg of A do not fit 360 deg that start at -180
    start = Joints(0, 0, 0, math.radians(170), 0.2)
    tips, axes = spiral(0.4, 200)                    # 144 deg, starting at azimuth 0
    j = rotary.solve_path(narrow, tips, axes, start=start)
    assert np.abs(np.diff(j[:, 3])).max() < math.radians(1.0)  # continuous: no wrap inside
    assert j[:, 3].min() >= -math.pi - 1e-12 and j[:, 3].max() <= math.pi + 1e-12
    fitted = TarusMachine(a_limits=(math.radians(300), math.radians(520)))
    j = rotary.solve_path(fitted, tips, axes)                # moved up one whole turn to fit
    assert j[0, 3] == pytest.approx(2 * math.pi)


def test_a_unwinds_at_the_rapid_between_cuts():
    """Two cuts of 300 deg each, the same way round, with an orientation-changing rapid between them: the
    second cut gets its own turn, so A stays inside +-360 deg; A changes by whole turns only at the rapid."""
    m = TarusMachine()
    t1, a1 = spiral(300 / 360, 301)
    t2, a2 = spiral(300 / 360, 301)
    up = np.array([[0.0, 0.0, 80.0]])
    tips = np.vstack([t1, up, t2])
    axes = np.vstack([a1, [[0.0, 0.0, 1.0]], a2])
    rapid = [False] * len(t1) + [True] + [True] + [False] * (len(t2) - 1)
    j = rotary.solve_path(m, tips, axes, rapid=rapid)
    assert j[:, 3].max() <= 2 * math.pi + 1e-12 and j[:, 3].min() >= -2 * math.pi - 1e-12
    cut1, cut2 = j[:len(t1), 3], j[len(t1) + 1:, 3]
    assert np.abs(np.diff(cut1)).max() < math.radians(1.5) and np.abs(np.diff(cut2)).max() < math.radians(1.5)
    ft, fa = m.forward_path(j)
    assert np.abs(fa - axes).max() < 1e-12


def test_limit_violation_names_move_joint_and_value():
    m = TarusMachine()
    tips = np.zeros((3, 3))
    axes = np.array([[0, 0, 1.0], [math.sin(0.5), 0, math.cos(0.5)], [math.sin(1.0), 0, math.cos(1.0)]])
    with pytest.raises(JointLimitError) as err:
        rotary.solve_path(m, tips, axes)
    e = err.value
    assert isinstance(e, TmmError)
    assert (e.index, e.joint) == (2, "C")
    assert e.value == pytest.approx(1.0)
    assert "move 2: joint C = 57.2958 deg is outside its limits [0 deg, 45 deg]" in str(e)
    # linear travel of the pivot
    mz = TarusMachine(z_limits=(-100.0, 200.0))
    with pytest.raises(JointLimitError) as err:
        mz.inverse((0, 0, 0), (0, 0, 1))  # pivot z = 250
    assert err.value.joint == "Z" and "joint Z = 250 mm" in str(err.value)
    # upside down is never reachable
    with pytest.raises(JointLimitError):
        m.inverse((0, 0, 0), (0, 0, -1))


def test_bad_settings_and_axes():
    with pytest.raises(TmmError):
        TarusMachine(tool_length=-1.0)
    with pytest.raises(TmmError):
        TarusMachine(c_limits=(1.0, 0.0))
    with pytest.raises(TmmError):
        TarusMachine(speeds=JointSpeeds(x=0.0))
    with pytest.raises(TmmError, match="no direction"):
        TarusMachine().inverse((0, 0, 0), (0, 0, 0))
    with pytest.raises(TmmError, match="finite"):
        TarusMachine().inverse((0, 0, 0), (0, math.nan, 1))


def test_non_unit_axis_is_normalised():
    m = TarusMachine()
    j = m.inverse((1, 2, 3), (0, 0, 5))
    assert (j.x, j.y, j.z, j.c) == (1.0, 2.0, 253.0, 0.0)


def test_motion_time_against_hand_values():
    m = TarusMachine()  # X 170, Y 180, Z 240 mm/s, A 0.5, C 0.3 rad/s
    j0 = Joints(0, 0, 0, 0, 0)
    assert m.motion_time(j0, Joints(170, 0, 0, 0, 0)) == pytest.approx(1.0)
    assert m.motion_time(j0, Joints(0, -360, 0, 0, 0)) == pytest.approx(2.0)
    assert m.motion_time(j0, Joints(0, 0, 120, 0, 0)) == pytest.approx(0.5)
    assert m.motion_time(j0, Joints(0, 0, 0, 1.0, 0)) == pytest.approx(2.0)
    assert m.motion_time(j0, Joints(0, 0, 0, 0, -0.6)) == pytest.approx(2.0)
    # all at once: the slowest joint decides (eq. 3.123)
    assert m.motion_time(j0, Joints(85, 90, 240, 0.25, 0.3)) == pytest.approx(1.0)
    assert m.motion_time(j0, Joints(85, 90, 24, 1.5, 0.3)) == pytest.approx(3.0)
    # the X, Y, Z joints are the pivot (the seed's CH point): a pure tilt about the tip moves it too
    a = m.inverse((0, 0, 0), (0, 0, 1))
    b = m.inverse((0, 0, 0), (math.sin(0.3), 0, math.cos(0.3)), previous=a)
    dx = 250 * math.sin(0.3)
    assert m.motion_time(a, b) == pytest.approx(max(dx / 170, 250 * (1 - math.cos(0.3)) / 240, 0.3 / 0.3))


def test_cycle_time_sums_segments_with_feeds():
    m = TarusMachine()
    joints = np.array([[0, 0, 300, 0, 0], [170, 0, 300, 0, 0], [170, 10, 300, 0, 0]], dtype=float)
    assert m.cycle_time(joints) == pytest.approx(1.0 + 10 / 180)
    # the second move at a feed of 5 mm/s: 2 s
    assert m.cycle_time(joints, feeds=[None, None, 5.0]) == pytest.approx(1.0 + 2.0)
    assert m.cycle_time(joints[:1]) == 0.0


def test_three_axis_machine():
    m = ThreeAxisMachine()
    j = m.inverse((1, 2, 3), (0, 0, 1))
    assert j == Joints(1, 2, 3, 0, 0)
    tip, axis = m.forward(j)
    np.testing.assert_allclose(tip, [1, 2, 3])
    np.testing.assert_allclose(axis, [0, 0, 1])
    with pytest.raises(TmmError, match="cannot tilt"):
        m.inverse((0, 0, 0), (0.1, 0, 1), index=7)
    assert m.motion_time(Joints(0, 0, 0, 0, 0), Joints(170, 0, 0, 0, 0)) == pytest.approx(1.0)
    assert m.solve_path(np.zeros((2, 3)), np.array([[0, 0, 1.0], [0, 0, 1.0]])).shape == (2, 5)


def test_a_continuous_does_not_unwind_between_cuts():
    """Without A limits each cut continues from the one before: no whole turn at the rapid between."""
    m = TarusMachine(a_limits=None)
    t1, a1 = spiral(300 / 360, 301)
    tips = np.vstack([t1, [[0.0, 0.0, 80.0]], t1])
    axes = np.vstack([a1, [[0.0, 0.0, 1.0]], a1])
    rapid = [False] * len(t1) + [True] + [True] + [False] * (len(t1) - 1)
    j = rotary.solve_path(m, tips, axes, rapid=rapid)
    assert np.abs(np.diff(j[:, 3])).max() < math.radians(61)
    assert j[-1, 3] == pytest.approx(math.radians(660))
