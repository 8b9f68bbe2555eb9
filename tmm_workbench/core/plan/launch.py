"""`python3 -m tmm_workbench.plan job.yaml`: the automatic planner's command (docs/planner.md).

Reads and checks the job file, places and analyses the model, decides the ops (all without FreeCAD), then starts
`freecadcmd` on app/plan_run.py to run the plan as one FreeCAD Job, post it and simulate it. Everything is made
in a temporary folder beside the output folder and moved into place only when complete (the document, the
G-code, the heat map, the tool path picture, report.json and report.html); on bad input or a failure nothing is written.

Exit codes: 0 verified, 1 verification failed (or the Job could not be made: the reason on stderr), 2 bad input.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl, save_stl
from tmm_workbench.core.plan import analysis, decide, five_axis, left_check, progress_note, recipes
from tmm_workbench.core.plan.job_file import (MODEL_SUFFIXES, UNITS, JobSpec, PlanInputError, ToolSpec, is_step,
                                              job_from_dict, read_data)
from tmm_workbench.core.plan.stock import planned_stock

VERIFIED, FAILED, BAD_INPUT = 0, 1, 2
APP_SCRIPT = Path(__file__).resolve().parents[2] / "app" / "plan_run.py"
STEP_SCRIPT = APP_SCRIPT.parent / "step_mesh.py"
STEP_DEFLECTION_SHARE = 0.5   # of the tolerance: the STEP's tessellation's chordal error (the design the Job is
#                               verified against lies within it of the solid; the rest of the tolerance is the Job's)
REPORT_FORMAT = "tmm-plan-report 1"


def say(text: str, quiet: bool) -> None:
    if not quiet:
        print(text, file=sys.stderr, flush=True)


def placed_mesh(job: JobSpec) -> tuple[TriMesh, bool]:
    """The model in mm at its place; True when it differs from the file (it is then written for FreeCAD)."""
    try:
        mesh = load_stl(job.model.file)
    except TmmError as exc:
        raise PlanInputError(f"model.file: {exc}") from None
    if len(mesh.triangles) == 0:
        raise PlanInputError(f"model.file: {job.model.file} has no triangles")
    scale = UNITS[job.model.units]
    moved = scale != 1.0 or any(job.model.translate)
    if not moved:
        return mesh, False
    vertices = mesh.vertices * scale + np.asarray(job.model.translate, dtype=float)
    return TriMesh(vertices, mesh.triangles, name=mesh.name), True


def make_plan(job: JobSpec, quiet: bool = True) -> tuple[TriMesh, bool, analysis.Analysis, decide.Plan]:
    """The placed model, whether it was moved, its analysis and the plan (core only; PlanInputError on bad input)."""
    mesh, moved = placed_mesh(job)
    stock = planned_stock(job, mesh)   # a model outside its stock refused before the analysis
    say(f"model {job.model.file.name}: {len(mesh.triangles)} triangles; analysing", quiet)
    # each tool reach-tested whole: its shank and holder as the simulation checks them
    cutters = [(t, decide.cutter_of(t)) for t in job.tools]
    tools = [(t.name, c, left_check.whole_tool(c, tool_entry(t))) for t, c in cutters]
    an = analysis.analyse(mesh, job.planner.analysis_cell, tools, job.finish.tolerance)
    compare = None
    if job.planner.compare_cutters:
        from tmm_workbench.core.plan.optimal_cutter import compare_cutters

        rapid = None if job.machine.rapid is None else tuple(r / 60.0 for r in job.machine.rapid)
        compare = partial(compare_cutters, sample_step=0.5, cell=job.planner.sim_cell,
                          tolerance=job.finish.tolerance, rapid=rapid)   # the machine's rapids: its cycle times
        say("comparing the finishing cutters (seed 003)", quiet)
    plan = decide.plan_job(job, mesh, an, compare, stock)
    if job.machine.five_axis:
        say("timing 5-axis finishing against the 3-axis raster (Tarus)", quiet)
        plan.five_axis = five_axis.consider(job, mesh, an, plan)
    return mesh, moved, an, plan


def tool_entry(tool: ToolSpec) -> dict:
    """A library tool's lengths, shank and holder (core.plan.left_check.whole_tool's spec)."""
    return {"flute_length": tool.flute_length, "length": decide.overall_length(tool),
            "shank_diameter": tool.shank_diameter, "holder": tool.holder, "stick_out": tool.stick_out}


def plan_document(job: JobSpec, plan: decide.Plan, model_file: Path) -> dict:
    """What app/plan_run.py needs to run the plan."""
    o = job.outputs
    reach = next(t for t in job.tools if t.name == plan.reach_tool)
    rapid = job.machine.rapid
    return {"model_file": str(model_file), "name": o.name, "post": job.machine.post, "gcode": o.gcode,
            "fcstd": o.fcstd, "heat_map": o.heat_map, "sim_cell": job.planner.sim_cell,
            "tolerance": job.finish.tolerance, "cusp": job.finish.cusp, "ops": [op.as_dict() for op in plan.ops],
            "stock": plan.stock.as_dict(),
            "rapid_mm_min": None if rapid is None else list(rapid), "apt_cl": o.apt_cl,
            "post_args": TARUS_POST_ARGS if job.machine.five_axis else None,
            "five_axis": None if plan.five_axis is None else plan.five_axis.as_dict(),
            "tools": {t.name: tool_entry(t) for t in job.tools},
            "reach_tool": {"name": plan.reach_tool, "diameter": reach.diameter, "corner_radius": reach.corner_radius}}


def tessellate_step(job: JobSpec, folder: Path, freecad: str, quiet: bool) -> JobSpec:
    """The job with its STEP model tessellated by FreeCAD (app/step_mesh.py) into `folder`/<name>_model.stl, the
    chordal deflection STEP_DEFLECTION_SHARE of the tolerance. PlanInputError: FreeCAD cannot read it; TmmError:
    FreeCAD could not be run or failed otherwise."""
    stl = tessellate(job.model.file, folder / f"{job.outputs.name}_model.stl", job.finish.tolerance, freecad,
                     quiet, "model.file")
    return replace(job, model=replace(job.model, file=stl))


def tessellate_stock(job: JobSpec, folder: Path, freecad: str, quiet: bool) -> JobSpec:
    """The job with its STEP stock tessellated as a STEP model is (`stock.mesh_file`: what the core checks the
    model against; the FreeCAD Job's stock is the STEP's exact solid)."""
    stl = tessellate(job.stock.file, folder / STOCK_MESH, job.finish.tolerance, freecad, quiet, "stock.file",
                     solid=True)
    return replace(job, stock=replace(job.stock, mesh_file=stl))


TARUS_POST_ARGS = "--no-show-editor"   # the tarus post writes no date (it has no --no-header)
TIP_GCODE = "tip.ngc"   # a tarus Job's G-code in tool-tip coordinates (--tcp), for the picture (removed after)
STOCK_MESH = "stock_mesh.stl"   # a STEP stock's tessellation in the run's folder (removed before the outputs)


def tessellate(step: Path, stl: Path, tolerance: float, freecad: str, quiet: bool, where: str,
               solid: bool = False) -> Path:
    """`step` tessellated by FreeCAD (app/step_mesh.py) into `stl` within STEP_DEFLECTION_SHARE of `tolerance`.
    PlanInputError naming `where`: FreeCAD cannot read it (or, `solid`, it holds no solid); TmmError: FreeCAD
    could not be run or failed."""
    deflection = round(STEP_DEFLECTION_SHARE * tolerance, 6)
    say(f"tessellating {step.name} within {deflection:g} mm (FreeCAD)", quiet)
    env = dict(os.environ, TMM_STEP_FILE=str(step), TMM_STEP_STL=str(stl), TMM_STEP_DEFLECTION=repr(deflection),
               TMM_STEP_SOLID="1" if solid else "0")
    try:
        proc = subprocess.run([freecad, str(STEP_SCRIPT)], env=env, cwd=str(stl.parent), capture_output=True, text=True)
    except OSError as exc:
        raise TmmError(f"could not start {freecad}: {exc}") from None
    tail = "\n".join((proc.stderr or proc.stdout or "").strip().splitlines()[-6:])
    if proc.returncode == 2:
        raise PlanInputError(f"{where}: {tail}")
    if proc.returncode != 0 or not stl.is_file():
        raise TmmError(f"the STEP tessellation failed (exit {proc.returncode}):\n{tail}")
    return stl


def run_freecad(folder: Path, freecad: str, quiet: bool) -> Optional[str]:
    """Runs the plan in `folder` under freecadcmd; None when it ran, else the reason it did not."""
    env = dict(os.environ, TMM_PLAN_FILE=str(folder / "plan.json"))
    try:
        proc = subprocess.run([freecad, str(APP_SCRIPT)], env=env, cwd=str(folder), capture_output=True, text=True)
    except OSError as exc:
        return f"could not start {freecad}: {exc}"
    if proc.returncode != 0 or not (folder / "verify.json").is_file():
        tail = "\n".join((proc.stderr or proc.stdout or "").strip().splitlines()[-12:])
        return f"the FreeCAD run failed (exit {proc.returncode}):\n{tail}"
    say("FreeCAD run done", quiet)
    return None


def report(job: JobSpec, an: analysis.Analysis, plan: decide.Plan, verified: dict, files: list) -> dict:
    return {"format": REPORT_FORMAT, "job_file": job.source.name, "passed": verified["passed"],
            "problems": verified["problems"], "verification": verified, "analysis": an.as_dict(),
            "plan": plan.as_dict(), "finish": {"cusp_mm": job.finish.cusp, "tolerance_mm": job.finish.tolerance},
            "stock": plan.stock.as_dict() | {"file": None if job.stock.file is None else job.stock.file.name},
            "material": job.material, "machine": machine_row(job),
            "tools": [tool_row(t) for t in job.tools], "notes": list(job.notes), "files": sorted(files)}


def machine_row(job: JobSpec) -> dict:
    m = job.machine
    row = {"type": m.type, "post": m.post, "travels_mm": list(m.travels),
           "rapid_mm_min": None if m.rapid is None else list(m.rapid)}
    return row | ({"tilt_limit_deg": m.tilt_limit} if m.five_axis else {})


def tool_row(tool: ToolSpec) -> dict:
    """A library tool for the setup sheet; its stick-out the job's, or the API's (the ToolBit's length less the
    grip) when the job gives none."""
    stick = tool.stick_out if tool.stick_out is not None else \
        decide.overall_length(tool) - decide.GRIP_DIAMETERS * tool.diameter
    return {"name": tool.name, "type": tool.type, "diameter": tool.diameter, "corner_radius": tool.corner_radius,
            "flutes": tool.flutes, "flute_length": tool.flute_length, "shank_diameter": tool.shank_diameter,
            "length": decide.overall_length(tool), "holder": tool.holder,
            "stick_out_mm": round(stick, 4)}


def draw_toolpath(mesh: TriMesh, gcode: Path, png: Path, name: Optional[str] = None) -> None:
    """The whole Job's G-code read back and drawn over the model (core.preview.toolpath_png); `name` the title's
    file name (the G-code's own by default)."""
    from tmm_workbench.core.preview.toolpath_png import render_toolpath_png, toolpath_of_gcode

    toolpath = toolpath_of_gcode(gcode.read_text(errors="replace"))
    render_toolpath_png(mesh, toolpath, str(png), title=f"the tool path: {name or gcode.name}", size_px=(1400, 650))


def write_pages(tmp: Path, job: JobSpec, doc: dict) -> None:
    """report.json and report.html (with the heat map and the tool path picture, drawn here) into `tmp`."""
    from tmm_workbench.core.plan.report_html import report_html

    name = job.outputs.name
    pictures = {kind: tmp / f"{name}_{kind}.png" for kind in ("sim", "toolpath")}
    (tmp / "report.json").write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
    html = report_html(doc, name, *(p.read_bytes() if p.is_file() else None for p in pictures.values()))
    (tmp / "report.html").write_text(html, encoding="utf-8")


def finish_outputs(tmp: Path, job: JobSpec, mesh: TriMesh, an: analysis.Analysis, plan: decide.Plan,
                   verified: dict, quiet: bool = True) -> dict:
    """After the FreeCAD side wrote its files into `tmp`: the tool path picture, report.json and report.html, all
    moved into the job's outputs.dir. Returns the report."""
    out = job.outputs
    gcode, tip = tmp / f"{out.name}.ngc", tmp / TIP_GCODE   # the Tarus's joints drawn at the tool tip
    if gcode.is_file():
        say("drawing the tool path", quiet)
        draw_toolpath(mesh, tip if tip.is_file() else gcode, tmp / f"{out.name}_toolpath.png",
                      f"{gcode.name}" + (" (the tool tip: the same program in TCP mode)" if tip.is_file() else ""))
    if tip.is_file():
        tip.unlink()
    files = sorted(f.name for f in tmp.iterdir()) + ["report.html", "report.json"]
    doc = report(job, an, plan, verified, files)
    write_pages(tmp, job, doc)
    move_into_place(tmp, out.dir)
    return doc


def temporary_folder(out_dir: Path, name: str) -> Path:
    """Where a run's files are made: a new hidden folder beside `out_dir` (the same file system: moved whole)."""
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=f".{name}.", dir=str(out_dir.parent)))


