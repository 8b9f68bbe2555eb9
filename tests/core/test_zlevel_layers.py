"""Layer heights of z-level roughing: fixed steps ending exactly at the final depth, seed 000 eq. 3.11 against
a hand computation (and eq. 3.10 giving the tolerance back), the cutters other than the ball, tolerance
layers on a cone of known slope, plateaus found from the mesh and layers added only where a plateau would
keep more than the tolerance."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies import zlevel_layers as L
from tmm_workbench.core.tools.cutter import Cutter


def test_fixed_layers_end_exactly_at_the_final_depth():
    z = L.fixed_layers(30.0, 3.3, 2.0)
    assert z[:-1] == pytest.approx(30.0 - 2.0 * np.arange(1, 14))
    assert z[-1] == 3.3 and len(z) == 14 and np.all(np.diff(z) < 0)
    assert np.diff(z)[-1] == pytest.approx(-0.7)      # 4 -> 3.3: the remainder
    exact = L.fixed_layers(10.0, 4.0, 2.0)                    # a whole number of steps: no sliver layer
    assert exact.tolist() == [8.0, 6.0, 4.0]
    assert len(L.fixed_layers(1.0, 2.0, 0.5)) == 0


def test_eq_3_11_against_a_hand_computation():
    # ball R = 5, delta = 0.1, alpha = 30 deg: eps = 2 * 0.5 * sqrt(2 * 0.1 * 5 - 0.01) = sqrt(0.99)
    eps = L.tolerance_depth(Cutter.ball(10), 0.1, 30.0)
    assert eps == pytest.approx(math.sqrt(0.99), rel=1e-12)
    # eq. 3.10 gives the remaining height back
    R, a = 5.0, math.radians(30.0)
    assert R - math.sqrt(R * R - (eps / (2 * math.sin(a))) ** 2) == pytest.approx(0.1, rel=1e-12)
    # vertical walls: eps = 2 sqrt(2 delta R - delta^2)
    assert L.tolerance_depth(Cutter.ball(10), 0.1, 90.0) == pytest.approx(2 * math.sqrt(0.99))
    # bull-nose: the corner radius plays R; flat end mill: the stair's corner, delta / cos(alpha)
    assert L.tolerance_depth(Cutter.bull(10, 1), 0.1, 30.0) == pytest.approx(math.sqrt(2 * 0.1 * 1 - 0.01))
    assert L.tolerance_depth(Cutter.flat(10), 0.1, 60.0) == pytest.approx(0.2)
    # below MIN_SLOPE_DEG the slope counts as MIN_SLOPE_DEG (eq. 3.11 would go to 0)
    assert L.tolerance_depth(Cutter.ball(10), 0.1, 1.0) == L.tolerance_depth(Cutter.ball(10), 0.1, L.MIN_SLOPE_DEG)


def cone_mesh(height: float, slope_deg: float, n: int = 256):
    """A right cone (apex up, no base) of n facets whose slope is atan(height / (r cos(pi / n)))."""
    r = height / math.tan(math.radians(slope_deg))
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    v = np.vstack([[0.0, 0.0, height], np.column_stack([r * np.cos(t), r * np.sin(t), np.zeros(n)])])
    f = np.array([[0, 1 + k, 1 + (k + 1) % n] for k in range(n)], dtype=np.int32)
    return TriMesh(v, f, "cone"), r


def test_tolerance_layers_on_a_cone_of_known_slope():
    cone, r = cone_mesh(20.0, 40.0)
    facet = math.degrees(math.atan(20.0 / (r * math.cos(math.pi / 256))))   # by hand, the facets' slope
    ball = Cutter.ball(8)
    z = L.tolerance_layers(cone, ball, 20.5, 0.5, 3.0, 0.05, 0.5)
    eps = 2 * math.sin(math.radians(facet)) * math.sqrt(2 * 0.05 * 4.0 - 0.05 ** 2)   # eq. 3.11, R = 4
    steps = -np.diff(np.concatenate([[20.5], z]))
    assert z[-1] == 0.5
    assert steps[:-1] == pytest.approx(np.full(len(steps) - 1, eps), rel=1e-9) and 0 < steps[-1] <= eps + 1e-12
    assert len(z) == math.ceil(20.0 / eps - 1e-9)
    # the step-down caps the depth: a loose tolerance gives the fixed layers
    assert L.tolerance_layers(cone, ball, 20.5, 0.5, 0.3, 1.0, 0.5) == pytest.approx(L.fixed_layers(20.5, 0.5, 0.3))


def test_plateau_layers():
    # two terraces at 5 and 12 mm on a plate at 0
    def h(x, y):
        return np.where(x < 10, 12.0, np.where(x < 20, 5.0, 0.0))
    terraces = grid_mesh(h, 30, 10, (0, 0, 30, 10))
    p = L.plateau_heights(terraces)
    assert p.tolist() == [12.0, 5.0, 0.0]
    layers = L.fixed_layers(15.0, 0.5, 4.0)                      # 11, 7, 3, 0.5
    z = L.with_plateaus(layers, p, 15.0, 0.5, 0.5, tolerance=0.1)
    lift = 0.5 + L.PLATEAU_LIFT
    assert z.tolist() == pytest.approx([12.0 + lift, 11.0, 7.0, 5.0 + lift, 3.0, 0.5])
    # a plateau within the tolerance of the next layer above gets none
    z = L.with_plateaus(np.array([12.6, 0.5]), np.array([12.0]), 15.0, 0.5, 0.5, tolerance=0.2)
    assert z.tolist() == [12.6, 0.5]
