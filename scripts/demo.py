"""TMM's main job, headless: three models finished with a 3-axis surface raster, a block roughed down to
sphere_on_plate and its walls finished by waterline (one Job), sphere_on_plate finished with a ball D10 and its
rest taken by a ball D3 (one Job), seed 003's sign planned with no operator (tmm plan), seed 001's convex Bézier
patch finished 5-axis by multipoint positioning (tarus G-code, APT CL, document, pictures), and seed 000's convex
surface as a mesh finished 5-axis by the 3D C-space method (scripts/demo_mesh5.py).

    freecadcmd scripts/demo.py            # G-code (.ngc), FreeCAD document (.FCStd) and picture (.png)
    /usr/bin/python3 scripts/demo.py      # without FreeCAD: the core alone, pictures only

Inputs: the OpenCAMLib meshes sphere_on_plate.stl (ball cutter) and mount_rush.stl (bull-nose cutter)
from shared/benchmarks/stl, and the convex bicubic Bézier patch of seed 001 tessellated (the seed's
toroidal cutter). Output folder: $TMM_OUT, default <repo>/out. Exit code 1 on any failure (freecadcmd
itself returns 0 even when a script raises, so the script exits explicitly).
"""
from __future__ import annotations

import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

# freecadcmd runs this file with __name__ == "demo" (the file's stem) and sets __file__.
REPO = Path(globals().get("__file__") or sys.argv[0]).resolve().parents[1]
# chordal tolerance of the patch tessellation: the paths hold ChordTolerance 0.001 mm to the mesh, so the mesh is
# as close to the design (at 0.01 mm the path followed facets 10x its tolerance off the patch; docs/results.md)
BEZIER_TOLERANCE_MM = 0.001


@dataclass
class Case:
    name: str
    what: str                                            # shown in the table and the picture title
    model: str = ""                                      # STL path (filled in for the Bézier patch)
    params: dict[str, Any] = field(default_factory=dict)  # keyword arguments of run_surface


def bench() -> Path:
    """shared/benchmarks (core.shared_data finds it; main() has put the repository on sys.path)."""
    from tmm_workbench.core.shared_data import shared_dir

    return shared_dir() / "benchmarks"


def cases(out: Path) -> list[Case]:
    """One case per input, parameters chosen from each model's size (mm) for a ~1 minute demo."""
    return [
        # 76 x 76 x 32 mm: a half sphere on a plate; ball D6, 0.5 mm step-over (scallop ~0.01 mm).
        Case("sphere_on_plate", "sphere_on_plate.stl", str(bench() / "stl" / "sphere_on_plate.stl"),
             dict(tool="ballend", diameter=6.0, stepover=0.5, sample_step=0.25, angle_deg=0.0)),
        # 86 x 43 x 27 mm relief without a base: small bull-nose for the faces' detail, passes along the
        # long side, lifting over the corners of the box where no part of the relief is under the tool.
        Case("mount_rush", "mount_rush.stl", str(bench() / "stl" / "mount_rush.stl"),
             dict(tool="bullnose", diameter=4.0, corner_radius=1.0, stepover=0.3, sample_step=0.2,
                  angle_deg=0.0, off_model="skip")),
        # 150 x 150 mm patch: seed 001's toroidal cutter (Ro 6.7 + Ri 6.0 -> D25.4 r6), feed along Y
        # as in the paper; a 3-axis step-over (scallop ~0.02 mm) instead of the paper's 5-axis 18 mm.
        Case("bezier_convex", f"seed 001 convex Bezier, tol {BEZIER_TOLERANCE_MM:g} mm", "",
             dict(tool="bullnose", diameter=25.4, corner_radius=6.0, stepover=1.0, sample_step=0.5,
                  angle_deg=90.0)),
    ]


def bezier_stl(out: Path) -> Path:
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.geometry.mesh import save_stl

    net = bezier.load_seed_patch(bench() / "seed_surfaces.json", "convex")
    mesh = bezier.tessellate_to_tolerance(net, BEZIER_TOLERANCE_MM, name="bezier_convex")
    path = out / "bezier_convex.stl"
    save_stl(mesh, path)
    return path


