"""Lean passes on the README's bezier_convex job (scripts/demo.py: seed 001's convex Bezier patch, bull-nose D25.4
r6, step-over 1.0, sample step 0.5, passes along Y) at finer tessellations of the patch. Core only (no FreeCAD).

The demo tessellated the patch to 0.01 mm, 10x the lean fit's chord tolerance (now 0.001 mm,
demo.BEZIER_TOLERANCE_MM, after this benchmark), and the lean fit follows the tessellated model's exact CL path (a
kink at every facet edge). This measures, for each
tessellation tolerance (the patch written to STL and read back, as the demo does), with raster_drop.compute at
chord_tol 0.001 mm over the model's XY box:

  before       ForwardStep "sample" (a point every 0.5 mm, thinned above only by reduce_chords): today's output
  lean lines   ForwardStep "tolerance" (the kernel's fewest lines within +-tol of the exact CL path)
  lean arcs    the same with arcs=True (an arc counts as one move)

moves as benchmarks/lean_fixed_step.py counts them (the cutting segments' moves), before / lean, the compute
seconds, and the lean moves' deviation from the exact CL path of the same mesh (lean_fixed_step.deviation:
sampled every 0.01 mm against the kernel's drop; arcs expanded into 1e-5 mm chords first).

Run: .venv/bin/python benchmarks/lean_tessellation.py [--tols 0.01,0.001,0.0003,0.0001] [--no-dev]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from lean_fixed_step import TOL, deviation, moves  # noqa: E402  (puts the repository on sys.path)

from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def with_arcs_chorded(segments) -> list:
    """The segments' tips with each arc move replaced by its 1e-5 mm chords (only .tips, for deviation)."""
    out = []
    for seg in segments:
        t = seg.tips
        pts = [t[:1]]
        for k, (a, b) in enumerate(zip(t[:-1], t[1:])):
            arc = seg.arc(k + 1)
            pts.append(b[None] if arc is None else arc.chords(a, b, 1e-5))
        out.append(SimpleNamespace(tips=np.vstack(pts)))
    return out


def main() -> None:
    from demo_jobs import load_demo

    ap = argparse.ArgumentParser()
    ap.add_argument("--tols", default="0.01,0.001,0.0003,0.0001", help="tessellation tolerances, mm")
    ap.add_argument("--no-dev", action="store_true", help="skip the deviation check (its exact drops)")
    args = ap.parse_args()
    demo = load_demo()
    case = next(c for c in demo.cases(Path(".")) if c.name == "bezier_convex")
    p = case.params
    cutter = Cutter.bull(p["diameter"], p["corner_radius"])
    net = bezier.load_seed_patch(demo.bench() / "seed_surfaces.json", "convex")
    out = Path(tempfile.mkdtemp(prefix="tmm_lean_tess_"))
    rows = []
    for tol_mesh in map(float, args.tols.split(",")):
        nu, nv = bezier.grid_for_tolerance(net, tol_mesh)
        path = out / f"bezier_convex_{tol_mesh:g}.stl"
        m = bezier.tessellate(net, nu, nv, name="bezier_convex")
        demo.write_binary_stl(m.vertices, m.triangles, path)
        mesh = load_stl(path)
        (x0, y0, _), (x1, y1, _) = mesh.bounds
        floor = float(mesh.bounds[0][2])
        surface = DropSurface(mesh)
        params = SurfaceParams(boundary=(float(x0), float(y0), float(x1), float(y1)), stepover=p["stepover"],
                               sample_step=p["sample_step"], angle_deg=p["angle_deg"], chord_tol=TOL)
        print(f"--- tessellation {tol_mesh:g} mm: {nu} x {nv} grid, {len(mesh.triangles)} triangles", flush=True)
        base = None
        for label, extra in (("before", dict(forward_step="sample")),
                             ("lean lines", dict(forward_step="tolerance", arcs=False)),
                             ("lean arcs", dict(forward_step="tolerance", arcs=True))):
            t0 = time.perf_counter()
            res = compute(mesh, cutter, replace(params, **extra), surface=surface)
            dt = time.perf_counter() - t0
            segs = res.segments
            n_arcs = sum(a is not None for s in segs for a in (s.arcs or ()))
            n = moves(segs)
            base = base or n
            row = dict(tol=tol_mesh, tris=len(mesh.triangles), label=label, moves=n, arcs=n_arcs,
                       ratio=base / n, s=dt, below=float("nan"), above=float("nan"), dev_s=0.0)
            if not args.no_dev and label != "before":
                t1 = time.perf_counter()
                row["below"], row["above"] = deviation(with_arcs_chorded(segs), surface, cutter, floor,
                                                       False)
                row["dev_s"] = time.perf_counter() - t1
            rows.append(row)
            print({k: (round(v, 5) if isinstance(v, float) else v) for k, v in row.items()}, flush=True)
    print()
    print("| tessellation mm | triangles | path | moves | arcs | before / this | dev below / above exact mm "
          "| compute s |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        dev = "" if r["label"] == "before" or args.no_dev else f"{r['below']:+.4f} / {r['above']:+.4f}"
        print(f"| {r['tol']:g} | {r['tris']} | {r['label']} | {r['moves']} | {r['arcs'] or ''} | {r['ratio']:.2f}x "
              f"| {dev} | {r['s']:.2f} |")


if __name__ == "__main__":
    main()
