"""Cost of dropping the whole tool assembly (cutter + shank + holder, with clearances) against the cutter alone.

    .venv/bin/python benchmarks/drop_assembly.py              # the table (about a minute)
    .venv/bin/python benchmarks/drop_assembly.py --quick      # coarser rasters
    .venv/bin/python benchmarks/drop_assembly.py --threads 0  # all cores, wall-clock time
    .venv/bin/python benchmarks/drop_assembly.py --tilted     # only the tilted axis (3+2), a few seconds
    .venv/bin/python benchmarks/drop_assembly.py --tilted --repeats 1 --save before.npz   # then, with a new build:
    .venv/bin/python benchmarks/drop_assembly.py --tilted --repeats 1 --compare before.npz  # owners equal, travels 1e-9
    valgrind --tool=callgrind .venv/bin/python benchmarks/drop_assembly.py --one 3:assembly   # instructions of one
        tilted batch of case 3 (sphere_on_plate; cases 0-4 in the table's order; :cutter, :load the mesh only,
        whose count is subtracted)

Per case: the same raster of CL points dropped with native.drop_cutter (the cutter alone) and with
native.drop_assembly (cutter, shank and holder), the median of a few runs each; their ratio (the target: at most
1.5), the share of points the shank or holder lifted, and how far they lifted the tool at most. Then the drop
along a direction 20 deg off -Z (native.drop_along against native.drop_assembly_along, a raster 4 times
coarser) with the tool axis against the direction (3+2: the vertical drop in the rotated frame) and tilted 15 deg
from it (the grown pieces as convex solids; the cutter then cut where the first body starts). Cases: real STL
files from the shared benchmark folder and a synthetic deep pocket where the holder sets the height. By default
one thread and the process's CPU time, which other jobs on the machine disturb less than wall-clock time.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.kernel import native  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402


def pocket_mesh(cells: int, size: float = 120.0, pocket: float = 50.0, depth: float = 40.0):
    """A plate `size` wide at z = 0 with a square pocket `pocket` wide and `depth` deep with a domed floor,
    as a height field of cells^2 quads (steep walls one cell wide)."""
    g = np.linspace(-size / 2, size / 2, cells + 1)
    x, y = np.meshgrid(g, g, indexing="ij")
    inside = (np.abs(x) < pocket / 2) & (np.abs(y) < pocket / 2)
    z = np.where(inside, -depth + 5 * np.cos(x / 8) * np.cos(y / 8), 0.0)
    v = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    a = (i * (cells + 1) + j).ravel()
    b, c, d = a + cells + 1, a + 1, a + cells + 2
    return v, np.concatenate([np.column_stack([a, b, c]), np.column_stack([c, b, d])]).astype(np.int32)


def raster(lo, hi, step: float) -> np.ndarray:
    """Zig-zag raster rows over the XY box, as a path would visit them."""
    xs = np.arange(lo[0], hi[0] + 1e-9, step)
    rows = []
    for k, y in enumerate(np.arange(lo[1], hi[1] + 1e-9, step)):
        row = np.column_stack([xs if k % 2 == 0 else xs[::-1], np.full(xs.size, y)])
        rows.append(row)
    return np.concatenate(rows)


def median_time(fn, repeats: int, clock=time.perf_counter) -> tuple[float, object]:
    """The median time of `repeats` runs (other jobs on a shared machine spoil single runs either way)."""
    times, out = [], None
    for _ in range(repeats):
        t0 = clock()
        out = fn()
        times.append(clock() - t0)
    return float(np.median(times)), out


def rotation(axis, angle: float) -> np.ndarray:
    """Rotation by `angle` (rad) about the unit `axis` (Rodrigues)."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def along_setup(v, f, cutter, bodies, xy):
    """The drop along a direction 20 deg off -Z: the direction, its index, the starts 10 mm above the part, the
    axis tilted 15 deg from -direction and the cutter alone along it (a solid up to where the first body
    starts, as in the assembly)."""
    direction = rotation([1.0, 0.3, 0.0], np.radians(20)) @ np.array([0.0, 0.0, -1.0])
    index = native.DirectionalIndex(v, f, direction)
    starts = np.column_stack([xy, np.full(len(xy), float(v[:, 2].max()) + 10.0)])
    tilted = rotation([0.0, 1.0, 0.0], np.radians(15)) @ -direction
    finite = native.Cutter.apt(cutter.radius, cutter.corner_radius, float(bodies[0][0]), 0.0, 0.0)
    return direction, index, starts, tilted, finite