def run_freecad(case: Case, out: Path) -> dict[str, Any]:
    """The headless API: Job, operation, G-code and document, as a macro would do it."""
    import FreeCAD
    from tmm_workbench.app.api import run_surface

    t0 = time.perf_counter()
    res = run_surface(case.model, gcode_path=str(out / f"{case.name}.ngc"),
                      fcstd_path=str(out / f"{case.name}.FCStd"), doc_name=case.name, **case.params)
    dt = time.perf_counter() - t0
    row = dict(mesh=res.mesh, toolpath=res.toolpath, seconds=dt,
               files=[out / f"{case.name}.ngc", out / f"{case.name}.FCStd"])
    row["sim"] = simulate_case(res, out / f"{case.name}_sim.png", SIM_CELL_MM)
    row["files"].append(out / f"{case.name}_sim.png")
    try:
        FreeCAD.closeDocument(res.doc.Name)  # saved already; keep memory flat across cases
    except Exception:  # noqa: BLE001 - closing is a courtesy, never a failure
        pass
    return row


SIM_CELL_MM = 0.1      # 3-axis simulation cells (the demo's step-overs are 0.3-1 mm)
SIM_CELL_5AXIS_MM = 0.25


UNSAFE: list[str] = []  # simulated gouges and rapids into stock, any of which fails the main job


def simulate_case(result: Any, png: Path, cell: float) -> dict[str, Any]:
    """The Job's stock cut by its op and compared with its model (api.simulate), with the heat map."""
    from tmm_workbench.app.api import simulate

    t0 = time.perf_counter()
    rep = simulate(result, cell=cell, tolerance=0.01, png_path=png, progress=False)
    if rep.gouged or rep.collisions:  # a path a machine must not run: the main job fails (after its files)
        UNSAFE.append(f"{png.stem}: {'gouged ' if rep.gouged else ''}{len(rep.collisions)} rapid collisions")
    return dict(max_left=rep.max_left, min_dev=rep.min_deviation, p95=rep.percentiles[95], gouged=rep.gouged,
                collisions=len(rep.collisions), cycle=rep.cycle_seconds, seconds=time.perf_counter() - t0)


def print_files(files: list[Path]) -> None:
    """Each file written with its size (MISSING when it is not there)."""
    for f in files:
        size = f.stat().st_size if f.exists() else -1
        print(f"  {f}  ({size / 1024:.0f} KiB)" if size >= 0 else f"  {f}  (MISSING)")


def sim_line(name: str, sim: dict[str, Any]) -> str:
    verdict = "GOUGED" if sim["gouged"] else "no gouge"
    return (f"{name:<16} max left {sim['max_left']:.4f} mm, min {sim['min_dev']:+.4f} mm, p95 {sim['p95']:.4f} mm, "
            f"{verdict}, {sim['collisions']} rapid collisions, cycle {sim['cycle'] / 60:.1f} min, "
            f"simulated in {sim['seconds']:.1f} s")


def run_core(case: Case, out: Path) -> dict[str, Any]:
    """Without FreeCAD: the same raster from the core, for the picture only."""
    from tmm_workbench.core.tools.cutter import Cutter
    from tmm_workbench.core.geometry.mesh import load_stl
    from tmm_workbench.core.linking import LinkPolicy
    from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath

    p = case.params
    cutter = {"ballend": lambda: Cutter.ball(p["diameter"]),
              "endmill": lambda: Cutter.flat(p["diameter"]),
              "bullnose": lambda: Cutter.bull(p["diameter"], p["corner_radius"])}[p["tool"]]()
    t0 = time.perf_counter()
    mesh = load_stl(case.model)
    lo, hi = mesh.bounds
    params = SurfaceParams(boundary=(lo[0], lo[1], hi[0], hi[1]), stepover=p["stepover"],
                           sample_step=p["sample_step"], angle_deg=p.get("angle_deg", 0.0),
                           off_model=p.get("off_model", "floor"))
    tp = compute_surface_toolpath(mesh, cutter, params, LinkPolicy(float(hi[2]) + 5, float(hi[2]) + 15))
    return dict(mesh=mesh, toolpath=tp, seconds=time.perf_counter() - t0, files=[])


def describe_tool(p: dict[str, Any]) -> str:
    if p["tool"] == "ballend":
        return f"ball D{p['diameter']:g}"
    if p["tool"] == "bullnose":
        return f"bull-nose D{p['diameter']:g} r{p['corner_radius']:g}"
    return f"{p['tool']} D{p['diameter']:g}"


