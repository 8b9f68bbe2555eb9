"""The FreeCAD side of the automatic planner: runs a plan made by core.plan (its ops as headless API calls, in
one Job), posts the whole Job, simulates it and writes what the simulation found. Started by core.plan.launch as

    TMM_PLAN_FILE=<folder>/plan.json freecadcmd tmm_workbench/app/plan_run.py

Everything goes to the plan file's folder (the launcher moves it into place when complete): <name>.FCStd,
<name>.ngc, <name>_sim.png and verify.json. freecadcmd returns 0 even when a script raises, so the outcome is an
explicit exit code: 0 the plan ran (verify.json says whether it passed), 3 it failed (the reason on stderr).
"""
from __future__ import annotations

import json
import os
import sys
import time
import traceback
from pathlib import Path
from typing import Any, Callable, Optional

REPO = Path(globals().get("__file__") or sys.argv[0]).resolve().parents[2]
TUPLES = ("stock", "slope_range")   # JSON lists the API takes as tuples
FAILED = 3


def run_ops(plan: dict, model: Any = None, progress: Any = False, left_out: Optional[list] = None) -> list:
    """The plan's ops in order in one Job made first around the model (`model`, a Mesh or Part object: the Job in
    its document; None: the plan's STL in a new document) with the plan's stock (app.plan_stock) and the machine's
    rapids; each op cut with its library tool's controller (library_controller: made before its first op, so
    every op computes once, with the tool's lengths and holder). An optional op (a rest, a pencil, a clean-up)
    that fails to compute (e.g. its Region 'Rest' is empty: the ops before it left nothing it reaches) is removed
    again and named with its reason in `left_out`; any other op's failure stops the run."""
    from tmm_workbench.app import api
    from tmm_workbench.app.plan_stock import new_job
    from tmm_workbench.core.errors import TmmError
    from tmm_workbench.core.plan import progress_note

    calls = {"run_roughing": api.run_roughing, "run_surface": api.run_surface, "run_waterline": api.run_waterline,
             "run_mesh5": api.run_mesh5}
    results: list = []
    controllers: dict = {}
    job = new_job(plan, model)
    if plan.get("rapid_mm_min") is not None:   # the machine's: every tool controller's by its expression
        job.SetupSheet.HorizRapid, job.SetupSheet.VertRapid = (v / 60.0 for v in plan["rapid_mm_min"])
    for i, op in enumerate(plan["ops"]):
        progress_note.note(2 + i, steps(plan), f"computing {op['label']}")
        kwargs = {k: tuple(v) if k in TUPLES else v for k, v in op["kwargs"].items() if k != "stock"}
        tc = controllers.get(op["tool"]) or library_controller(job, op["tool"], plan["tools"][op["tool"]], kwargs)
        try:
            r = calls[op["api"]](None, job=job, tool_controller=tc, label=op["label"], progress=progress, **kwargs)
        except TmmError as exc:
            if not op.get("optional") or left_out is None:
                raise
            left_out.append(f"left out {op['label']}: {exc}")
            remove_unused(job, results, controllers)
            continue
        controllers[op["tool"]] = tc
        results.append(r)
    if not results:
        raise RuntimeError("no op of the plan computed a tool path")
    for r in results:
        if not r.op.isValid():
            raise RuntimeError(f"{r.op.Label}: {r.op.getStatusString()}")
    return results


def library_controller(job: Any, tool: str, spec: dict, kwargs: dict) -> Any:
    """A tool controller in `job` for the library's `tool` (one per library tool, shared by its ops: the G-code
    changes tools only when the tool changes): the ToolBit of the op's tool shape and size (`kwargs`, the op's API
    arguments) and feeds, named after the library's tool and given its flute length, overall length, shank and
    holder (the ops use the controller's holder: their Holder is FromToolController)."""
    from tmm_workbench.app import compat
    from tmm_workbench.app.api import set_holder
    from tmm_workbench.app.api_run import add_tool, bit

    made = add_tool(job, bit(job.Document, kwargs["tool"], float(kwargs["diameter"]),
                             float(kwargs.get("corner_radius", 0.0))),
                    kwargs["horiz_feed"] / 60.0, kwargs["vert_feed"] / 60.0, kwargs["spindle_speed"])
    made.Label = f"TC: {tool}"
    made.Tool.Label = tool
    made.Tool.CuttingEdgeHeight = float(spec["flute_length"])
    made.Tool.Length = float(spec["length"])
    if spec.get("shank_diameter") is not None:
        made.Tool.ShankDiameter = float(spec["shank_diameter"])
    if spec["holder"] is not None:
        set_holder(made, spec["holder"], float(spec["stick_out"] or 0.0))
    compat.settle_toolbit(made)
    return made