def move_into_place(tmp: Path, target: Path) -> list:
    """The finished files from `tmp` into `target` (created), replacing files of the same name."""
    target.mkdir(parents=True, exist_ok=True)
    names = []
    for f in sorted(tmp.iterdir()):
        os.replace(f, target / f.name)
        names.append(f.name)
    return names


def job_of(job_path: str, overrides: Sequence[tuple[tuple[str, ...], Any]] = (), out_dir: Optional[str] = None
           ) -> tuple[JobSpec, Optional[dict]]:
    """The checked job of a job file, or of a model file (.stl, .step, .stp) planned with the default recipe
    (core.plan.recipes.default_job, into <stem>_plan in the current folder); `overrides` (a field's path, its value)
    set in its data, `out_dir` in place of outputs.dir. Returns the job and, for the default recipe, the data of
    the job file that plans it again (written as job.json beside the outputs)."""
    path = Path(job_path)
    recipe = path.suffix.lower() in MODEL_SUFFIXES
    if recipe:
        data = recipes.default_job(str(path.resolve()), str(Path.cwd() / f"{path.stem}_plan"))
    else:
        data = read_data(path)
    for keys, value in overrides:
        if not isinstance(data, dict) or len(keys) > 1 and not isinstance(data.get(keys[0], {}), dict):
            break   # job_from_dict names what is wrong with the file
        section = data.setdefault(keys[0], {}) if len(keys) > 1 else data
        section[keys[-1]] = value
    if out_dir is not None and isinstance(data, dict) and isinstance(data.get("outputs"), dict):
        data["outputs"]["dir"] = str(Path(out_dir).resolve())
    job = job_from_dict(data, Path.cwd() / "job.json" if recipe else path)
    return job, dict(data, outputs=dict(data["outputs"], dir=".")) if recipe else None


