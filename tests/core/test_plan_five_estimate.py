"""The 5-axis mesh op's cycle time estimated without planning it (core.plan.mesh5_estimate), against the op itself
planned and timed by the Tarus post (core.plan.five_axis's former way, what the FreeCAD op then computes): on a
small window of each of seed 000's convex and concave surfaces (the step control replayed: test_mesh5_step_replay)."""
from __future__ import annotations

import pytest

from benchmarks.seed000_surfaces import seed000_mesh
from tmm_workbench.core import path5
from tmm_workbench.core.linking import link
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.plan import decide, five_axis, materials
from tmm_workbench.core.plan.job_file import ToolSpec
from tmm_workbench.core.post import Operation, ToolInfo
from tmm_workbench.core.post.tarus_writer import write_tarus
from tmm_workbench.core.strategies.mesh5 import finish
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params
from tmm_workbench.core.strategies.multipoint import link_policy


class _Job:
    """What five_axis.mesh5_estimate reads of a job: the finish, the machine, the material."""
    class finish:
        cusp, tolerance = 0.05, 0.01

    class machine:
        tilt_limit, post, spindle_max, feed_max = 45.0, "tarus", 24000.0, 5000.0

    material = "modelling_foam"


def built_seconds(mesh, tool: ToolSpec) -> tuple[float, int]:
    """The op planned (mesh5.finish.compute) and timed by the Tarus post: (s, passes)."""
    args = five_axis.mesh5_args(_Job, tool)
    cutter = decide.cutter_of(tool)
    result = finish.compute(mesh, cutter, Mesh5Params(tolerance=args["tolerance"], forward_step=args["forward_step"],
                                                      chord_tol=args["chord_tolerance"]))
    top = float(mesh.bounds[1][2])
    tp = link(result.segments, link_policy(cutter, top + 5.0, top + 10.0, 5.0))
    c = materials.cutting(_Job.material, tool.diameter, tool.flutes, _Job.machine.spindle_max, _Job.machine.feed_max)
    info = ToolInfo(number=1, label=tool.name, shape="endmill", diameter=tool.diameter, corner_radius=0.0,
                    cutting_height=tool.flute_length, spindle_rpm=c.rpm)
    program = [info, Operation("op", path5.encode_toolpath(tp, c.feed / 60.0, c.plunge / 60.0), "Flood")]
    return write_tarus(program, TarusMachine()).cycle_time, result.diagnostics["passes"]


@pytest.mark.parametrize("surface", ["convex", "concave"])
def test_estimate_near_the_built_op(surface: str) -> None:
    mesh, _ = seed000_mesh(surface, nt=21, ns=11, window=(0.45, 0.55, 0.45, 0.55))   # about 25 x 27 mm
    tool = ToolSpec(name="T1 flat D8", type="flat", diameter=8.0, corner_radius=0.0, flutes=2, flute_length=20.0)
    est = five_axis.mesh5_estimate(_Job, mesh, tool)
    seconds, passes = built_seconds(mesh, tool)
    assert est.blocked == 0 and est.probed > 50
    assert abs(est.passes - passes) <= 2, (est.passes, passes)
    # the estimate runs low: the op tilts and yaws the tool for its motion time, which turns A more at the links
    # (measured -27 % and -12 % here, -0 % to -24 % on the 51 x 53 mm windows: docs/planner.md)
    assert -0.35 * seconds < est.seconds - seconds < 0.1 * seconds, (est.seconds, seconds)