def main() -> None:
    sys.path.insert(0, str(REPO))
    sys.path.insert(0, str(REPO / "scripts"))
    from tmm_workbench.core.preview.toolpath_png import path_statistics, render_toolpath_png

    out = Path(os.environ.get("TMM_OUT") or REPO / "out").resolve()
    out.mkdir(parents=True, exist_ok=True)
    try:
        import FreeCAD
        with_freecad = True
        mode = "FreeCAD " + ".".join(FreeCAD.Version()[:3])
    except ImportError:
        with_freecad = False
        mode = "core only (no FreeCAD: pictures, no G-code)"
    print(f"TMM demo with {mode}; output in {out}", flush=True)

    rows = []
    t_all = time.perf_counter()
    for case in cases(out):
        written = []
        if not case.model:
            case.model = str(bezier_stl(out))
            written.append(Path(case.model))
        print(f"--- {case.name}: {case.what}, {describe_tool(case.params)}, step-over "
              f"{case.params['stepover']:g} mm", flush=True)
        row = (run_freecad if with_freecad else run_core)(case, out)
        stats = path_statistics(row["toolpath"])
        png = out / f"{case.name}.png"
        t0 = time.perf_counter()
        p = case.params
        render_toolpath_png(row["mesh"], row["toolpath"], str(png),
                            title=f"TMM 3-axis surface: {case.what} - {describe_tool(p)}, step-over "
                                  f"{p['stepover']:g} mm, sample {p['sample_step']:g} mm, "
                                  f"angle {p.get('angle_deg', 0):g} deg")
        row["files"] = written + row["files"]
        row.update(name=case.name, png=png, png_seconds=time.perf_counter() - t0, stats=stats,
                   tool=describe_tool(p))
        rows.append(row)

    print_table(rows, time.perf_counter() - t_all)

    # stock to part: a block roughed down to sphere_on_plate, its walls finished by waterline, one Job
    t_r = time.perf_counter()
    print_rough_finish(run_rough_finish_case(out, with_freecad), time.perf_counter() - t_r)

    # rest: what a ball D10 leaves in sphere_on_plate's fillet, taken off by a ball D3 in the same Job
    if with_freecad:
        t_rest = time.perf_counter()
        print_rest(run_rest_case(out), time.perf_counter() - t_rest)

    # planned with no operator: seed 003's sign, made from its text, planned from its job file (tmm plan)
    t_p = time.perf_counter()
    print_planned(run_planned_case(out), time.perf_counter() - t_p)

    # 5-axis part: seed 001's convex patch, multipoint positioning (the 3-axis part above is unchanged)
    t5 = time.perf_counter()
    row5 = run_multipoint_case(out, with_freecad)
    print_table5(row5, time.perf_counter() - t5)

    # 5-axis on a mesh: seed 000's convex surface, the 3D C-space method, Tarus G-code
    from demo_mesh5 import print_mesh5, run_mesh5_case

    t_m5 = time.perf_counter()
    print_mesh5(run_mesh5_case(out, with_freecad, simulate_case), time.perf_counter() - t_m5, sim_line, print_files)


# --- stock to part ----------------------------------------------------------------------------------
RF_NAME = "rough_finish"
# A block 1 mm beyond the model on the sides and on top; bull-nose D10 r1 roughing 3 mm layers at 45 %
# step-over leaving 0.5 mm, then a ball D6 waterline every 0.5 mm over the walls (stock to leave 0).
RF_ROUGH = dict(tool="bullnose", diameter=10.0, corner_radius=1.0, step_down=3.0, stepover_percent=45.0,
                stock_to_leave=0.5, entry="helix")
RF_WATER = dict(tool="ballend", diameter=6.0, step_down=0.5)


