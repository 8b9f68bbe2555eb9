"""The planner's 5-axis finish estimate (core.plan.mesh5_estimate, through five_axis.mesh5_estimate) against the op
planned (mesh5.finish.compute with the planner's settings, no holder) and timed by the Tarus post, for each
candidate tool of a Tarus job (docs/planner.md's table).

    .venv/bin/python benchmarks/plan_mesh5_estimate.py [benchmarks/jobs/seed000_tarus.yaml ...] [--built /tmp/b.pkl]

--built: the op's plans are kept there (they take most of the time) and read back when the file is there. Prints
a table: surface, tool, estimate passes and min (and its CPU s), the op's passes and min, estimate against the op.
"""
from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tmm_workbench.core import path5  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import link  # noqa: E402
from tmm_workbench.core.machine.tarus import TarusMachine  # noqa: E402
from tmm_workbench.core.plan import decide, five_axis, materials  # noqa: E402
from tmm_workbench.core.plan.job_file import read_job  # noqa: E402
from tmm_workbench.core.post import Operation, ToolInfo  # noqa: E402
from tmm_workbench.core.post.tarus_writer import write_tarus  # noqa: E402
from tmm_workbench.core.strategies.mesh5 import finish  # noqa: E402
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params  # noqa: E402
from tmm_workbench.core.strategies.multipoint import link_policy  # noqa: E402

JOBS = ("benchmarks/jobs/seed000_tarus.yaml", "benchmarks/jobs/seed000_concave_tarus.yaml", "tests/data/plan_tarus.yaml")


def built(job, mesh, tool) -> tuple[float, int]:
    """The op planned with the planner's settings and timed by the Tarus post: (s, passes)."""
    args = five_axis.mesh5_args(job, tool)
    cutter = decide.cutter_of(tool)
    result = finish.compute(mesh, cutter, Mesh5Params(tolerance=args["tolerance"], tilt_max_deg=args["tilt_limit_deg"],
                                                      forward_step=args["forward_step"],
                                                      chord_tol=args["chord_tolerance"]))
    top = float(mesh.bounds[1][2])
    tp = link(result.segments, link_policy(cutter, top + 5.0, top + 10.0, 5.0))
    c = materials.cutting(job.material, tool.diameter, tool.flutes, job.machine.spindle_max, job.machine.feed_max)
    info = ToolInfo(number=1, label=tool.name, shape="endmill" if tool.type == "flat" else "bullnose",
                    diameter=tool.diameter, corner_radius=tool.corner_radius, cutting_height=tool.flute_length,
                    spindle_rpm=c.rpm)
    program = [info, Operation("op", path5.encode_toolpath(tp, c.feed / 60.0, c.plunge / 60.0), "Flood")]
    return write_tarus(program, TarusMachine()).cycle_time, result.diagnostics["passes"]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("jobs", nargs="*", default=list(JOBS))
    ap.add_argument("--built", type=Path, default=None)
    a = ap.parse_args()
    store = pickle.loads(a.built.read_bytes()) if a.built is not None and a.built.is_file() else {}
    print("| job | tool | estimate: passes, min (CPU s) | the op: passes, min | estimate against the op |")
    print("|---|---|---|---|---|")
    for path in a.jobs:
        job = read_job(path)
        mesh = load_stl(job.model.file)
        for tool in (t for t in job.tools if t.type in ("flat", "bull")):
            c0 = time.process_time()
            est = five_axis.mesh5_estimate(job, mesh, tool)
            cpu = time.process_time() - c0
            key = (str(path), tool.name, job.finish.cusp)
            if key not in store:
                store[key] = built(job, mesh, tool)
                if a.built is not None:
                    a.built.write_bytes(pickle.dumps(store))
            seconds, passes = store[key]
            print(f"| {Path(path).stem} | {tool.name} | {est.passes}, {est.seconds / 60:.2f} ({cpu:.1f}) | "
                  f"{passes}, {seconds / 60:.2f} | {100 * (est.seconds - seconds) / seconds:+.0f} % |", flush=True)


if __name__ == "__main__":
    main()
