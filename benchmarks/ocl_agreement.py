"""Largest CL height difference between TMM's drop-cutter and OpenCAMLib on every shared STL file.

    .venv/bin/python benchmarks/ocl_agreement.py

Per file and cutter: a 0.5 mm raster over the model's bounds plus a 2 mm margin (all points), both programs
on the same welded triangles; prints the largest |difference| and how many points touch the model.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402

from opencamlib import ocl  # noqa: E402

STL_DIR = shared_dir() / "benchmarks" / "stl"
CUTTERS = [("ball d6", Cutter.ball(6.0), lambda: ocl.BallCutter(6.0, 50.0)),
           ("flat d6", Cutter.flat(6.0), lambda: ocl.CylCutter(6.0, 50.0)),
           ("bull d10 r2", Cutter.bull(10.0, 2.0), lambda: ocl.BullCutter(10.0, 2.0, 50.0))]


def main() -> None:
    print(f"{'file':22} {'triangles':>9} {'cutter':>12} {'points':>8} {'touching':>8} {'max |dz| mm':>12}")
    for path in sorted(STL_DIR.glob("*.stl")):
        mesh = load_stl(path)
        lo, hi = mesh.bounds
        xs = np.arange(lo[0] - 2, hi[0] + 2, 0.5)
        ys = np.arange(lo[1] - 2, hi[1] + 2, 0.5)
        X, Y = np.meshgrid(xs, ys)
        xy = np.column_stack([X.ravel(), Y.ravel()])
        zmin = float(lo[2]) - 100
        surf = ocl.STLSurf()
        v = mesh.vertices
        for a, b, c in mesh.triangles:
            surf.addTriangle(ocl.Triangle(ocl.Point(*v[a]), ocl.Point(*v[b]), ocl.Point(*v[c])))
        ours_surface = DropSurface(mesh)
        for name, cutter, make in CUTTERS:
            ours = ours_surface.drop(cutter, xy, zmin)
            bdc = ocl.BatchDropCutter()
            bdc.setSTL(surf)
            oc = make()  # OpenCAMLib keeps a raw pointer: keep the cutter alive through run()
            bdc.setCutter(oc)
            for x, y in xy:
                bdc.appendPoint(ocl.CLPoint(float(x), float(y), zmin))
            bdc.run()
            theirs = np.array([p.z for p in bdc.getCLPoints()])
            print(f"{path.name:22} {len(mesh):9d} {name:>12} {len(xy):8d} {int((ours > zmin).sum()):8d} "
                  f"{np.abs(ours - theirs).max():12.2e}", flush=True)


if __name__ == "__main__":
    main()