def run(job_path: str, freecad: str = "freecadcmd", quiet: bool = False, out_dir: Optional[str] = None,
        overrides: Sequence[tuple[tuple[str, ...], Any]] = ()) -> int:
    """Plans, runs and verifies the job (a job file, or a model with the default recipe: job_of); `out_dir` in
    place of the job file's outputs.dir (a batch's part folder)."""
    t0 = time.perf_counter()
    tmp: Optional[Path] = None
    try:
        job, again = job_of(job_path, overrides, out_dir)
        progress_note.note(1, 0, "analysing the model and planning")
        job, tmp = tessellated(job, freecad, quiet)
        mesh, moved, an, plan = make_plan(job, quiet)
        if job.stock.mesh_file is not None:
            job.stock.mesh_file.unlink()
    except (PlanInputError, TmmError) as exc:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        bad = isinstance(exc, PlanInputError)
        print(f"tmm plan: {'bad input: ' if bad else ''}{exc}", file=sys.stderr)
        return BAD_INPUT if bad else FAILED
    say(f"planned {len(plan.ops)} ops in {time.perf_counter() - t0:.1f} s: "
        + ", ".join(op.label for op in plan.ops), quiet)
    out = job.outputs
    tmp = tmp or temporary_folder(out.dir, out.name)
    try:
        model_file = job.model.file
        if moved:
            model_file = tmp / f"{out.name}_model.stl"
            save_stl(mesh, model_file)
        if again is not None:
            (tmp / "job.json").write_text(json.dumps(again, indent=1, sort_keys=True) + "\n")
        (tmp / "plan.json").write_text(json.dumps(plan_document(job, plan, model_file), indent=1, sort_keys=True))
        failure = run_freecad(tmp, freecad, quiet)
        if failure is not None:
            print(f"tmm plan: {failure}", file=sys.stderr)
            return FAILED
        verified = json.loads((tmp / "verify.json").read_text())
        five_axis.after_run(plan, verified)   # the fallback, or the built op's time beside the estimate
        for name in ("plan.json", "verify.json"):
            (tmp / name).unlink()
        finish_outputs(tmp, job, mesh, an, plan, verified, quiet)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    say_outcome(verified, out.dir, time.perf_counter() - t0, quiet)
    return VERIFIED if verified["passed"] else FAILED