def run_rough_finish_case(out: Path, with_freecad: bool) -> dict[str, Any]:
    """Z-level roughing then waterline finishing of sphere_on_plate.stl in one Job (run_roughing, then
    run_waterline with job=), both posted; the Job simulated (heat map) and both paths drawn. Without FreeCAD
    the core strategies give the pictures of the paths."""
    from tmm_workbench.core.preview.toolpath_png import render_toolpath_png

    model = str(bench() / "stl" / "sphere_on_plate.stl")
    print(f"--- {RF_NAME}: sphere_on_plate.stl from a block: roughing {describe_tool(RF_ROUGH)}, step-down "
          f"{RF_ROUGH['step_down']:g} mm, step-over {RF_ROUGH['stepover_percent']:g} %, stock to leave "
          f"{RF_ROUGH['stock_to_leave']:g} mm; waterline {describe_tool(RF_WATER)}, step-down "
          f"{RF_WATER['step_down']:g} mm", flush=True)
    files: list[Path] = []
    t0 = time.perf_counter()
    if with_freecad:
        import FreeCAD
        from tmm_workbench.app.api import run_roughing, run_waterline

        rough = run_roughing(model, gcode_path=str(out / f"{RF_NAME}_roughing.ngc"), doc_name=RF_NAME,
                             progress=False, **RF_ROUGH)
        t1 = time.perf_counter()
        water = run_waterline(None, job=rough, gcode_path=str(out / f"{RF_NAME}_waterline.ngc"),
                              fcstd_path=str(out / f"{RF_NAME}.FCStd"), progress=False, **RF_WATER)
        t2 = time.perf_counter()
        files += [out / f"{RF_NAME}_roughing.ngc", out / f"{RF_NAME}_waterline.ngc", out / f"{RF_NAME}.FCStd"]
        mesh, paths = rough.mesh, (rough.toolpath, water.toolpath)
        sim = simulate_case(water, out / f"{RF_NAME}_sim.png", 0.2)
        files.append(out / f"{RF_NAME}_sim.png")
        seconds = (t1 - t0, t2 - t1)
        try:
            FreeCAD.closeDocument(rough.doc.Name)
        except Exception:  # noqa: BLE001 - closing is a courtesy
            pass
    else:
        from tmm_workbench.core.geometry.mesh import load_stl
        from tmm_workbench.core.linking import LinkPolicy, link
        from tmm_workbench.core.strategies import waterline, zlevel_rough
        from tmm_workbench.core.tools.cutter import Cutter

        mesh = load_stl(model)
        lo, hi = mesh.bounds
        top = float(hi[2]) + 1.0
        policy = LinkPolicy(top + 5.0, top + 10.0)
        rough_params = zlevel_rough.RoughingParams(
            stock_box=(lo[0] - 1, lo[1] - 1, lo[2] - 1, hi[0] + 1, hi[1] + 1, top),
            step_down=RF_ROUGH["step_down"], stepover_percent=RF_ROUGH["stepover_percent"],
            stock_to_leave=RF_ROUGH["stock_to_leave"])
        rough_tp = zlevel_rough.compute_roughing_toolpath(mesh, Cutter.bull(10.0, 1.0), rough_params, policy)
        t1 = time.perf_counter()
        ball = Cutter.ball(RF_WATER["diameter"])
        r = ball.radius
        water_params = waterline.WaterlineParams(boundary=(lo[0] - r, lo[1] - r, hi[0] + r, hi[1] + r),
                                                 step_down=RF_WATER["step_down"])
        water_tp = link(waterline.compute(mesh, ball, water_params).segments, policy)
        paths, sim, seconds = (rough_tp, water_tp), None, (t1 - t0, time.perf_counter() - t1)
    for kind, tp, what in (("roughing", paths[0], f"z-level roughing, {describe_tool(RF_ROUGH)}"),
                           ("waterline", paths[1], f"waterline finishing, {describe_tool(RF_WATER)}")):
        png = out / f"{RF_NAME}_{kind}.png"
        render_toolpath_png(mesh, tp, str(png), title=f"TMM {what}: sphere_on_plate.stl from a block")
        files.append(png)
    return dict(name=RF_NAME, moves=(len(paths[0]), len(paths[1])), seconds=seconds, sim=sim, files=files)


def print_rough_finish(r: dict[str, Any], total: float) -> None:
    print(f"\n{'case (stock to part)':<22} {'roughing moves':>14} {'roughing s':>10} {'waterline moves':>15} "
          f"{'waterline s':>11}")
    print(f"{r['name']:<22} {r['moves'][0]:>14} {r['seconds'][0]:>10.2f} {r['moves'][1]:>15} {r['seconds'][1]:>11.2f}")
    if r.get("sim"):
        print("simulated (roughing + waterline; shallow areas keep the roughing's 0.5 mm): "
              + sim_line(r["name"], r["sim"]))
    print("written (stock to part):")
    print_files(r["files"])
    print(f"stock to part {total:.1f} s", flush=True)