def direction_rows(name, v, f, cutter, bodies, xy, repeats, threads, clock, tilted_only=False,
                   arrays=None) -> list[str]:
    """Cutter alone against the assembly along a direction 20 deg off -Z, the axis against it and tilted (or
    the tilted axis alone). `arrays` (or None): each drop's travels and owners stored under the row's label."""
    direction, index, starts, tilted, finite = along_setup(v, f, cutter, bodies, xy)
    rows = []
    axes = (("axis -V", -direction, cutter), ("axis tilted 15", tilted, finite))
    for label, axis, alone in axes[1:] if tilted_only else axes:
        t0, c = median_time(lambda: native.drop_along(index, alone, starts, axis, np.inf, threads), repeats, clock)
        t1, (a, by) = median_time(lambda: native.drop_assembly_along(index, cutter, bodies, starts, axis,
                                                                     threads=threads), repeats, clock)
        lifted = by >= 0
        assert np.all(a <= c + 1e-9), "the assembly travels further than its cutter"
        short = f"{name.split(', ')[0]}, {name.split(', ')[-1]}, {label}"
        if arrays is not None:
            arrays.update({f"{short} cutter": c, f"{short} travel": a, f"{short} owner": by})
        rows.append(f"{short:62s} {len(f):7d} {len(xy):8d} {t0:9.3f} {t1:10.3f} {t1 / t0:6.2f} "
                    f"{lifted.mean():7.1%} {np.max(np.where(np.isfinite(c), c - a, 0.0)):8.2f}")
    return rows


def cases(quick: bool):
    stl = shared_dir() / "benchmarks" / "stl"
    step = 0.5 if quick else 0.25
    ball6 = native.Cutter(3.0, 3.0)
    # (z0, z1, r0, r1, clearance) above the tip: shank from the flutes' end, then a holder.
    shank_holder = lambda stick, shank_r, holder_r: np.array([  # noqa: E731
        [stick - 15.0, stick, shank_r, shank_r, 0.5],
        [stick, stick + 60.0, holder_r, holder_r, 2.0]])
    tapered_neck = lambda stick: np.array([  # noqa: E731
        [12.0, stick - 10.0, 2.5, 2.5, 0.5],
        [stick - 10.0, stick, 2.5, 8.0, 1.0],
        [stick, stick + 60.0, 16.0, 16.0, 2.0]])
    m = load_stl(stl / "mount_rush.stl")
    yield "mount_rush, ball d6, stick-out 25, holder r15", m.vertices, m.triangles, ball6, shank_holder(25, 3, 15), step
    yield "mount_rush, ball d6, neck cone + holder r16", m.vertices, m.triangles, ball6, tapered_neck(30), step
    m = load_stl(stl / "wheel_in_box.stl")
    yield "wheel_in_box, ball d6, stick-out 30, holder r20", m.vertices, m.triangles, ball6, shank_holder(30, 3, 20), 2 * step
    m = load_stl(stl / "sphere_on_plate.stl")
    yield "sphere_on_plate, bull d10 r2, stick-out 20, holder r25", m.vertices, m.triangles, native.Cutter(5.0, 2.0), \
        shank_holder(20, 5, 25), step
    v, f = pocket_mesh(300 if quick else 600)
    yield "deep pocket 40 deep, ball d6, stick-out 25, holder r20", v, f, ball6, shank_holder(25, 3, 20), \
        2 * step