def remove_unused(job: Any, results: list, controllers: Optional[dict] = None) -> None:
    """Removes from `job` the ops none of `results` is (ops left out, or what a failed API call added) and the
    tool controllers neither their ops nor `controllers` (the library tools' shared ones) hold."""
    from tmm_workbench.app import compat

    kept = [r.op for r in results]
    doc = job.Document
    for op in [o for o in job.Operations.Group if o not in kept]:
        doc.removeObject(op.Name)
    used = [o.ToolController for o in kept] + list((controllers or {}).values())
    for tc in [t for t in job.Tools.Group if t not in used]:
        bit = tc.Tool
        doc.removeObject(tc.Name)
        compat.remove_toolbit(bit)
    doc.recompute()


def change_failing(results: list, plan: dict, folder: Path, report: dict, replanned: list, first: float,
                   progress: Any = False) -> dict:
    """Each failing optional op changed by core.plan.replan's changes in turn, the Job verified after each, until
    it no longer fails (the change kept, said in `replanned`) or none is left (the op as planned again, for the
    caller to leave out), within the re-plan's budget (replan.Budget; `first`: s the first verification took).
    The ops after a changed one are recomputed: a rest reads the stock its earlier ops leave. Returns the last
    verification."""
    from tmm_workbench.core.plan import replan

    last = {"report": report}

    def attempt(label: str, change: dict) -> bool:
        index = next(i for i, r in enumerate(results) if r.op.Label == label)
        planned = op_properties(results[index].op, {})
        set_properties(results[index:], op_properties(results[index].op, change))
        last["report"] = verify(results, plan, folder, progress)
        if label not in last["report"]["failing_ops"] and not last["report"]["gouged"]:
            return True
        set_properties(results[index:], planned)
        last["report"] = verify(results, plan, folder, progress)
        return False

    ops = {op["label"]: op for op in plan["ops"]}
    replanned += replan.change_failing(list(report["failing_ops"]), ops, attempt, replan.Budget(first))
    return last["report"]


def op_properties(op: Any, change: dict) -> dict:
    """The op's tool-assembly properties for `change` (API keyword arguments; empty: their values now)."""
    from tmm_workbench.app import stages, tool_assembly

    if not change:
        return {f.prop: getattr(op, f.prop) for f in tool_assembly.STAGE.fields if f.api}
    return stages.api_values((tool_assembly.STAGE,), None, dict(change, holder="tool_controller"), None)


def set_properties(results: list, values: dict) -> None:
    """`values` set on the first result's op, it and the ops after it recomputed."""
    op = results[0].op
    for prop, value in values.items():
        setattr(op, prop, value)
    for r in results:
        r.op.touch()
    op.Document.recompute()
    for r in results:
        if not r.op.isValid():
            raise RuntimeError(f"{r.op.Label}: {r.op.getStatusString()}")


def op_rows(results: list, sim: Any) -> list:
    rows = []
    for r, s in zip(results, sim.ops):
        row = {"label": r.op.Label, "moves": s.moves, "cycle_seconds": round(s.cycle_seconds, 1),
               "rapids_through_stock": len(s.collisions), "holder": None if s.holder is None else s.holder.summary()}
        if getattr(r.op, "RestReport", ""):   # a rest or pencil op: its rest area, the volume before and after
            row["rest"] = r.op.RestReport
        rows.append(row)
    return rows


def steps(plan: dict) -> int:
    """The run's steps for its progress notes: the analysis and plan (the launcher's), each op, the simulation, the
    G-code and the document when asked."""
    return 1 + len(plan["ops"]) + 1 + bool(plan["gcode"]) + bool(plan["fcstd"])


def rapid_problems(collisions: list) -> list[str]:
    """The rapids through stock of (op label, move, depth mm), a problem per op led by its label: the re-plan
    names an op's problems by that prefix."""
    by_op: dict[str, list[float]] = {}
    for label, _move, depth in collisions:
        by_op.setdefault(label, []).append(float(depth))
    return [f"{label}: {len(d)} rapid{'s' if len(d) > 1 else ''} through stock (deepest {max(d):.3f} mm)"
            for label, d in by_op.items()]


