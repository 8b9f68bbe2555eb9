"""Drop-cutter speed and agreement, TMM side by side with OpenCAMLib in the same run.

    .venv/bin/python benchmarks/drop_cutter_bench.py            # full table (several minutes)
    .venv/bin/python benchmarks/drop_cutter_bench.py --quick    # 80k meshes and the shared STL files only

Per case it prints points/s for both with the same thread count and their ratio, index build times,
the index memory, the largest CL height difference, and the mean number of triangles tested per CL point
against the number whose XY bounds come within the cutter's radius (the "shadow" candidates).
OpenCAMLib runs on an evenly spaced subset of the CL points when it would take too long (column `ocl n`).
"""
from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.kernel import native  # noqa: E402
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402

from opencamlib import ocl  # noqa: E402

STL_DIR = shared_dir() / "benchmarks" / "stl"
# name, kernel cutter, OpenCAMLib factory (None: OpenCAMLib has no such cutter)
TAPER_DEG = 3.0
CUTTERS = [
    ("ball d6", native.Cutter(3.0, 3.0), lambda: ocl.BallCutter(6.0, 50.0)),
    ("flat d6", native.Cutter(3.0, 0.0), lambda: ocl.CylCutter(6.0, 50.0)),
    ("bull d10 r2", native.Cutter(5.0, 2.0), lambda: ocl.BullCutter(10.0, 2.0, 50.0)),
    # Tapered ball: tip radius 1.5, 3 degree taper, cutting length 20 (ours alone).
    ("taper ball r1.5 3deg",
     native.Cutter.apt(1.5 / np.cos(np.radians(TAPER_DEG)) + 18.5 * np.tan(np.radians(TAPER_DEG)), 1.5, 20.0, 0.0,
                       np.radians(TAPER_DEG)), None),
]


def height_field(cells: int, jitter: bool, seed: int = 0) -> TriMesh:
    """z = 10 sin(x/15) cos(y/20) + 5 exp(-((x-50)^2 + (y-50)^2)/400) over 100 x 100 mm, 2 cells^2 triangles;
    with jitter, interior vertices move by up to 10% of a cell in X and Y."""
    n = cells
    g = np.linspace(0.0, 100.0, n + 1)
    x, y = np.meshgrid(g, g, indexing="ij")
    if jitter:
        rng = np.random.default_rng(seed)
        h = 100.0 / n
        inner = np.zeros_like(x, dtype=bool)
        inner[1:-1, 1:-1] = True
        x = x + np.where(inner, rng.uniform(-0.1, 0.1, x.shape) * h, 0)
        y = y + np.where(inner, rng.uniform(-0.1, 0.1, y.shape) * h, 0)
    z = 10 * np.sin(x / 15) * np.cos(y / 20) + 5 * np.exp(-((x - 50) ** 2 + (y - 50) ** 2) / 400)
    v = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c, d = a + n + 1, a + 1, a + n + 2
    f = np.vstack([np.column_stack([a, b, c]), np.column_stack([c, b, d])]).astype(np.int32)
    return TriMesh(v, f, f"height field {n}x{n}{' jittered' if jitter else ''}")


def raster(mesh: TriMesh, step: float) -> np.ndarray:
    lo, hi = mesh.bounds
    xs = np.arange(lo[0], hi[0] + 1e-9, step)
    ys = np.arange(lo[1], hi[1] + 1e-9, step)
    X, Y = np.meshgrid(xs, ys)  # rows along X: the order a raster footprint visits them
    return np.column_stack([X.ravel(), Y.ravel()])


def shadow_candidates(mesh: TriMesh, xy: np.ndarray, radius: float, sample: int = 300) -> float:
    """Mean number of triangles whose XY bounds come within `radius` of a CL point (on a subset)."""
    t = mesh.vertices[mesh.triangles]
    lo, hi = t[:, :, :2].min(1), t[:, :, :2].max(1)
    pts = xy[np.linspace(0, len(xy) - 1, min(sample, len(xy))).astype(int)]
    counts = []
    for p in pts:
        d = np.maximum(np.maximum(lo - p, p - hi), 0)
        counts.append(int(((d ** 2).sum(1) <= radius * radius).sum()))
    return float(np.mean(counts))


def ocl_surface(mesh: TriMesh):
    s = ocl.STLSurf()
    v = mesh.vertices
    for a, b, c in mesh.triangles:
        s.addTriangle(ocl.Triangle(ocl.Point(*v[a]), ocl.Point(*v[b]), ocl.Point(*v[c])))
    return s


