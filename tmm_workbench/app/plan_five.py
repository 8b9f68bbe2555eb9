"""The planner on the Tarus (core.plan.five_axis): a plan whose finishing is the 5-axis mesh op is run and verified
as any plan (app.plan_run.run_plan: the Job's simulation cuts the tilted flat end with the 5-axis stock
simulation); when the op fails or the Job does not verify, the 3-axis plan it replaced is run in a new Job
instead and the reason goes into verify.json (`five_axis_fallback`, `replanned`). The Job's G-code is the Tarus
post's (3-axis paths post too, the axis vertical); beside it, for the picture, the same in tool-tip coordinates
(`--tcp`) and, when the job asks, the APT CL file."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Optional

import FreeCAD

from tmm_workbench.core.errors import Cancelled

PROBLEMS_SHOWN = 3   # of a failed verification, in the fallback's reason


def run(plan: dict, folder: Path, run_plan: Callable, model: Any = None, progress: Any = False,
        discard: Optional[Callable[[], None]] = None) -> tuple[list, dict]:
    """`run_plan(plan, folder, model, progress)`, and for a plan with a 5-axis op its 3-axis fallback when the op
    fails or does not verify; then the tarus extras (post_extras). `discard()` removes what the failed 5-axis run
    added (the GUI's TMM Auto: its objects in the model's document); by default the documents it opened are closed
    (`tmm plan`: the Job's own document)."""
    choice = plan.get("five_axis")
    if not choice:
        results, report = run_plan(plan, folder, model, progress)
        post_extras(results, plan, folder)
        return results, report
    before = set(FreeCAD.listDocuments())
    try:
        results, report = run_plan(plan, folder, model, progress)
    except Cancelled:
        raise
    except Exception as exc:  # noqa: BLE001 - any failure of the 5-axis run: the 3-axis plan is the answer
        reason = f"failed: {exc}"
    else:
        if report["passed"]:
            post_extras(results, plan, folder)
            return results, report
        reason = "did not verify: " + "; ".join(report["problems"][:PROBLEMS_SHOWN])
    if discard is not None:
        discard()
    for name in set(FreeCAD.listDocuments()) - before:   # the 5-axis Job's document, made by this run
        FreeCAD.closeDocument(name)
    FreeCAD.Console.PrintWarning(f"{choice['op']} {reason}: the 3-axis plan instead\n")
    results, report = run_plan(dict(plan, ops=choice["fallback_ops"]), folder, model, progress)
    report["five_axis_fallback"] = reason
    report["replanned"] = [f"{choice['op']} {reason}: the 3-axis plan instead"] + report.get("replanned", [])
    post_extras(results, plan, folder)
    return results, report


def job_objects(results: list) -> list:
    """The Job's tool controllers and ops in posting order (a controller where its tool comes in)."""
    objects: list = []
    for r in results:
        objects += [r.op] if r.op.ToolController in objects else [r.op.ToolController, r.op]
    return objects


def post_extras(results: list, plan: dict, folder: Path) -> None:
    """A tarus Job's G-code in tool-tip coordinates (core.plan.launch.TIP_GCODE, for the picture) and, when asked,
    the APT CL file <name>.apt."""
    from tmm_workbench.app import posts
    from tmm_workbench.core.plan.launch import TIP_GCODE

    if not plan["gcode"]:
        return
    objects = job_objects(results)
    if plan["post"] == "tarus":
        posts.export("tarus", objects, folder / TIP_GCODE, "--no-show-editor --tcp")
    if plan.get("apt_cl"):
        posts.export("apt_cl", objects, folder / f"{plan['name']}.apt", "--no-show-editor --no-header")
