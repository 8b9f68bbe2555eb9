"""Lean passes (issue 14 item 2): the README's demo jobs (scripts/demo.py: sphere_on_plate, mount_rush, seed 001's
convex patch; 3-axis Surface) before (ForwardStep SampleStep: a point every sample step, moves thinned above
only, today's output) and after (ForwardStep Tolerance: the fewest moves within +-ChordTolerance of the exact CL
path; lines through linuxcnc, and with ArcFitting through grbl), all at ChordTolerance 0.001 mm, side by side:

  moves         motion lines of the G-code (G0/G1/G2/G3)
  lines         all G-code lines the post wrote
  dev -/+ mm    the cutting moves (lines, arcs as 1e-5 mm chords) sampled every 0.01 mm against the exact drop
                height there (the kernel's drop-cutter): deepest below / highest above the exact CL path
                (moves shorter than 2 um in XY, cliff corners, and air left out)
  gouge mm      TMM's stock simulation of the op's Path (0.1 mm cells, G18/G19 arcs read) against the model:
                the deepest cell below the design (0 where none)
  compute s     the op's recompute (drop, refine, lean) as a user waits for it after OK
  post s        FreeCAD's post writing the G-code

Run with FreeCAD's Python (freecadcmd), e.g.
    HOME=/tmp/home-x freecadcmd -c "exec(open('benchmarks/lean_path.py').read())"
    TMM_LEAN_QUICK=1 ... (sphere_on_plate only); TMM_LEAN_CASES=mount_rush,bezier_convex ... (those)
"""
from __future__ import annotations

import math
import os
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import FreeCAD  # noqa: E402

from tmm_workbench.app import posts  # noqa: E402
from tmm_workbench.app.api import run_surface, simulate  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

TOL = 0.001
STEP = 0.01  # mm between the points where a move is compared with the exact drop height
CLIFF = 2e-3  # mm: moves shorter in XY go down or up a cliff (raster_refine's corners), not along the path


def deviation(toolpath, mesh, cutter: Cutter) -> tuple[float, float]:
    """(most below, most above) the exact CL path over the FEED moves, mm (air points left out)."""
    tp = toolpath.chorded(1e-5)
    p = tp.points()
    feed = np.array([m.kind is MoveKind.FEED for m in tp.moves])
    pts = []
    for i in np.flatnonzero(feed[1:]) + 1:
        a, b = p[i - 1], p[i]
        length = math.hypot(*(b[:2] - a[:2]))
        if length < CLIFF:
            continue  # vertical, or raster_refine's cliff corner: a vertical measure means nothing there
        n = int(math.ceil(length / STEP))
        f = np.arange(n + 1)[:, None] / n
        pts.append(a + f * (b - a))
    pts = np.vstack(pts)
    floor = float(mesh.bounds[0][2])
    exact = DropSurface(mesh).drop(cutter, pts[:, :2], floor - 1e3)
    on = exact > floor - 1.0          # air (skip mode) is not on the path
    d = pts[on, 2] - np.maximum(exact[on], floor)
    return float(d.min()), float(d.max())


def run(case, label: str, post: str, cutter: Cutter, out: Path, **extra) -> dict:
    t0 = time.perf_counter()
    r = run_surface(case.model, doc_name=f"lean_{case.name}_{label}", post=post,
                    gcode_path=str(out / f"{case.name}_{label}.ngc"), progress=False, chord_tolerance=TOL,
                    **case.params, **extra)
    total = time.perf_counter() - t0
    t1 = time.perf_counter()
    posts.export(post, [r.op.ToolController, r.op], str(out / f"{case.name}_{label}_again.ngc"))
    post_s = time.perf_counter() - t1
    lines = r.gcode.splitlines()
    moves = sum(1 for ln in lines if re.match(r"^(N\d+\s+)?G0?[0-3]\b", ln.strip()))
    below, above = deviation(r.toolpath, r.mesh, cutter)
    s = simulate(r, cell=0.1, tolerance=0.01, progress=False)
    row = dict(case=case.name, label=label, post=post, moves=moves, lines=len(lines), arcs=len(r.toolpath.arcs),
               below=below, above=above, gouge=min(0.0, s.min_deviation), compute=total - post_s, post_s=post_s)
    FreeCAD.closeDocument(r.doc.Name)
    return row


def main() -> None:
    from demo_jobs import load_demo

    demo = load_demo()

    out = Path(tempfile.mkdtemp(prefix="tmm_lean_"))
    quick = bool(os.environ.get("TMM_LEAN_QUICK"))
    only = os.environ.get("TMM_LEAN_CASES", "").split(",") if os.environ.get("TMM_LEAN_CASES") else None
    rows = []
    for case in demo.cases(out):
        if (quick and case.name != "sphere_on_plate") or (only and case.name not in only):
            continue
        if not case.model:
            case.model = str(demo.bezier_stl(out))
        p = case.params
        cutter = (Cutter.ball(p["diameter"]) if p["tool"] == "ballend"
                  else Cutter.bull(p["diameter"], p["corner_radius"]))
        for label, post, extra in (("before", "linuxcnc", dict(forward_step="sample")),
                                   ("lean lines", "linuxcnc", dict(forward_step="tolerance")),
                                   ("lean arcs", "grbl", dict(forward_step="tolerance", arcs=True))):
            row = run(case, label.replace(" ", "_"), post, cutter, out, **extra)
            row["label"] = label
            rows.append(row)
            print(f"{row['case']:<16} {label:<11} {post:<8} {row['moves']:>7} {row['lines']:>7} {row['arcs']:>6} "
                  f"{row['below']:+.4f}/{row['above']:+.4f} {row['gouge']:+.4f} {row['compute']:>7.2f} "
                  f"{row['post_s']:>6.2f}", flush=True)
    print()
    print("| job | forward step | post | moves | G-code lines | arcs | dev below / above exact mm | deepest gouge mm "
          "| compute s | post s | moves vs before |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    base = {r["case"]: r for r in rows if r["label"] == "before"}
    for r in rows:
        ratio = base[r["case"]]["moves"] / r["moves"]
        print(f"| {r['case']} | {r['label']} | {r['post']} | {r['moves']} | {r['lines']} | {r['arcs']} | "
              f"{r['below']:+.4f} / {r['above']:+.4f} | {r['gouge']:+.4f} | {r['compute']:.2f} | {r['post_s']:.2f} | "
              f"{ratio:.2f}x |")


main()