# --- planned by the automatic planner ---------------------------------------------------------------------
PLAN_NAME = "sign_planned"


def run_planned_case(out: Path) -> dict[str, Any]:
    """A sign of seed 003 (core.geometry.sign) planned, run and verified by `python3 -m tmm_workbench.plan` from a
    job file naming only the model, the stock margin, the machine, the library, the material and the finish."""
    import json
    import subprocess

    import yaml
    from tmm_workbench.core.geometry.mesh import save_stl
    from tmm_workbench.core.geometry.sign import SignSpec, make_sign

    folder = out / PLAN_NAME
    folder.mkdir(parents=True, exist_ok=True)
    model = save_stl(make_sign(SignSpec("TMM 2026", width=100, height=50, cell=0.4)).mesh, folder / "sign.stl")
    job = yaml.safe_load((REPO / "benchmarks" / "jobs" / "beet.yaml").read_text())
    job.update(model={"file": str(model), "units": "mm"}, tools=str(REPO / "benchmarks" / "jobs" / "shop_tools.yaml"),
               finish={"cusp": 0.05, "tolerance": 0.01}, outputs={"dir": str(folder), "name": PLAN_NAME})
    job_file = folder / "job.yaml"
    job_file.write_text(yaml.safe_dump(job))
    proc = subprocess.run(["/usr/bin/python3", "-m", "tmm_workbench.plan", str(job_file), "--quiet"], cwd=REPO,
                          capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(REPO)))
    report = folder / "report.json"
    if proc.returncode not in (0, 1) or not report.is_file():
        raise RuntimeError(f"tmm plan failed (exit {proc.returncode}): {proc.stderr.strip()[-800:]}")
    rep = json.loads(report.read_text())
    return dict(name=PLAN_NAME, exit=proc.returncode, report=rep,
                files=[job_file, model] + [folder / f for f in rep["files"]])


def print_planned(r: dict[str, Any], total: float) -> None:
    rep, v = r["report"], r["report"]["verification"]
    print(f"\n--- {r['name']}: seed 003's sign planned with no operator (tmm plan, exit {r['exit']}): "
          f"{'verified' if rep['passed'] else 'NOT verified: ' + '; '.join(rep['problems'])}")
    for d in rep["plan"]["decisions"]:
        print(f"  {d['topic']}: {d['choice']}")
    print(f"  deepest gouge {v['deepest_gouge_mm']:g} mm, cycle {v['cycle_seconds'] / 60:.1f} min")
    print("written (planned):")
    print_files(r["files"])
    print(f"planned part {total:.1f} s", flush=True)


# --- rest -----------------------------------------------------------------------------------------------
REST_NAME = "rest_finish"
REST_FINISH = dict(tool="ballend", diameter=10.0, stepover=0.6, sample_step=0.25, boundary="model")
REST_SMALL = dict(tool="ballend", diameter=3.0, stepover=0.3, sample_step=0.25, boundary="model", region="rest")


def run_rest_case(out: Path) -> dict[str, Any]:
    """sphere_on_plate.stl finished with a ball D10, then a ball D3 only where the D10 left more than 0.01 mm
    that the D3 reaches (Region Rest, app.rest_source) in the same Job; both posted, the Job simulated."""
    import FreeCAD
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.core.preview.toolpath_png import render_toolpath_png

    model = str(bench() / "stl" / "sphere_on_plate.stl")
    print(f"--- {REST_NAME}: sphere_on_plate.stl, {describe_tool(REST_FINISH)} finish then {describe_tool(REST_SMALL)}"
          f" rest", flush=True)
    t0 = time.perf_counter()
    big = run_surface(model, gcode_path=str(out / f"{REST_NAME}_d10.ngc"), doc_name=REST_NAME, progress=False,
                      **REST_FINISH)
    small = run_surface(None, job=big, gcode_path=str(out / f"{REST_NAME}_d3.ngc"),
                        fcstd_path=str(out / f"{REST_NAME}.FCStd"), progress=False, **REST_SMALL)
    seconds = time.perf_counter() - t0
    files = [out / f"{REST_NAME}_d10.ngc", out / f"{REST_NAME}_d3.ngc", out / f"{REST_NAME}.FCStd"]
    png = out / f"{REST_NAME}_d3.png"
    render_toolpath_png(small.mesh, small.toolpath, str(png), title="TMM rest: a ball D3 where a D10 left material")
    sim = simulate_case(small, out / f"{REST_NAME}_sim.png", 0.2)
    files += [png, out / f"{REST_NAME}_sim.png"]
    report = str(small.op.RestReport)
    try:
        FreeCAD.closeDocument(big.doc.Name)
    except Exception:  # noqa: BLE001 - closing is a courtesy
        pass
    return dict(name=REST_NAME, moves=(len(big.toolpath), len(small.toolpath)), seconds=seconds, sim=sim,
                report=report, files=files)


