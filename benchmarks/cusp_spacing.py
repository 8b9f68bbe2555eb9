"""Passes and cycle time at equal maximum cusp (issue 14): the 3-axis Surface raster spaced adaptively (each pass
from the previous one's CL points) against a constant step-over chosen so that its simulated maximum cusp is
the same, and against the constant cusp mode (the planar step-over at the steepest crossing).

The maximum cusp of every raster is measured the same way, independently of how it was placed: the raster and a
dense raster (0.1 mm apart) are cut into the stock simulation (core.sim, 0.1 mm cells), and the cusp is the
largest difference along the normal where the slope is at most the cusp slope limit and the dense raster comes
within the tolerance of the model (elsewhere the tool cannot reach: not a cusp): core.sim.cusp_field. The rows
"+ verify" are the constant cusp mode and the adaptive raster with the verification pass (issue 14 item 4,
core.strategies.surface.variable_step: partial passes added where the simulated cusp exceeds the tolerance).

    .venv/bin/python benchmarks/cusp_spacing.py            # sphere_on_plate and mount_rush, ball D6, 0.01 mm
    .venv/bin/python benchmarks/cusp_spacing.py --quick    # sphere_on_plate only
    .venv/bin/python benchmarks/cusp_spacing.py --quick --offset3d-only   # only the 3D offset row (and the
                                                           # dense raster it is measured against)
    .venv/bin/python benchmarks/cusp_spacing.py --seed000  # seed 000's convex and concave surfaces (ball D 0.5 in,
                                                           # cusp 0.002 in; benchmarks/seed000_surfaces.py)
    ... --reference   # the adaptive passes placed by the numpy reference (as before the kernel port) to compare
    .venv/bin/python benchmarks/cusp_spacing.py --cusp-mode-only   # only the constant cusp mode row (and its
                                                           # dense raster), sphere_on_plate and mount_rush
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.sim.cusp_field import measure  # noqa: E402
from tmm_workbench.core.strategies.surface.reference import cusp_field  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CELL = 0.1
SLOPE_LIMIT = 75.0
FEED, PLUNGE = 1000.0 / 60, 300.0 / 60  # mm/s


def raster(mesh, cutter, boundary, sample_step=0.25, **kw):
    """The linked raster, the seconds it took (strategy and linker: what a user waits for before the post) and
    its pass count."""
    t0 = time.perf_counter()
    result = compute(mesh, cutter, SurfaceParams(boundary=boundary, sample_step=sample_step, **kw))
    top = float(mesh.bounds[1][2])
    path = link(result.segments, LinkPolicy(top + 5, top + 10))
    return path, time.perf_counter() - t0, result.diagnostics["passes"]


def cycle(path) -> float:
    tips = np.array([[m.x, m.y, m.z] for m in path.moves])
    return three_axis_time(tips, toolpath_feeds(path, FEED, PLUNGE)).seconds


@dataclass
class Bisection:
    """The largest constant step-over whose simulated maximum cusp is at most `target`: `row` (None when no
    step in the range got there), the bracket (step_lo, cusp_lo) <= target < (step_hi, cusp_hi) (a cusp None
    where that end was never measured: the range's own ends)."""
    row: Optional[tuple]
    step_lo: float
    cusp_lo: Optional[float]
    step_hi: float
    cusp_hi: Optional[float]


def equal_cusp_stepover(mesh, cutter: Cutter, boundary, field, target: float, rounds: int = 7) -> Bisection:
    """Bisection on the step-over between 0.02 mm and the planar step for the field's tolerance, each step's
    raster measured in `field`."""
    lo_s, hi_s = 0.02, 2 * math.sqrt(2 * cutter.radius * field.tolerance)
    cusp_lo = cusp_hi = best = None
    for _ in range(rounds):
        s = 0.5 * (lo_s + hi_s)
        path, secs, n = raster(mesh, cutter, boundary, stepover=s)
        c, _ = measure(field, path, cutter)
        if c <= target:
            lo_s, cusp_lo, best = s, c, (f"constant step-over {s:.3f} mm", n, c, cycle(path), secs, len(path))
        else:
            hi_s, cusp_hi = s, c
    return Bisection(best, lo_s, cusp_lo, hi_s, cusp_hi)


def verified(mesh, cutter: Cutter, boundary, field, mode: str, tol: float, label: str) -> tuple[tuple, dict]:
    """The row of the `mode` raster with the verification pass, and the strategy's diagnostics."""
    t0 = time.perf_counter()
    result = compute(mesh, cutter, SurfaceParams(boundary=boundary, sample_step=0.25, stepover_mode=mode, cusp=tol,
                                                 max_slope_deg=SLOPE_LIMIT, verify_cusp=True))
    top = float(mesh.bounds[1][2])
    path = link(result.segments, LinkPolicy(top + 5, top + 10))
    secs, v = time.perf_counter() - t0, result.diagnostics["verify"]
    c, _ = measure(field, path, cutter)
    return (label, f"{result.diagnostics['passes']} + {v['passes_added']} partial ({v['length_added'] / 1000:.2f} m)",
            c, cycle(path), secs, len(path)), result.diagnostics


def run(name: str, mesh, cutter: Cutter, tol: float, cell: float = CELL, boundary=None,
        offset3d_only: bool = False, cusp_mode_only: bool = False) -> list[str]:
    """The table for one model; `cell` is the simulation's cell and the dense raster's step-over (its own cusp
    is negligible against `tol`); `boundary` (x0, y0, x1, y1) the region, by default the model's box."""
    lo, hi = mesh.bounds
    if boundary is None:
        boundary = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    # measured inside, clear of the boundary's edges by the tool radius (the passes' ends)
    field = cusp_field(mesh, cutter, boundary, tol, cell, SLOPE_LIMIT, sample_step=0.25)

    rows = []
    if cusp_mode_only:  # the constant cusp mode (core.footprint.cusp_section) alone, with its step's diagnostics
        result = compute(mesh, cutter, SurfaceParams(boundary=boundary, sample_step=0.25, stepover_mode="cusp",
                                                     cusp=tol, max_slope_deg=SLOPE_LIMIT))
        d = result.diagnostics
        path, secs, n = raster(mesh, cutter, boundary, stepover_mode="cusp", cusp=tol, max_slope_deg=SLOPE_LIMIT)
        c, share = measure(field, path, cutter)
        rows.append((f"constant cusp mode {d['stepover']:.4f} mm (planar {d['cusp_planar_stepover']:.4f}; section "
                     f"rule's worst {d['cusp_section']:.4f}{', limited' if d['cusp_limited'] else ''})", n, c,
                     cycle(path), secs, len(path)))
        return _table(name, mesh, cutter, tol, share, rows)
    # --- 3D offset (constant scallop loops from the boundary inward; core.footprint.offset3d) ---
    path, secs, n = raster(mesh, cutter, boundary, stepover_mode="offset3d", cusp=tol, max_slope_deg=SLOPE_LIMIT)
    c, share = measure(field, path, cutter)
    rows.append(("3D offset (loops)", n, c, cycle(path), secs, len(path)))
    if offset3d_only:
        return _table(name, mesh, cutter, tol, share, rows)
    path, secs, n_adaptive = raster(mesh, cutter, boundary, stepover_mode="adaptive", cusp=tol,
                                    max_slope_deg=SLOPE_LIMIT)
    cusp, share = measure(field, path, cutter)
    rows.append(("adaptive", n_adaptive, cusp, cycle(path), secs, len(path)))

    path, secs, n = raster(mesh, cutter, boundary, stepover_mode="cusp", cusp=tol, max_slope_deg=SLOPE_LIMIT)
    c, _ = measure(field, path, cutter)
    rows.append(("constant cusp mode", n, c, cycle(path), secs, len(path)))

    # the constant step-over whose simulated maximum cusp is the adaptive raster's (bisection on the step)
    best = equal_cusp_stepover(mesh, cutter, boundary, field, cusp).row
    if best is not None:
        rows.append(best)

    # --- the verification pass (issue 14 item 4, core.strategies.surface.variable_step): partial passes where the
    # simulated cusp exceeds the tolerance; passes shown as the set's + the partial ones
    for label, mode in (("constant cusp mode + verify", "cusp"), ("adaptive + verify", "adaptive")):
        row, _ = verified(mesh, cutter, boundary, field, mode, tol, label)
        rows.append(row)

    out = _table(name, mesh, cutter, tol, share, rows)
    if best is not None:
        out.append(f"passes: constant step-over at the same max cusp / adaptive = {best[1] / n_adaptive:.2f}")
    return out


def _table(name, mesh, cutter, tol, share, rows) -> list[str]:
    out = [f"\n{name}: {len(mesh.triangles)} triangles, {cutter.describe()}, cusp {tol:g} mm (slopes up to "
           f"{SLOPE_LIMIT:g} deg; {share:.0%} of the cells measured)",
           "| spacing | passes | simulated max cusp mm | cycle min | compute s | moves |", "|---|---|---|---|---|---|"]
    for label, n, c, t, secs, moves in rows:
        out.append(f"| {label} | {n} | {c:.4f} | {t / 60:.1f} | {secs:.1f} | {moves} |")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="sphere_on_plate only")
    ap.add_argument("--offset3d-only", action="store_true", help="only the 3D offset row")
    ap.add_argument("--seed000", action="store_true", help="seed 000's convex and concave surfaces only")
    ap.add_argument("--cusp-mode-only", action="store_true", help="only the constant cusp mode row")
    ap.add_argument("--window", type=float, default=100.0,
                    help="with --seed000: the side in mm of the square region centred on the surface (0: all of "
                         "its 254 x 270 mm, which takes hours in the Python adaptive raster)")
    ap.add_argument("--reference", action="store_true",
                    help="place the adaptive passes with the numpy reference instead of the kernel")
    args = ap.parse_args()
    if args.reference:  # the strategy imported the function by name: swap it there
        from tests.core import adaptive_raster_reference
        from tmm_workbench.core.strategies.surface import pattern
        pattern.adaptive_pass_offsets = adaptive_raster_reference.adaptive_pass_offsets
    if args.seed000:
        from seed000_surfaces import INCH, seed000_mesh
        for name in ("convex", "concave"):
            mesh, deviation = seed000_mesh(name)
            lo, hi = mesh.bounds
            c, h = 0.5 * (lo + hi), 0.5 * args.window
            region = (float(c[0] - h), float(c[1] - h), float(c[0] + h), float(c[1] + h)) if args.window else None
            print(f"\nseed 000 {name}: ruled through its two cubic B-spline sections, mesh within {deviation:.4f} mm; "
                  f"region {region or 'the whole surface'}")
            print("\n".join(run(f"seed 000 {name}", mesh, Cutter.ball(0.5 * INCH), 0.002 * INCH, cell=0.2,
                                 boundary=region)), flush=True)
        return
    stl = shared_dir() / "benchmarks" / "stl"
    cases = [("sphere_on_plate", stl / "sphere_on_plate.stl")]
    if not args.quick:
        cases.append(("mount_rush", stl / "mount_rush.stl"))
    for name, path in cases:
        print("\n".join(run(name, load_stl(path), Cutter.ball(6.0), 0.01, offset3d_only=args.offset3d_only,
                             cusp_mode_only=args.cusp_mode_only)), flush=True)


if __name__ == "__main__":
    main()