def verify(results: list, plan: dict, folder: Path, progress: Any = False) -> dict:
    from tmm_workbench.app.api import simulate
    from tmm_workbench.core.plan import progress_note

    progress_note.note(2 + len(plan["ops"]), steps(plan), "simulating the Job")

    png = folder / f"{plan['name']}_sim.png" if plan["heat_map"] else None
    # the shanks keep their clearance from the design; the stock a finish leaves within the tolerance over it is
    # not a collision
    sim = simulate(results[0].job, cell=plan["sim_cell"], tolerance=plan["tolerance"], png_path=png,
                   progress=progress, body_tolerance=plan["tolerance"])
    problems = []
    if sim.gouged:
        problems.append(f"gouged {-sim.min_deviation:.4f} mm below the model (tolerance {plan['tolerance']:g} mm)")
    problems += rapid_problems(sim.collisions)
    problems += [f"{label}: {check.summary()}" for label, check in sim.holder_collisions]
    problems += [f"{label}: {found.summary()}" for label, found in sim.stock_collisions]
    failing = {c[0] for c in sim.collisions} | {label for label, _ in sim.holder_collisions + sim.stock_collisions}
    return {"passed": not problems, "problems": problems, "gouged": bool(sim.gouged), "failing_ops": sorted(failing),
            "deepest_gouge_mm": round(max(0.0, -sim.min_deviation), 4),
            "most_material_left_mm": round(sim.max_left, 4),
            "left_percentiles_mm": {str(k): round(v, 4) for k, v in sorted(sim.percentiles.items())},
            "removed_volume_mm3": round(sim.removed_volume, 1), "remaining_volume_mm3": round(sim.remaining_volume, 1),
            "cycle_seconds": round(sim.cycle_seconds, 1), "ops": op_rows(results, sim.simulation),
            "sim_cell_mm": plan["sim_cell"], "tolerance_mm": plan["tolerance"],
            "regions": rounded(dict(sorted(sim.regions.items()))), "left_in_reach": left_in_reach(sim, plan)}


def left_in_reach(sim: Any, plan: dict) -> dict:
    """The simulated Job's material left judged where the library's most reaching tool reaches with its shank and
    holder (core.plan.left_check)."""
    from tmm_workbench.core.geometry.mesh import load_stl
    from tmm_workbench.core.plan import left_check
    from tmm_workbench.core.tools.cutter import Cutter

    js, tool = sim.simulation, plan["reach_tool"]
    cutter = Cutter(tool["diameter"], tool["corner_radius"])
    # where the whole tool reaches: its shank and holder as the simulation checks them
    return left_check.left_in_reach(load_stl(plan["model_file"]), js.grid, js.design, js.comparison.deviation,
                                    tool["name"], cutter, plan["tolerance"], plan.get("cusp", 0.0),
                                    left_check.whole_tool(cutter, plan["tools"][tool["name"]]))


