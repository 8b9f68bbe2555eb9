"""The main job's 5-axis mesh case: seed 000's convex benchmark surface (Appendix A) as an STL, finished by the
'TMM 5-axis Mesh' op (the 3D C-space method: a flat-end D 0.5 in tilted to the surface, adaptive passes within
the seed's 0.004 in scallop), posted for the Tarus mill, simulated (heat map) and drawn. Without FreeCAD the
core computes the same passes and the picture only (no Job, no G-code)."""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable

NAME = "mesh5_convex"
INCH = 25.4
PARAMS = dict(tool="endmill", diameter=0.5 * INCH, tolerance=0.004 * INCH)
SIM_CELL_MM = 1.0   # the surface is ~250 mm square: 63 k cells (0.5 mm: 4x the time of a tool footprint)


def run_mesh5_case(out: Path, with_freecad: bool,
                   simulate_case: Callable[[Any, Path, float], dict[str, Any]]) -> dict[str, Any]:
    from benchmarks.seed000_surfaces import seed000_mesh
    from tmm_workbench.core.geometry.mesh import save_stl
    from tmm_workbench.core.preview.toolpath_png import path_statistics, render_toolpath_png

    mesh, _ = seed000_mesh("convex")
    stl = save_stl(mesh, out / f"{NAME}.stl")
    print(f"--- {NAME}: seed 000 convex surface (mesh), 5-axis C-space finishing, flat-end D"
          f"{PARAMS['diameter']:g}, scallop {PARAMS['tolerance']:g} mm", flush=True)
    files: list[Path] = [stl]
    t0 = time.perf_counter()
    sim = None
    if with_freecad:
        import FreeCAD
        from tmm_workbench.app.api import run_mesh5

        r = run_mesh5(str(stl), **PARAMS, gcode_path=out / f"{NAME}.tarus.nc", fcstd_path=out / f"{NAME}.FCStd",
                      doc_name=NAME, progress=False)
        toolpath, summary = r.toolpath, r.op.Mesh5Summary
        files += [out / f"{NAME}.tarus.nc", out / f"{NAME}.FCStd"]
        seconds = time.perf_counter() - t0
        sim = simulate_case(r, out / f"{NAME}_sim.png", SIM_CELL_MM)
        files.append(out / f"{NAME}_sim.png")
        FreeCAD.closeDocument(r.doc.Name)
    else:
        from tmm_workbench.core.linking import link
        from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params, compute, report
        from tmm_workbench.core.strategies.multipoint import link_policy
        from tmm_workbench.core.tools.cutter import Cutter

        cutter = Cutter.flat(PARAMS["diameter"])
        result = compute(mesh, cutter, Mesh5Params(tolerance=PARAMS["tolerance"]))
        top = float(mesh.bounds[1][2])
        toolpath = link(result.segments, link_policy(cutter, top + 5.0, top + 15.0, 5.0))
        summary, seconds = report(result.diagnostics), time.perf_counter() - t0
    png = out / f"{NAME}.png"
    render_toolpath_png(mesh, toolpath, str(png), title=f"TMM 5-axis mesh: seed 000 convex surface - flat-end "
                        f"D{PARAMS['diameter']:g}, scallop {PARAMS['tolerance']:g} mm")
    files.append(png)
    return dict(name=NAME, summary=summary, stats=path_statistics(toolpath), seconds=seconds, sim=sim, files=files)


def print_mesh5(r: dict[str, Any], total: float, sim_line: Callable, print_files: Callable) -> None:
    s = r["stats"]
    print(f"\n{'case (5-axis mesh)':<18} {'cut moves':>9} {'cut mm':>9} {'compute s':>9}")
    print(f"{r['name']:<18} {s['feed_count'] + s['plunge_count']:>9} {s['cutting_length']:>9.0f} {r['seconds']:>9.2f}")
    print(f"  {r['summary']}")
    if r["sim"]:
        print("simulated: " + sim_line(r["name"], r["sim"]))
    print("\nwritten (5-axis mesh):")
    print_files(r["files"])
    print(f"5-axis mesh part {total:.1f} s", flush=True)