def outcome_lines(verified: dict, ops: bool = False) -> list[str]:
    """A run's outcome for people (the terminal's last lines, TMM Auto's result box): what the run changed in the
    plan (a 5-axis op's fallback, an optional op changed or left out), the verdict with the numbers, and with
    `ops` each op's cycle time."""
    lines = [f"plan changed: {change}" for change in verified.get("replanned", [])]
    state = "verified" if verified["passed"] else "verification FAILED: " + "; ".join(verified["problems"])
    lines.append(f"{state}; deepest gouge {verified['deepest_gouge_mm']:g} mm, most left "
                 f"{verified['most_material_left_mm']:g} mm, cycle {verified['cycle_seconds'] / 60:.1f} min")
    if ops:
        lines += [f"  {o['label']}: {o['cycle_seconds']:g} s" for o in verified["ops"]]
    return lines


def say_outcome(verified: dict, out_dir: Path, seconds: float, quiet: bool) -> None:
    lines = outcome_lines(verified)
    for line in lines[:-1]:
        say(line, quiet)
    say(f"{lines[-1]}; written to {out_dir} ({seconds:.0f} s)", quiet)


def tessellated(job: JobSpec, freecad: str, quiet: bool) -> tuple[JobSpec, Optional[Path]]:
    """The job with its STEP model and its STEP stock tessellated by FreeCAD in a temporary folder beside the
    outputs (the run's), and that folder; the job and None when neither is a STEP."""
    model, stock = is_step(job.model.file), job.stock.type == "solid" and is_step(job.stock.file)
    if not (model or stock):
        return job, None
    tmp = temporary_folder(job.outputs.dir, job.outputs.name)
    try:
        if model:
            job = tessellate_step(job, tmp, freecad, quiet)
        if stock:
            job = tessellate_stock(job, tmp, freecad, quiet)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return job, tmp


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m tmm_workbench.plan",
                                 description="Plans, runs and verifies a Job from a job file (docs/planner.md).")
    ap.add_argument("job", help="the job file (.yaml, .yml or .json), or a model (.stl, .step, .stp) planned with "
                    "the default recipe (docs/planner.md)")
    ap.add_argument("--freecad", default=os.environ.get("TMM_FREECADCMD", "freecadcmd"),
                    help="the freecadcmd to run (default: $TMM_FREECADCMD or freecadcmd)")
    ap.add_argument("--quiet", action="store_true", help="no progress lines (errors only)")
    ap.add_argument("--out", default=None, help="the folder for the outputs, in place of the job file's outputs.dir")
    for flag, keys, kind, text in OVERRIDES:
        ap.add_argument(flag, type=kind, default=None, help=f"{text}, in place of the job's {'.'.join(keys)}")
    args = ap.parse_args(argv)
    overrides = [(keys, getattr(args, flag[2:])) for flag, keys, _, _ in OVERRIDES
                 if getattr(args, flag[2:]) is not None]
    return run(args.job, args.freecad, args.quiet, args.out, overrides)


def _absolute(path: str) -> str:
    return str(Path(path).resolve())


# the command's options that change a job's field (a job file's or the default recipe's)
OVERRIDES = (("--cusp", ("finish", "cusp"), float, "the scallop height, mm"),
             ("--tolerance", ("finish", "tolerance"), float, "the verification's tolerance, mm"),
             ("--material", ("material",), str, "the material of the speeds and feeds table"),
             ("--tools", ("tools",), _absolute, "a tools file (YAML, JSON) or a FreeCAD tool library (.fctl)"),
             ("--margin", ("stock", "margin"), float, "the stock beyond the model on each side, mm"),
             ("--name", ("outputs", "name"), str, "the outputs' file name"))
