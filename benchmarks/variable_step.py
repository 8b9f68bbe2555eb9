"""Seed 003's variable side-step experiment (section 4.1), reproduced on a relief of our own (mount_rush.stl),
and the verification pass of issue 14 item 4 (core.strategies.surface.variable_step) beside it.

The seed: a ball of radius 1/8 in, a zig-zag raster at a side step of 1/40 in, the surface divided into 20 x 20 mm
buckets; the buckets whose scallop is above the work piece's average are machined again with a side step of
1/64 in; the maximum scallop fell from 0.153 to 0.098 mm, the total by 5 %. Here the same tool and side steps on
mount_rush.stl, the buckets 20 x 20 mm over its box, every scallop measured the same way (core.sim.cusp_field:
the path and a dense raster cut into the z-map, along the normal, slopes up to 75 deg, reachable cells only):
  - "raster 1/40 in": the raster alone;
  - "seed 003 buckets": plus a 1/64 in raster over each bucket whose mean scallop is above the average;
  - "verify": the raster with VerifyCusp at the tolerance the 1/40 in side step gives on a plane (partial
    passes only in the gaps and stretches whose simulated cusp exceeds it).

    .venv/bin/python benchmarks/variable_step.py            # the whole model (84 x 40 mm)
    .venv/bin/python benchmarks/variable_step.py --quick    # a 40 x 20 mm window at its centre
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.footprint.cusp import plane_cusp  # noqa: E402
from tmm_workbench.core.strategies.surface.variable_step import measure_cell  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.strategies.surface.reference import cusp_field  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

INCH = 25.4
BALL = Cutter.ball(2 * INCH / 8)            # radius 1/8 in
SIDE, FINE = INCH / 40, INCH / 64           # the seed's side steps
BUCKET = 20.0                               # mm
SAMPLE = 0.25


def cut_length(segments) -> float:
    return float(sum(np.linalg.norm(np.diff(s.tips, axis=0), axis=1).sum() for s in segments))


def passes(segments) -> int:
    return sum(1 for s in segments if not s.joined)  # pieces cut after a lift


def run(mesh, region, label: str) -> list[str]:
    tol = plane_cusp(BALL, SIDE, 0.0)
    cell = measure_cell(BALL, tol)
    top = float(mesh.bounds[1][2])
    policy = LinkPolicy(top + 6, top + 10)
    field = cusp_field(mesh, BALL, region, tol, cell, sample_step=cell)
    grid = field.grid
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    nbx = max(1, round((region[2] - region[0]) / BUCKET))
    nby = max(1, round((region[3] - region[1]) / BUCKET))
    bx = np.clip(((X - region[0]) / BUCKET).astype(int), 0, nbx - 1)
    by = np.clip(((Y - region[1]) / BUCKET).astype(int), 0, nby - 1)
    bucket_of = by * nbx + bx

    def stats(heights):
        c = field.cusp(heights)
        ok = np.isfinite(c)
        return (float(np.nanmax(c)), float(np.clip(c[ok], 0, None).sum() * grid.cell_area), int(np.sum(c[ok] > tol)))

    rows = []
    t0 = time.perf_counter()
    base = compute(mesh, BALL, SurfaceParams(boundary=region, stepover=SIDE, sample_step=SAMPLE))
    secs = time.perf_counter() - t0
    h0 = field.cut(link(base.segments, policy), BALL)
    rows.append(("raster 1/40 in", len(base.segments), passes(base.segments), cut_length(base.segments), *stats(h0),
                 secs))

    # seed 003: buckets whose mean scallop is above the average, machined again at 1/64 in
    c0 = field.cusp(h0)
    ok = np.isfinite(c0)
    mean = float(c0[ok].mean())
    chosen = [b for b in range(nbx * nby) if np.any(ok & (bucket_of == b))
              and float(c0[ok & (bucket_of == b)].mean()) > mean]
    t0 = time.perf_counter()
    extra = []
    for b in chosen:
        i, j = b % nbx, b // nbx
        rect = (region[0] + i * BUCKET, region[1] + j * BUCKET,  # the last row and column take the rest
                region[2] if i == nbx - 1 else region[0] + (i + 1) * BUCKET,
                region[3] if j == nby - 1 else region[1] + (j + 1) * BUCKET)
        extra += compute(mesh, BALL, SurfaceParams(boundary=rect, stepover=FINE, sample_step=SAMPLE)).segments
    secs_seed = secs + time.perf_counter() - t0
    h1 = field.cut(link(extra, policy), BALL, h0.copy()) if extra else h0
    rows.append((f"seed 003 buckets ({len(chosen)} of {nbx * nby} at 1/64 in)", len(base.segments) + len(extra),
                 passes(base.segments) + passes(extra), cut_length(base.segments) + cut_length(extra), *stats(h1),
                 secs_seed))

    # the verification pass
    t0 = time.perf_counter()
    checked = compute(mesh, BALL, SurfaceParams(boundary=region, stepover=SIDE, sample_step=SAMPLE, cusp=tol,
                                                verify_cusp=True))
    secs = time.perf_counter() - t0
    v = checked.diagnostics["verify"]
    h2 = field.cut(link(checked.segments, policy), BALL)
    rows.append((f"verify ({v['buckets']} buckets, {v['rounds']} rounds)", len(checked.segments),
                 passes(checked.segments), cut_length(checked.segments), *stats(h2), secs))

    out = [f"\n{label}: {len(mesh.triangles)} triangles, region x {region[0]:.1f}..{region[2]:.1f} y {region[1]:.1f}.."
           f"{region[3]:.1f} mm, {BALL.describe()}, side step {SIDE:.3f} mm (tolerance {tol:.4f} mm, its cusp on a "
           f"plane), cells {cell:.3f} mm; {field.measured.sum()} cells measured, {field.unreachable.sum()} out of "
           f"the tool's reach, {field.steep.sum()} steeper than 75 deg",
           "| tool path | segments | lifts + 1 | cut length m | max scallop mm | scallop volume mm^3 | cells above "
           "tolerance | compute s |", "|---|---|---|---|---|---|---|---|"]
    for name, nseg, npass, length, mx, vol, above, s in rows:
        out.append(f"| {name} | {nseg} | {npass} | {length / 1000:.2f} | {mx:.4f} | {vol:.2f} | {above} | {s:.1f} |")
    out.append(f"verify: partial passes {v['passes_added']} ({v['length_added'] / 1000:.2f} m), its own measure "
               f"{v['max_cusp_before']:.4f} -> {v['max_cusp_after']:.4f} mm (crests {v['ridge_before']:.4f} -> "
               f"{v['ridge_after']:.4f}), {v['exceeding_after']} cells left above; {v['seconds']:.1f} s in the verification "
               f"(dense raster, simulation, partial passes)")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="a 40 x 20 mm window at the model's centre")
    args = ap.parse_args()
    mesh = load_stl(shared_dir() / "benchmarks" / "stl" / "mount_rush.stl")
    lo, hi = mesh.bounds
    if args.quick:
        c = 0.5 * (lo + hi)
        region = (float(c[0] - 20), float(c[1] - 10), float(c[0] + 20), float(c[1] + 10))
    else:  # whole buckets over the box
        c = 0.5 * (lo + hi)
        region = (float(c[0] - 42), float(c[1] - 20), float(c[0] + 42), float(c[1] + 20))
    print("\n".join(run(mesh, region, "mount_rush" + (" (quick)" if args.quick else ""))), flush=True)


if __name__ == "__main__":
    main()