def print_rest(r: dict[str, Any], total: float) -> None:
    print(f"\n{'case (rest)':<22} {'D10 moves':>10} {'D3 rest moves':>14} {'both s':>8}")
    print(f"{r['name']:<22} {r['moves'][0]:>10} {r['moves'][1]:>14} {r['seconds']:>8.2f}")
    print(f"the rest: {r['report']}")
    print("simulated (D10 finish + D3 rest): " + sim_line(r["name"], r["sim"]))
    print("written (rest):")
    print_files(r["files"])
    print(f"rest {total:.1f} s", flush=True)


# --- 5-axis part -------------------------------------------------------------------------------------
MP_NAME = "multipoint_convex"
# The seed's tool and footprint: passes 18 mm apart from x = 0, the last at x = 150; 2 mm forward steps.
MP_PARAMS = dict(Ro=6.7, Ri=6.0, method="vcrf", side_step=18.0, pass_spacing="fixed", forward_step=2.0)


def run_multipoint_case(out: Path, with_freecad: bool) -> dict[str, Any]:
    """Seed 001's convex patch as a FreeCAD Bézier face through `run_multipoint` (Job, bull-nose ToolBit,
    'TMM 5-axis Multipoint' op, tarus and apt_cl posts, document), a picture of the tool axes, and (when
    benchmarks.seed.experiment is there) the seed's section-deviation plot at y = 27 mm."""
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams, compute_multipoint_toolpath
    from tmm_workbench.core.tools.cutter import Cutter
    from tmm_workbench.core.preview.axes_png import face_grid, render_axes_png

    net = bezier.load_seed_patch(bench() / "seed_surfaces.json", "convex")
    p = MP_PARAMS
    print(f"--- {MP_NAME}: seed 001 convex Bezier face, 5-axis multipoint {p['method'].upper()}, torus Ro "
          f"{p['Ro']:g} Ri {p['Ri']:g}, side step {p['side_step']:g} mm, forward step {p['forward_step']:g} mm",
          flush=True)
    t0 = time.perf_counter()
    files: list[Path] = []
    if with_freecad:
        import FreeCAD
        import Part
        from tmm_workbench.app.api import run_multipoint

        surf = Part.BezierSurface()
        surf.increase(3, 3)
        for i in range(4):
            for j in range(4):
                surf.setPole(i + 1, j + 1, FreeCAD.Vector(*map(float, net[i, j])))
        r = run_multipoint(surf, **p, out_dir=out, name=MP_NAME, fcstd_path=out / f"{MP_NAME}.FCStd",
                           doc_name=MP_NAME)
        face, results, core_tp = r.op.Proxy.face, r.results, r.toolpath
        n_commands, summary = len(r.op.Path.Commands), r.op.ContactSummary
        files += [r.files["tarus"], r.files["apt_cl"], r.files["fcstd"]]
        sim = simulate_case(r, out / f"{MP_NAME}_sim.png", SIM_CELL_5AXIS_MM)
        files.append(out / f"{MP_NAME}_sim.png")
        try:
            FreeCAD.closeDocument(r.doc.Name)
        except Exception:  # noqa: BLE001 - closing is a courtesy
            pass
    else:
        face = BezierFace.from_net(net, name="seed convex")
        core_tp, results = compute_multipoint_toolpath(
            face, Cutter.torus(p["Ro"], p["Ri"]),
            MultipointParams(side_step=p["side_step"], pass_spacing=p["pass_spacing"],
                             forward_step=p["forward_step"], method=p["method"]))
        n_commands, summary, sim = 0, "", None
    seconds = time.perf_counter() - t0

    import numpy as np

    png = out / f"{MP_NAME}_axes.png"
    t1 = time.perf_counter()
    render_axes_png(face_grid(face), results, str(png), toolpath=core_tp,
                    title=f"TMM 5-axis multipoint ({p['method'].upper()}): seed 001 convex Bezier patch - torus "
                          f"Ro {p['Ro']:g} Ri {p['Ri']:g}, side step {p['side_step']:g} mm, forward step "
                          f"{p['forward_step']:g} mm")
    files.append(png)
    png_seconds = time.perf_counter() - t1

    section_note = ""
    try:
        from benchmarks.seed.experiment import run_experiment, section_plot
    except ImportError:
        section_note = "section plot skipped (benchmarks.seed.experiment not available)"
    else:
        t2 = time.perf_counter()
        sec = run_experiment("convex", p["method"])
        sec_png = out / f"{MP_NAME}_section.png"
        section_plot([sec], sec_png)
        files.append(sec_png)
        section_note = (f"section y = {sec.section_y:g} mm ({sec.n_positions} positions at the seed's footprint): max "
                        f"deviation {sec.max_dev:.3f} mm (seed, simulated: 0.53 mm), {time.perf_counter() - t2:.1f} s")
    counts = results.counts()
    tilt = np.degrees(np.arccos(np.clip(results["axis"][results.status != 2][:, 2], -1, 1)))
    return dict(name=MP_NAME, counts=counts, points=len(results), commands=n_commands, summary=summary,
                cut_moves=sum(1 for m in core_tp if m.kind.name != "RAPID"), max_tilt=float(tilt.max()),
                seconds=seconds, png_seconds=png_seconds, files=files, section=section_note, sim=sim)