def one_batch(spec: str) -> None:
    """One tilted batch of one case, for an instruction count: "N:cutter", "N:assembly" or "N:load" (no drop)."""
    k, what = spec.split(":")
    name, v, f, cutter, bodies, step = list(cases(False))[int(k)]
    lo, hi = v.min(axis=0), v.max(axis=0)
    _, index, starts, tilted, finite = along_setup(v, f, cutter, bodies, raster(lo[:2], hi[:2], 4 * step))
    if what == "cutter":
        native.drop_along(index, finite, starts, tilted, np.inf, 1)
    elif what == "assembly":
        native.drop_assembly_along(index, cutter, bodies, starts, tilted, threads=1)
    elif what != "load":
        sys.exit(f"--one: what must be cutter, assembly or load, got {what!r}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--threads", type=int, default=1, help="0: all cores (then wall-clock time)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--tilted", action="store_true", help="only the drop along a direction with the axis tilted")
    ap.add_argument("--save", metavar="NPZ", help="store the drops along the direction (travels, owners)")
    ap.add_argument("--compare", metavar="NPZ", help="check them array for array against a --save of another build")
    ap.add_argument("--one", metavar="N:WHAT", help="one tilted batch of case N (cutter | assembly | load), for callgrind")
    args = ap.parse_args()
    if args.one:
        one_batch(args.one)
        return
    arrays = {} if args.save or args.compare else None
    clock = time.process_time if args.threads == 1 else time.perf_counter
    head = f"{'case':62s} {'tri':>7s} {'points':>8s} {'cutter s':>9s} {'assembly s':>10s} {'ratio':>6s} " \
           f"{'lifted':>7s} {'max lift':>8s}"
    if not args.tilted:
        print(head)
        print("-" * len(head))
    along = []
    for name, v, f, cutter, bodies, step in cases(args.quick):
        lo, hi = v.min(axis=0), v.max(axis=0)
        if args.tilted:
            along += direction_rows(name, v, f, cutter, bodies, raster(lo[:2], hi[:2], 4 * step), args.repeats,
                                    args.threads, clock, tilted_only=True, arrays=arrays)
            continue
        index = native.MeshIndex(v, f)
        xy = raster(lo[:2], hi[:2], step)
        floor = float(lo[2]) - 1.0
        t0, z0 = median_time(lambda: native.drop_cutter(index, cutter, xy, floor, args.threads), args.repeats, clock)
        t1, (z1, by) = median_time(lambda: native.drop_assembly(index, cutter, bodies, xy, floor,
                                                                threads=args.threads), args.repeats, clock)
        lifted = by >= 0
        assert np.all(z1 >= z0) and np.array_equal(z1[~lifted], z0[~lifted])
        print(f"{name:62s} {len(f):7d} {len(xy):8d} {t0:9.3f} {t1:10.3f} {t1 / t0:6.2f} "
              f"{lifted.mean():7.1%} {np.max(z1 - z0):8.2f}", flush=True)
        along += direction_rows(name, v, f, cutter, bodies, raster(lo[:2], hi[:2], 4 * step),
                                max(3, args.repeats // 2), args.threads, clock, arrays=arrays)
    print("\nalong a direction 20 deg off -Z (travel; 'max lift' = how much earlier the assembly stops)")
    print(head)
    print("-" * len(head))
    for row in along:
        print(row)
    if args.save:
        np.savez(args.save, **arrays)
    if args.compare:
        compare(arrays, args.compare)


def compare(arrays: dict, path: str, tol: float = 1e-9) -> None:
    """Exits with an error naming every array that differs from (or is missing in) the saved file: owners must be
    equal, travels within `tol` mm (each travel array that is not identical is named with its largest difference)."""
    saved = np.load(path)
    bad = []
    for k in arrays:
        if k not in saved:
            bad.append(k)
            print(f"differs from {path}: {k} (missing)")
            continue
        a, b = arrays[k], saved[k]
        if np.array_equal(a, b):
            continue
        n = int(np.sum(a != b))
        same_inf = np.array_equal(np.isfinite(a), np.isfinite(b))
        gap = float(np.max(np.abs(np.where(np.isfinite(a), a - b, 0.0)))) if same_inf else np.inf
        within = not k.endswith(" owner") and gap <= tol
        print(f"{'within' if within else 'differs from'} {path}: {k} ({n} of {a.size} differ, at most {gap:.3g} mm)")
        if not within:
            bad.append(k)
    if bad:
        sys.exit(1)
    print(f"all {len(arrays)} arrays identical to {path} or within {tol:g} mm")


if __name__ == "__main__":
    main()
