"""The side found covered to the mesh's edge measured again under the pass's own tool positions
(widths.edge_by_tools): the flat bottoms at the CC points and between, cut by each CC point's section."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.widths import edge_by_tools
from tmm_workbench.core.tools.cutter import Cutter

TOL = 0.1


def _pass(tilt_deg: float, lift: float):
    """A plane z = 0 whose edge lies 4 mm left (+y) of the drive plane y = 6, the tools' tips on it (lifted by
    `lift`), their axes tilted `tilt_deg` about LX (the bottom rising to the left)."""
    mesh = grid_mesh(lambda x, y: 0.0 * x, 20, 10, (0, 0, 40, 10), "plane")
    path = cc_paths(mesh, (1.0, 0.0), np.array([6.0]), 2.0, 0.01)[0]
    f = path.frames
    t = math.radians(tilt_deg)
    axes = math.cos(t) * f[:, 2] - math.sin(t) * f[:, 1]
    tips = path.points + lift * f[:, 2]
    widths = np.full((len(path), 2), np.inf)
    ends = np.full((len(path), 2, 3), np.nan)
    return MeshReach(mesh), path, tips, axes, widths, ends


def test_level_tools_on_the_surface_cover_the_side_to_the_edge() -> None:
    reach, path, tips, axes, widths, ends = _pass(0.0, 0.0)
    w, e, _ = edge_by_tools(reach, Cutter.flat(12.7), [path], tips, axes, widths, ends, TOL, (0,))
    assert np.isinf(w[:, 0]).all() and np.isinf(w[:, 1]).all()


def test_a_bottom_rising_to_the_side_stops_where_it_leaves_the_tolerance() -> None:
    # the bottom z = y tan(10 deg) over the plane: within the tolerance to TOL / tan(10 deg) = 0.567 mm
    reach, path, tips, axes, widths, ends = _pass(10.0, 0.0)
    w, e, short = edge_by_tools(reach, Cutter.flat(12.7), [path], tips, axes, widths, ends, TOL, (0,))
    expect = TOL / math.tan(math.radians(10.0))
    assert np.allclose(short, 4.0 - expect, atol=0.14)                   # to the last section sample on the mesh
    assert w[:, 0] == pytest.approx(np.full(len(path), expect), abs=1e-3)
    assert np.allclose(e[:, 0, 1], 6.0 + w[:, 0], atol=1e-6) and np.allclose(e[:, 0, 2], 0.0, atol=1e-6)
    assert np.isinf(w[:, 1]).all()                                                   # the right side: not asked


def test_tools_above_the_tolerance_cover_nothing_and_a_bull_nose_is_left_as_it_is() -> None:
    reach, path, tips, axes, widths, ends = _pass(0.0, 0.3)
    w, _, _ = edge_by_tools(reach, Cutter.flat(12.7), [path], tips, axes, widths, ends, TOL, (0,))
    assert np.allclose(w[:, 0], 0.0)
    w, _, _ = edge_by_tools(reach, Cutter.bull(12.7, 1.0), [path], tips, axes, widths, ends, TOL, (0,))
    assert np.isinf(w).all()