def print_table5(r: dict[str, Any], total: float) -> None:
    head = f"{'case (5-axis)':<18} {'points':>6} {'two':>5} {'one':>5} {'failed':>6} {'cut moves':>9} " \
           f"{'commands':>8} {'max tilt':>8} {'compute s':>9} {'png s':>6}"
    print("\n" + head)
    print("-" * len(head))
    c = r["counts"]
    print(f"{r['name']:<18} {r['points']:>6} {c['two']:>5} {c['one']:>5} {c['failed']:>6} {r['cut_moves']:>9} "
          f"{r['commands']:>8} {r['max_tilt']:>7.1f}d {r['seconds']:>9.2f} {r['png_seconds']:>6.2f}")
    if r["section"]:
        print(r["section"])
    if r.get("sim"):
        print("simulated: " + sim_line(r["name"], r["sim"]))
    print("\nwritten (5-axis):")
    print_files(r["files"])
    print(f"5-axis part {total:.1f} s", flush=True)


def print_table(rows: list[dict[str, Any]], total: float) -> None:
    head = f"{'case':<16} {'tool':<20} {'triangles':>9} {'CL points':>9} {'cut mm':>9} {'rapids':>6} " \
           f"{'compute s':>9} {'png s':>6}"
    print("\n" + head)
    print("-" * len(head))
    for r in rows:
        s = r["stats"]
        print(f"{r['name']:<16} {r['tool']:<20} {len(r['mesh'].triangles):>9} "
              f"{s['feed_count'] + s['plunge_count']:>9} {s['cutting_length']:>9.0f} {s['rapid_count']:>6} "
              f"{r['seconds']:>9.2f} {r['png_seconds']:>6.2f}")
    sims = [r for r in rows if r.get("sim")]
    if sims:
        print("\nsimulated stock vs model (vertical deviation; api.simulate):")
        for r in sims:
            print("  " + sim_line(r["name"], r["sim"]))
    print("\nwritten:")
    print_files([f for r in rows for f in (*r["files"], r["png"])])
    print(f"total {total:.1f} s", flush=True)


def _entry() -> None:
    try:
        main()
        if UNSAFE:
            raise RuntimeError("the simulation found paths a machine must not run: " + "; ".join(UNSAFE))
    except BaseException:  # noqa: BLE001 - freecadcmd would swallow it and exit 0
        traceback.print_exc()
        sys.stdout.flush()
        raise SystemExit(1)


if __name__ in ("__main__", "demo"):
    _entry()