def run_case(mesh, surf, index, name, cutter, make_ocl, xy, threads, ocl_budget_s, zmin):
    # Ours: all points (best of 3 short runs when quick).
    reps = 3 if len(xy) < 200_000 else 1
    best = np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        z, stats = native.drop_cutter_stats(index, cutter, xy, zmin, threads)
        best = min(best, time.perf_counter() - t0)
    ours_pps = len(xy) / best
    tested = stats["triangles_tested"] / len(xy)
    if make_ocl is None:
        return dict(cutter=name, ours=ours_pps, ocl=float("nan"), ratio=float("nan"), n=len(xy), n_ocl=0,
                    diff=float("nan"), tested=tested, ocl_index_s=float("nan"))
    # OpenCAMLib: an evenly spaced subset sized to the time budget (estimated from a small probe).
    def ocl_run(sub):
        bdc = ocl.BatchDropCutter()
        bdc.setThreads(threads)
        t0 = time.perf_counter()
        bdc.setSTL(surf)
        t_idx = time.perf_counter() - t0
        cutter = make_ocl()  # OpenCAMLib keeps a raw pointer: the object must outlive run()
        bdc.setCutter(cutter)
        for x, y in sub:
            bdc.appendPoint(ocl.CLPoint(float(x), float(y), zmin))
        t0 = time.perf_counter()
        bdc.run()
        dt = time.perf_counter() - t0
        return np.array([p.z for p in bdc.getCLPoints()]), dt, t_idx
    probe_idx = np.linspace(0, len(xy) - 1, min(200, len(xy))).astype(int)
    _, dt_probe, _ = ocl_run(xy[probe_idx])
    n_ocl = int(min(len(xy), max(200, ocl_budget_s / max(dt_probe / len(probe_idx), 1e-9))))
    sub_idx = np.linspace(0, len(xy) - 1, n_ocl).astype(int)
    zo, dt_ocl, t_idx_ocl = ocl_run(xy[sub_idx])
    ocl_pps = n_ocl / dt_ocl
    diff = float(np.abs(z[sub_idx] - zo).max())
    return dict(cutter=name, ours=ours_pps, ocl=ocl_pps, ratio=ours_pps / ocl_pps, n=len(xy), n_ocl=n_ocl,
                diff=diff, tested=tested, ocl_index_s=t_idx_ocl)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="80k meshes and the shared STL files only")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--step", type=float, default=0.5, help="CL raster step (mm)")
    ap.add_argument("--ocl-seconds", type=float, default=4.0, help="time budget per OpenCAMLib case")
    args = ap.parse_args()

    meshes = []
    for f in ("mount_rush.stl", "sphere_on_plate.stl"):
        meshes.append(lambda f=f: load_stl(STL_DIR / f))
    sizes = [200] if args.quick else [200, 500, 1000]
    for n in sizes:
        for jit in (True, False):
            meshes.append(lambda n=n, jit=jit: height_field(n, jit))

    print(f"# drop-cutter, TMM vs OpenCAMLib {ocl.version()}, {args.threads} threads, CL raster {args.step} mm")
    hdr = (f"{'mesh':32} {'tris':>8} {'build s':>8} {'B/tri':>6} {'ocl build s':>11} {'cutter':>20} "
           f"{'TMM pts/s':>11} {'OCL pts/s':>10} {'ratio':>7} {'ocl n':>7} {'max |dz| mm':>11} "
           f"{'tested':>7} {'shadow':>7}")
    print(hdr)
    print("-" * len(hdr))
    for make in meshes:
        mesh = make()
        t0 = time.perf_counter()
        index = native.MeshIndex(mesh.vertices, mesh.triangles)
        t_build = time.perf_counter() - t0
        t0 = time.perf_counter()
        surf = ocl_surface(mesh)
        xy = raster(mesh, args.step)
        zmin = float(mesh.bounds[0][2]) - 10
        for name, cutter, make_ocl in CUTTERS:
            res = run_case(mesh, surf, index, name, cutter, make_ocl, xy, args.threads, args.ocl_seconds, zmin)
            shadow = shadow_candidates(mesh, xy, cutter.max_radius)
            print(f"{mesh.name[:32]:32} {len(mesh):8d} {t_build:8.3f} {index.memory_bytes / len(mesh):6.0f} "
                  f"{res['ocl_index_s']:11.3f} {name:>20} {res['ours']:11.0f} {res['ocl']:10.0f} "
                  f"{res['ratio']:7.1f} {res['n_ocl']:7d} {res['diff']:11.2e} {res['tested']:7.1f} {shadow:7.1f}",
                  flush=True)
        del surf, index
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"# peak RSS of the whole run (both programs, all meshes): {peak_mb:.0f} MB")
    linearity(args.threads)


def linearity(threads: int) -> None:
    """Time per CL point at three raster densities on the jittered 80k mesh: flat if linear."""
    mesh = height_field(200, True)
    index = native.MeshIndex(mesh.vertices, mesh.triangles)
    cutter = CUTTERS[0][1]
    row = []
    for step in (1.0, 0.5, 0.25):
        xy = raster(mesh, step)
        t0 = time.perf_counter()
        native.drop_cutter(index, cutter, xy, -50.0, threads)
        row.append(f"{step} mm: {len(xy)} pts {1e6 * (time.perf_counter() - t0) / len(xy):.2f} us/pt")
    print("# linearity (ball d6, jittered 80k): " + "; ".join(row))


if __name__ == "__main__":
    main()