def rounded(value: Any) -> Any:
    """Floats to 4 decimals through dicts and lists (the report's numbers, byte-stable)."""
    if isinstance(value, float):
        return round(value, 4)
    if isinstance(value, dict):
        return {str(k): rounded(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [rounded(v) for v in value]
    return value


def run_plan(plan: dict, folder: Path, model: Any = None, progress: Any = False) -> tuple[list, dict]:
    """The plan run as one Job (run_ops), verified, its optional ops left out when they alone fail, the whole Job
    posted into `folder`: (the API results of the ops kept, the verification)."""
    from tmm_workbench.app import posts
    from tmm_workbench.core.plan import progress_note

    replanned: list = []
    results = run_ops(plan, model, progress, replanned)
    start = time.monotonic()
    report = verify(results, plan, folder, progress)
    first = time.monotonic() - start
    optional = {op["label"] for op in plan["ops"] if op.get("optional")}
    if not report["passed"] and not report["gouged"] and set(report["failing_ops"]) <= optional:
        # an optional op (a rest, a pencil) failing the verification alone is changed (core.plan.replan) and
        # verified again; one no change clears is left out, its material reported as left; a failing roughing or
        # finishing op stops the plan with the reason (exit 1)
        report = change_failing(results, plan, folder, report, replanned, first, progress)
    dropping = set(report["failing_ops"])
    if not report["passed"] and not report["gouged"] and dropping and dropping <= optional:
        replanned += [f"left out {label}: " + "; ".join(p for p in report["problems"] if p.startswith(label))
                      for label in sorted(dropping)]
        kept = [r for r in results if r.op.Label not in dropping]
        remove_unused(results[0].job, kept)
        results = kept
        report = verify(results, plan, folder, progress)
    report["replanned"] = replanned
    if plan["gcode"]:
        progress_note.note(3 + len(plan["ops"]), steps(plan), f"writing the G-code ({plan['post']})")
        objects = []
        for r in results:   # a tool controller where its tool comes in (once per tool)
            objects += [r.op] if r.op.ToolController in objects else [r.op.ToolController, r.op]
        # without the header's export time: the same plan gives the same G-code, byte for byte
        args = plan.get("post_args") or posts.DEFAULT_ARGS.get(plan["post"], "--no-show-editor") + " --no-header"
        posts.export(plan["post"], objects, folder / f"{plan['name']}.ngc", args)
    return results, report


def plan_object(model: Any, data: dict, progress: Any = True) -> tuple[Any, dict]:
    """The automatic planner on a Mesh or Part object of an open document (the GUI's TMM Auto). `data`: a job
    file's data (core.plan.recipes.job_data) with absolute paths; its model is the object's mesh, written as
    <name>_model.stl beside the outputs (with job.json, the job file that plans it again with `tmm plan`). The
    Job is made in the object's document and left there for review; the G-code, pictures and reports go to
    outputs.dir, moved in whole. A failed or cancelled run removes what it added and writes nothing.
    Returns (the Job, the report). PlanInputError: the recipe refused (its message names the field)."""
    import shutil

    from tmm_workbench.app import plan_five
    from tmm_workbench.app.geometry import mesh_from_object
    from tmm_workbench.core.geometry.mesh import save_stl
    from tmm_workbench.core.plan import five_axis, launch
    from tmm_workbench.core.plan.job_file import job_from_dict

    name, out_dir = data["outputs"]["name"], Path(data["outputs"]["dir"])
    tmp = launch.temporary_folder(out_dir, name)
    doc, before = model.Document, {o.Name for o in model.Document.Objects}
    try:
        # a Part object tessellated as a STEP model is (core.plan.launch): within a share of the tolerance
        deflection = launch.STEP_DEFLECTION_SHARE * float(data["finish"]["tolerance"])
        stl = save_stl(mesh_from_object(model, deflection), tmp / f"{name}_model.stl")
        again = dict(data, model=dict(data["model"], file=stl.name), outputs=dict(data["outputs"], dir="."))
        (tmp / "job.json").write_text(json.dumps(again, indent=1, sort_keys=True) + "\n")
        job = job_from_dict(dict(data, model=dict(data["model"], file=str(stl))), tmp / "job.json")
        mesh, _, an, plan = launch.make_plan(job)
        plan_doc = dict(launch.plan_document(job, plan, stl), fcstd=False)
        try:   # a 5-axis op that fails or does not verify: the 3-axis plan instead, as `tmm plan` does
            results, verified = plan_five.run(plan_doc, tmp, run_plan, model, progress,
                                              discard=lambda: remove_added(doc, before))
        except BaseException:
            remove_added(doc, before)
            raise
        five_axis.after_run(plan, verified)
        return results[0].job, launch.finish_outputs(tmp, job, mesh, an, plan, verified)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def remove_added(doc: Any, before: set) -> None:
    """The objects a failed run added to `doc`, removed (the newest first: an op before its Job)."""
    for name in reversed([o.Name for o in doc.Objects if o.Name not in before]):
        if doc.getObject(name) is not None:   # by name: removing a Job removes its children too (1.1)
            doc.removeObject(name)
    doc.recompute()


def main() -> int:
    sys.path.insert(0, str(REPO))
    plan_file = Path(os.environ["TMM_PLAN_FILE"])
    folder = plan_file.parent
    plan = json.loads(plan_file.read_text())
    from tmm_workbench.core.plan import progress_note

    from tmm_workbench.app import plan_five

    results, report = plan_five.run(plan, folder, run_plan)   # a 5-axis op's fallback; the tarus extras
    if plan["fcstd"]:
        progress_note.note(steps(plan), steps(plan), "saving the document")
        results[0].job.Document.saveAs(str(folder / f"{plan['name']}.FCStd"))
    (folder / "verify.json").write_text(json.dumps(report, indent=1, sort_keys=True) + "\n")
    return 0


def exit_with(run: Callable[[], int]) -> None:
    """A freecadcmd script's end: `run`'s exit code, FAILED with the traceback when it raises (freecadcmd would
    swallow the exception and exit 0)."""
    try:
        code = run()
    except BaseException:  # noqa: BLE001
        traceback.print_exc()
        code = FAILED
    sys.stdout.flush()
    sys.stderr.flush()
    raise SystemExit(code)


if __name__ in ("__main__", "plan_run"):
    exit_with(main)
