"""5-axis on a mesh against TMM's best 3-axis ball finish at equal scallop (seed 000's convex surface, Fig. 5-5's
case): a flat end mill D 0.5 in tilted by the 3D C-space (core.strategies.mesh5.finish, the op's strategy),
posted by the Tarus post (its estimate plans A and C at the joint speeds), against a ball D 0.5 in with the
Surface's cusp-driven modes (cusp and adaptive, raster along X and along Y, and the 3D offset; the fastest
counts), both at the same feed and the same scallop height (the seed's 0.004 in).

    .venv/bin/python benchmarks/mesh5_vs_3axis.py [--surface convex] [--tolerance-in 0.004] [--feed 1000]

Prints per strategy: passes, cutting length, rapid length, simulated cycle time, compute time (wall and CPU); then the
ratio 5-axis / best 3-axis (the issue's target: at most 0.5 on the convex surface).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.seed000_surfaces import INCH, seed000_mesh  # noqa: E402
from tmm_workbench.core import path5  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.machine.tarus import TarusMachine  # noqa: E402
from tmm_workbench.core.post import Operation, ToolInfo  # noqa: E402
from tmm_workbench.core.post.tarus_writer import write_tarus  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.strategies.mesh5 import finish  # noqa: E402
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params  # noqa: E402
from tmm_workbench.core.strategies.multipoint import link_policy  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import compute  # noqa: E402
from tmm_workbench.core.strategies.surface.params import ADAPTIVE, CUSP, OFFSET3D, SurfaceParams  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def row(name: str, passes: int, tp, seconds: float, compute_s: tuple[float, float]) -> dict:
    step = np.linalg.norm(np.diff(tp.points(), axis=0), axis=1)
    fed = np.array([m.kind in (MoveKind.FEED, MoveKind.PLUNGE) for m in tp.moves[1:]])
    return dict(name=name, passes=passes, seconds=seconds, compute=compute_s, cut=float(step[fed].sum()),
                rapid=float(step[~fed].sum()))


def five_axis(mesh, tol: float, feed: float, safe: float) -> dict:
    cutter = Cutter.flat(0.5 * INCH)
    t0, w0 = time.process_time(), time.perf_counter()
    result = finish.compute(mesh, cutter, Mesh5Params(tolerance=tol))
    tp = link(result.segments, link_policy(cutter, safe, safe + 5.0, 5.0))
    compute_s = (time.perf_counter() - w0, time.process_time() - t0)
    tool = ToolInfo(number=1, label="flat 0.5 in", shape="endmill", diameter=cutter.diameter, corner_radius=0.0,
                    cutting_height=25.0, spindle_rpm=10000.0)
    program = [tool, Operation("Mesh5", path5.encode_toolpath(tp, feed, feed / 3), "Flood")]
    seconds = write_tarus(program, TarusMachine()).cycle_time
    return row("5-axis flat D 0.5 in (C-space, Tarus)", int(result.diagnostics["passes"]), tp, seconds,
               compute_s)


def three_axis(mesh, tol: float, feed: float, safe: float, mode: str, angle: float) -> dict:
    cutter = Cutter.ball(0.5 * INCH)
    lo, hi = mesh.bounds
    params = SurfaceParams(boundary=(lo[0], lo[1], hi[0], hi[1]), stepover_mode=mode, cusp=tol, angle_deg=angle)
    t0, w0 = time.process_time(), time.perf_counter()
    result = compute(mesh, cutter, params)
    tp = link(result.segments, LinkPolicy(safe, safe + 5.0))
    compute_s = (time.perf_counter() - w0, time.process_time() - t0)
    seconds = three_axis_time(tp.points(), toolpath_feeds(tp, feed, feed / 3)).seconds
    return row(f"3-axis ball D 0.5 in, {mode}, raster {angle:g} deg", int(result.diagnostics.get("passes", 0)),
               tp, seconds, compute_s)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--surface", default="convex", choices=("convex", "concave", "complex"))
    ap.add_argument("--tolerance-in", type=float, default=0.004)
    ap.add_argument("--feed", type=float, default=1000.0, help="mm/min, both machines")
    a = ap.parse_args()
    mesh, _ = seed000_mesh(a.surface)
    tol, feed = a.tolerance_in * INCH, a.feed / 60.0
    safe = float(mesh.bounds[1][2]) + 10.0
    print(f"seed 000 {a.surface} surface, scallop {tol:.4f} mm, feed {a.feed:g} mm/min, "
          f"load {os.getloadavg()[0]:.1f}")
    rows = [three_axis(mesh, tol, feed, safe, m, ang) for m in (CUSP, ADAPTIVE) for ang in (0.0, 90.0)]
    rows.append(three_axis(mesh, tol, feed, safe, OFFSET3D, 0.0))
    best = min(rows, key=lambda r: r["seconds"])
    rows.append(five_axis(mesh, tol, feed, safe))
    print("| strategy | passes | cutting mm | rapid mm | cycle s | compute wall s | CPU s |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['name']} | {r['passes']} | {r['cut']:.0f} | {r['rapid']:.0f} | {r['seconds']:.0f} | "
              f"{r['compute'][0]:.1f} | {r['compute'][1]:.1f} |")
    print(f"5-axis / best 3-axis cycle time: {rows[-1]['seconds'] / best['seconds']:.2f} (target <= 0.5)")


if __name__ == "__main__":
    main()
