"""Z-level roughing speed: the whole roughing (layers, waterlines, clearing, entries, linking) of a
100 x 100 x 30 mm block over the 80k-triangle height field of drop_cutter_bench.py and of the shared
mount_rush.stl, with the simulator's verdict on the result.

    .venv/bin/python benchmarks/roughing_bench.py            # both models, flat D10 and ball D6
    .venv/bin/python benchmarks/roughing_bench.py --quick    # the height field with the flat D10 only

Per case: layers, regions, moves, seconds for the whole roughing (compute + link) and of its waterline part
(the tool's loops at every layer, the same call the strategy makes), and the peer: OpenCAMLib has no
roughing, so its Waterline at the same levels and sampling (the part of roughing it can do) stands beside
ours, timed on a few of the layers and scaled to all (column `ocl wl s`), with the ratio to our waterline
part. Then the simulated stock (0.25 mm cells) against the model plus stock to leave: the deepest cell below
it (a gouge if below -0.001 mm), the rapids that removed material, and the material left (median, 99 %)
over the cells with model under them.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from drop_cutter_bench import STL_DIR, height_field, ocl_surface  # noqa: E402
from opencamlib import ocl  # noqa: E402

from tmm_workbench.core.geometry.mesh import TriMesh, load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.query import waterline as wl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies import zlevel_rough as zr  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

OCL_LAYERS = 3          # OpenCAMLib's waterline timed on this many layers, scaled to all


def block_over(mesh: TriMesh, height: float = 30.0) -> tuple:
    """The model's XY box, `height` tall, its top 2 mm above the model (or its bottom at the model's lowest)."""
    lo, hi = mesh.bounds
    top = max(float(hi[2]) + 2.0, float(lo[2]) + height)
    return (float(lo[0]), float(lo[1]), top - height if top - height <= lo[2] else float(lo[2]),
            float(hi[0]), float(hi[1]), top)


def ocl_waterline_seconds(surf, cutter: Cutter, levels, sample: float) -> float:
    picks = np.linspace(0, len(levels) - 1, min(OCL_LAYERS, len(levels))).astype(int)
    seconds = 0.0
    for k in picks:
        w = ocl.Waterline()
        w.setSTL(surf)
        tool = (ocl.BallCutter(cutter.diameter, 50.0) if cutter.kind == "ball" else
                ocl.CylCutter(cutter.diameter, 50.0) if cutter.kind == "flat" else
                ocl.BullCutter(cutter.diameter, cutter.corner_radius, 50.0))
        w.setCutter(tool)
        w.setZ(float(levels[k]))
        w.setSampling(sample)
        w.setThreads(2)
        t = time.perf_counter()
        w.run()
        seconds += time.perf_counter() - t
    return seconds / len(picks) * len(levels)


def run(name: str, mesh: TriMesh, cutter: Cutter, params: zr.RoughingParams, surf_ocl) -> dict:
    surface = DropSurface(mesh)
    box = params.stock_box
    policy = LinkPolicy(box[5] + 5.0, box[5] + 10.0, entry=params.entry, ramp_angle_deg=params.ramp_angle_deg)
    t0 = time.perf_counter()
    result = zr.compute(mesh, cutter, params, surface=surface)
    path = link(result.segments, policy)
    total = time.perf_counter() - t0
    d = result.diagnostics
    # the waterline part alone: the same call the strategy makes for the tool (not the model's slices)
    grow = cutter.radius + params.stock_to_leave + zr._AIR_MARGIN + params.stepover(cutter)
    bounds = (box[0] - grow, box[1] - grow, box[3] + grow, box[4] + grow)
    levels = [z - params.axial for z in d["layer_z"]]
    sample = wl.default_sample_step(cutter, bounds)
    t0 = time.perf_counter()
    wl.waterline_loops(surface, cutter.offset(params.stock_to_leave), levels, bounds, sample_step=sample,
                       chord_tol=params.chord_tol)
    t_wl = time.perf_counter() - t0
    # stock to leave: OpenCAMLib's tool grown the same way (ball, flat or bull of the grown size)
    grown = cutter.offset(params.stock_to_leave)
    t_ocl = ocl_waterline_seconds(surf_ocl, grown, levels, sample) if surf_ocl is not None else float("nan")
    grid = Grid.covering(box[0], box[1], box[3], box[4], 0.25)
    sim = simulate(path, cutter, grid, box_heights(grid, box[5]))
    s = params.stock_to_leave
    design = (surface.drop(Cutter.ball(2 * s), grid.centres(), float(mesh.bounds[0][2]) - 1.0) + s
              ).reshape(grid.ny, grid.nx)
    design[np.isnan(mesh_heights(mesh, grid, surface))] = np.nan     # no model under the cell: not compared
    dev = sim.heights - design
    feeds = sum(1 for m in path.moves if m.kind is not MoveKind.RAPID)
    return dict(case=name, tool=cutter.describe(), layers=d["layers"], regions=d["regions"], moves=len(path),
                feeds=feeds, total=total, wl=t_wl, ocl=t_ocl, ratio=t_ocl / t_wl, gouge=float(np.nanmin(dev)),
                rapids=len(sim.collisions), p50=float(np.nanpercentile(dev, 50)),
                p99=float(np.nanpercentile(dev, 99)),
                entries=d["entries"], sim_s=sim.seconds)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="the height field with the flat D10 only")
    ap.add_argument("--no-ocl", action="store_true", help="leave OpenCAMLib's waterline out")
    args = ap.parse_args()
    field = height_field(200, False)
    models = [("height field 80k", field)]
    if not args.quick:
        models.append(("mount_rush.stl", load_stl(STL_DIR / "mount_rush.stl")))
    tools = [Cutter.flat(10)] if args.quick else [Cutter.flat(10), Cutter.ball(6)]
    rows = []
    for name, mesh in models:
        surf_ocl = None if args.no_ocl else ocl_surface(mesh)
        box = block_over(mesh)
        for cutter in tools:
            params = zr.RoughingParams(stock_box=box, step_down=2.0, stepover_percent=40.0, stock_to_leave=0.5)
            rows.append(run(name, mesh, cutter, params, surf_ocl))
            r = rows[-1]
            print(f"# {name}, {r['tool']}: stock {box[3] - box[0]:.4g} x {box[4] - box[1]:.4g} x "
                  f"{box[5] - box[2]:.4g} mm, {len(mesh.triangles)} triangles, entries {r['entries']}", flush=True)
    print("| model | tool | layers | regions | moves | roughing s | of it waterline s | ocl wl s | ocl / ours "
          "| deepest below design mm | rapids through stock | left p50 / p99 mm |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['case']} | {r['tool']} | {r['layers']} | {r['regions']} | {r['moves']} | {r['total']:.2f} | "
              f"{r['wl']:.2f} | {r['ocl']:.1f} | {r['ratio']:.1f} | {r['gouge']:.4f} | {r['rapids']} | "
              f"{r['p50']:.2f} / {r['p99']:.2f} |")


if __name__ == "__main__":
    main()
