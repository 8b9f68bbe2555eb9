"""Do the cusp modes hold the cusp they are asked for? (CUSP, ADAPTIVE, OFFSET3D; ball D6, cusp 0.01 mm)

Cases: two random height fields (60 x 60 mm of smooth bumps 0-15 mm high, numpy seeds fixed), a sphere cavity
(a 100 x 100 mm block with a hemispherical pocket of radius 40 mm, as OpenCAMLib's examples have it), and the
shared STLs sphere_on_plate and mount_rush. Each mode's path is made through raster_drop.compute (the op's entry,
cusp_spacing.raster) and measured independently, as benchmarks/cusp_item7.py measures: the path and a dense raster
of the same tool cut into the stock simulation (core.sim.cusp_field, 0.1 mm cells, the dense raster's passes a cell
apart sampled every 0.25 mm), the cusp along the normal on slopes up to 75 deg where the tool reaches the model.
Printed per row: the largest cusp, its 99.5th percentile, the cells above 1.05 x the cusp, the cycle (1000 mm/min)
and the compute seconds (the op's own check included), and what the op itself reports (CheckCusp On: diagnostics
"cusp_check": cells above the cusp on the verification's finer cells, crests included, the largest, its seconds;
--check auto: on CheckCusp Auto's cells, coarser on regions of more than 250,000 of those).

    .venv/bin/python benchmarks/cusp_hold.py                       # every case and mode (about 10 min loaded)
    .venv/bin/python benchmarks/cusp_hold.py --only bumps1,cavity --modes offset3d
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from cusp_spacing import SLOPE_LIMIT, cycle  # noqa: E402

from tmm_workbench.core.geometry.mesh import TriMesh, load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies.surface.reference import cusp_field  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

TOL = 0.01
CELL = 0.1
OVER = 1.05           # cells above this x the cusp are counted
MODES = ("cusp", "adaptive", "offset3d")
CHECK = "on"          # the op's own check (CheckCusp) by default On on every case: its report and what it costs
                      # on the verification's cells (--check auto: these regions on Auto's coarser cells)


def grid_mesh(z: np.ndarray, size: tuple[float, float], name: str) -> TriMesh:
    """Heights z[j, i] on a regular grid over [0, size x] x [0, size y] as two triangles per cell."""
    ny, nx = z.shape
    xs, ys = np.meshgrid(np.linspace(0, size[0], nx), np.linspace(0, size[1], ny))
    v = np.column_stack([xs.ravel(), ys.ravel(), z.ravel()])
    j, i = np.meshgrid(np.arange(ny - 1), np.arange(nx - 1), indexing="ij")
    a = (j * nx + i).ravel()
    b, c, d = a + 1, a + nx, a + nx + 1
    return TriMesh(v, np.vstack([np.column_stack([a, b, d]), np.column_stack([a, d, c])]), name)


def bumps(seed: int, size: float = 60.0, high: float = 15.0, cell: float = 0.25) -> TriMesh:
    """Smooth random bumps: 20 Gaussians of radius 3-9 mm at random places, scaled to 0..`high` mm (slopes up to
    55-62 deg on seeds 1 and 2)."""
    rng = np.random.default_rng(seed)
    n = int(round(size / cell)) + 1
    x, y = np.meshgrid(np.linspace(0, size, n), np.linspace(0, size, n))
    z = np.zeros_like(x)
    for _ in range(20):
        cx, cy = rng.uniform(-5, size + 5, 2)
        r, a = rng.uniform(3, 9), rng.uniform(-1, 1)
        z += a * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * r * r))
    z = (z - z.min()) / np.ptp(z) * high
    return grid_mesh(z, (size, size), f"bumps{seed}")


def sphere_cavity(side: float = 100.0, radius: float = 40.0, top: float = 50.0, cell: float = 0.25) -> TriMesh:
    """A block's top with a hemispherical pocket at its centre (the block's sides are not cut: a height field)."""
    n = int(round(side / cell)) + 1
    x, y = np.meshgrid(np.linspace(0, side, n), np.linspace(0, side, n))
    r2 = (x - side / 2) ** 2 + (y - side / 2) ** 2
    z = top - np.sqrt(np.clip(radius * radius - r2, 0.0, None))
    return grid_mesh(z, (side, side), "sphere_cavity")


def cases(only: set[str]) -> list[tuple[str, TriMesh]]:
    makers = {"bumps1": lambda: bumps(1), "bumps2": lambda: bumps(2), "cavity": sphere_cavity,
              "sphere_on_plate": lambda: load_stl(benchmark_file("stl", "sphere_on_plate.stl")),
              "mount_rush": lambda: load_stl(benchmark_file("stl", "mount_rush.stl"))}
    return [(name, make()) for name, make in makers.items() if not only or name in only]


def row(name: str, mesh: TriMesh, cutter: Cutter, mode: str, field, check: str = CHECK) -> str:
    lo, hi = mesh.bounds
    boundary = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    t0 = time.perf_counter()
    result = compute(mesh, cutter, SurfaceParams(boundary=boundary, sample_step=0.25, stepover_mode=mode, cusp=TOL,
                                                 max_slope_deg=SLOPE_LIMIT, cusp_check=check))
    top = float(hi[2])
    path = link(result.segments, LinkPolicy(top + 5, top + 10))
    secs = time.perf_counter() - t0
    c = field.cusp(field.cut(path, cutter))
    m = c[np.isfinite(c)]
    above = int(np.sum(m > OVER * TOL))
    check = result.diagnostics.get("cusp_check")
    said = ("-" if check is None else "skipped" if check["skipped"] else
            f"{check['exceeding']} / {check['max_cusp']:.4f} ({check['seconds']:.1f} s, {check['cell']:.3f} mm cells)")
    return (f"| {name} | {mode} | {result.diagnostics['passes']} | {m.max():.4f} | {np.percentile(m, 99.5):.4f} | "
            f"{above} | {len(m)} | {cycle(path) / 60:.1f} | {secs:.1f} | {said} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", default="", help="comma-separated: bumps1, bumps2, cavity, sphere_on_plate, mount_rush")
    ap.add_argument("--modes", default=",".join(MODES), help="comma-separated: " + ", ".join(MODES))
    ap.add_argument("--check", default=CHECK, choices=("on", "auto"), help="the op's CheckCusp")
    args = ap.parse_args()
    cutter = Cutter.ball(6.0)
    print(f"| case | mode | passes | max cusp mm | p99.5 mm | cells > {OVER:g} x | measured | cycle min | compute s "
          f"| op says: cells above / max (check s) |\n|---|---|---|---|---|---|---|---|---|---|", flush=True)
    t0 = time.perf_counter()
    for name, mesh in cases(set(filter(None, args.only.split(",")))):
        lo, hi = mesh.bounds
        boundary = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        field = cusp_field(mesh, cutter, boundary, TOL, CELL, SLOPE_LIMIT, sample_step=0.25)
        for mode in filter(None, args.modes.split(",")):
            print(row(name, mesh, cutter, mode, field, args.check), flush=True)
    print(f"# {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
