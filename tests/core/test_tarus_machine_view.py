"""Seed 001's three patches through the Tarus post, seen by the machine (tests/core/machine_view.py): in joint
and TCP mode, A stays inside its +-360 deg limits and never turns 180 deg in one line, every line is doable
at the joint speeds, the tool cuts no deeper than 0.01 mm into the face anywhere along the motion (as the
control moves it), and in joint mode the tip stays within 0.005 mm of the straight line between programmed
tips under linear joint interpolation (issue 11 items 1, 2, 3, 7; before: A to 786 deg, tips 6.9 mm off
their lines, 46-122 lines too fast, cuts 0.05-0.09 mm deep between positions:
benchmarks/tarus_machine_view.py)."""
from __future__ import annotations

import math

import pytest

from tests.conftest import SEED_JSON
from tmm_workbench.core import path5
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.post import Operation, ToolInfo
from tmm_workbench.core.post.tarus_writer import TarusOptions, write_tarus
from tmm_workbench.core.strategies.multipoint import (MultipointParams, compute_multipoint_toolpath, face_top,
                                                      link_policy, make_positioner)
from tmm_workbench.core.tools.cutter import Cutter
from tests.core import machine_view, swept

TOOL = ToolInfo(number=1, label="bull-nose D25.4 r6", shape="bullnose", diameter=25.4, corner_radius=6.0,
                cutting_height=30.0, spindle_rpm=10000, spindle_dir="CW")


@pytest.fixture(scope="module", params=["convex", "concave", "saddle"])
def program(request):
    net = bezier.load_seed_patch(SEED_JSON, request.param)
    face = BezierFace.from_net(net)
    tool = Cutter.torus(6.7, 6.0)
    safe = face_top(face) + 5.0
    tp, _ = compute_multipoint_toolpath(face, tool, MultipointParams(side_step=18.0, pass_spacing="fixed",
                                                                     forward_step=2.0),
                                        link_policy(tool, safe, safe + 5.0, 5.0))
    gouge = swept.FaceGouge(make_positioner(face, 6.7, 6.0, MultipointParams()), face, 6.7 + 2 * 6.0 + 1.0)
    return request.param, [TOOL, Operation(request.param, path5.encode_toolpath(tp, 1000 / 60, 300 / 60))], gouge


@pytest.mark.parametrize("tcp", [False, True])
def test_the_machine_can_follow_the_program(program, tcp):
    name, prog, gouge = program
    m = TarusMachine()
    res = write_tarus(prog, m, TarusOptions(tcp=tcp))
    v = machine_view.view(TarusMachine(a_limits=None), res.text, tcp=tcp, depth=gouge)
    assert v.deepest_cut <= 0.01, (name, v.deepest_cut)  # the face, anywhere along the motion
    assert -2 * math.pi - 1e-9 <= v.a_min and v.a_max <= 2 * math.pi + 1e-9, (name, v.a_min, v.a_max)
    assert v.largest_a_step <= math.pi / 2 + 1e-9
    assert not v.too_fast, (name, v.too_fast[:5])
    if not tcp:
        assert v.largest_tip_deviation <= 0.005 + 1e-4
        assert v.largest_axis_deviation <= math.radians(0.05) + 1e-7
    assert res.cycle_time == pytest.approx(v.cycle_time, rel=1e-3)  # the estimate the machine's view gives
