"""Issue 14 item 7 in one run: passes and cycle time at equal maximum cusp, constant step-over against the
constant cusp mode, the adaptive raster and the 3D offset (each with and without the verification pass), on
sphere_on_plate.stl and mount_rush.stl (ball D6, cusp 0.01 mm) and seed 000's convex and concave surfaces (ball
D 0.5 in, cusp 0.002 in, a 100 x 100 mm window at the centre, then the whole surfaces); then the wait a user sees
on sphere_on_plate (OK to path and FreeCAD's linuxcnc post, through `freecadcmd` and `run_surface`) for each
spacing, "before" being the constant step-over op.

Every row is measured as `benchmarks/cusp_spacing.py` measures (its functions, not a copy): the strategies are
called through `core.strategies.raster_drop.compute` (the op's own entry), the path linked, cut into the stock
simulation beside a dense raster, and its cusp read in `core.sim.cusp_field`; the constant step-over is the
largest step whose simulated maximum cusp is the adaptive raster's (bisection, 7 rounds). The cycle time is
`core.sim.cycle_time.three_axis_time` at 1000 mm/min cutting and 300 mm/min plunging, rapids 5000 mm/min.

    .venv/bin/python benchmarks/cusp_item7.py            # all four models, then the end-to-end table
    .venv/bin/python benchmarks/cusp_item7.py --quick    # sphere_on_plate only (and the end-to-end table)
    ... --no-e2e       # without the FreeCAD table;  --no-whole: seed 000 on the window only (the whole
                       # surfaces take about 15 min more)
    ... --modes cusp   # only these rows (from stepover,cusp,adaptive,verify,offset3d,offset3d-verify), e.g. the
                       # constant cusp mode
    ... --offset3d-only  # the same as --modes offset3d,offset3d-verify --no-e2e
The end-to-end table needs `freecadcmd` and a HOME whose FreeCAD Mod/TMM is this checkout.
"""
from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field as dc_field
from pathlib import Path
from typing import Callable, Optional

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from cusp_spacing import (FEED, PLUNGE, SLOPE_LIMIT, Bisection, cycle, equal_cusp_stepover,  # noqa: E402
                          raster, verified)

from tmm_workbench.core.errors import TmmError  # noqa: E402
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.sim.cusp_field import measure  # noqa: E402
from tmm_workbench.core.strategies.surface.reference import cusp_field  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

BASE = "constant step-over"


@dataclass
class Row:
    label: str
    passes: int         # passes; closed loops for the 3D offset
    partial: int        # partial passes added by the verification
    cusp: float         # simulated maximum cusp, mm (cusp_field.measure)
    cycle_s: float
    compute_s: float    # strategy and linker
    moves: int
    note: str = ""


@dataclass
class ModelTable:
    name: str
    header: str
    rows: list[Row]
    bisection: Bisection
    failed: list[str] = dc_field(default_factory=list)  # rows a strategy refused: "label: message"

    def base(self) -> Optional[Row]:
        return next((r for r in self.rows if r.label.startswith(BASE)), None)


def _row(t: tuple, partial: int = 0, passes: Optional[int] = None, note: str = "") -> Row:
    label, n, c, cyc, secs, moves = t
    return Row(label, int(n if passes is None else passes), partial, float(c), float(cyc), float(secs), int(moves),
               note)


MODES = ("stepover", "cusp", "adaptive", "verify", "offset3d", "offset3d-verify")  # the rows, by --modes


def model_rows(name: str, mesh: TriMesh, cutter: Cutter, tol: float, cell: float, boundary=None,
               log: Callable[[str], None] = lambda s: None, modes: tuple[str, ...] = MODES) -> ModelTable:
    """Every item-7 row for one model over `boundary` (default the model's box), measured in one cusp field;
    `modes` picks the rows (the constant step-over's target is the tolerance when the adaptive row is left out)."""
    lo, hi = mesh.bounds
    if boundary is None:
        boundary = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    t0 = time.perf_counter()
    field = cusp_field(mesh, cutter, boundary, tol, cell, SLOPE_LIMIT, sample_step=0.25)
    log(f"  {name}: cusp field {time.perf_counter() - t0:.1f} s")
    found: dict[str, Row] = {}
    failed: list[str] = []

    def spacing(label: str, mode: str) -> None:
        try:
            path, secs, n = raster(mesh, cutter, boundary, stepover_mode=mode, cusp=tol, max_slope_deg=SLOPE_LIMIT)
        except TmmError as e:
            failed.append(f"{label}: {e}")
            return
        found[label] = _row((label, n, measure(field, path, cutter)[0], cycle(path), secs, len(path)))
        log(f"  {name}: {label} {secs:.1f} s")

    def checked(label: str, mode: str) -> None:
        try:
            t, diag = verified(mesh, cutter, boundary, field, mode, tol, label)
        except TmmError as e:
            failed.append(f"{label}: {e}")
            return
        v = diag["verify"]
        found[label] = _row(t, v["passes_added"], diag["passes"], f"{v['length_added'] / 1000:.2f} m partial")
        log(f"  {name}: {label} {t[4]:.1f} s")

    if "adaptive" in modes:
        spacing("adaptive", "adaptive")
    target = found["adaptive"].cusp if "adaptive" in found else tol
    bis = Bisection(None, 0.0, None, 0.0, None)
    if "stepover" in modes:
        t0 = time.perf_counter()
        bis = equal_cusp_stepover(mesh, cutter, boundary, field, target)
        if bis.row is not None:
            found[BASE] = _row(bis.row, note=f"bisection: {bis.step_lo:.3f} mm -> {_mm(bis.cusp_lo)}, "
                                              f"{bis.step_hi:.3f} mm -> {_mm(bis.cusp_hi)}")
        else:
            failed.append(f"{BASE}: no step-over in [0.02, {bis.step_hi:.3f}] mm keeps the cusp under "
                          f"{target:.4f} mm")
        log(f"  {name}: bisection {time.perf_counter() - t0:.1f} s")
    if "cusp" in modes:
        spacing("constant cusp mode", "cusp")
    if "verify" in modes:
        checked("adaptive + verify", "adaptive")
    if "offset3d" in modes:
        spacing("3D offset", "offset3d")
    if "offset3d-verify" in modes:
        checked("3D offset + verify", "offset3d")
    order = [BASE, "constant cusp mode", "adaptive", "adaptive + verify", "3D offset", "3D offset + verify"]
    rows = [found[k] for k in order if k in found]
    header = (f"{name}: {len(mesh.triangles)} triangles, {cutter.describe()}, cusp {tol:g} mm, region "
              f"{', '.join(f'{v:.1f}' for v in boundary)}; {field.share:.0%} of the cells measured "
              f"({cell:g} mm cells, slopes up to {SLOPE_LIMIT:g} deg)")
    return ModelTable(name, header, rows, bis, failed)


def _mm(c: Optional[float]) -> str:
    return "not measured" if c is None else f"{c:.4f} mm"


def ratios(row: Row, base: Optional[Row]) -> tuple[float, float]:
    """(constant step-over's passes / the row's passes + partial ones, its cycle / the row's): > 1 is better."""
    if base is None:
        return math.nan, math.nan
    return base.passes / (row.passes + row.partial), base.cycle_s / row.cycle_s


def table(models: list[ModelTable]) -> list[str]:
    out = ["| model | spacing | passes | simulated max cusp mm | cycle min | compute s | moves | passes: constant / "
           "this | cycle: constant / this |", "|---|---|---|---|---|---|---|---|---|"]
    for m in models:
        base = m.base()
        for r in m.rows:
            p, c = ratios(r, base)
            passes = f"{r.passes} + {r.partial} partial" if r.partial or "verify" in r.label else str(r.passes)
            passes += " loops" if r.label.startswith("3D offset") else ""
            label = r.label if r is not base else r.label + " (before)"
            out.append(f"| {m.name} | {label} | {passes} | {r.cusp:.4f} | {r.cycle_s / 60:.1f} | "
                       f"{r.compute_s:.1f} | {r.moves} | " + (" | |" if math.isnan(p) else f"{p:.2f}x | {c:.2f}x |"))
    return out


def notes(models: list[ModelTable]) -> list[str]:
    out = []
    for m in models:
        out.append(f"- {m.header}")
        out += [f"  - {r.label}: {r.note}" for r in m.rows if r.note]
        out += [f"  - refused: {f}" for f in m.failed]
    return out


# --- the wait a user sees (FreeCAD) ---

E2E_MODES = [("before: constant step-over", dict(stepover_mode="stepover")),
             ("constant cusp mode", dict(stepover_mode="cusp")),
             ("adaptive", dict(stepover_mode="adaptive")),
             ("adaptive + verify", dict(stepover_mode="adaptive", verify_cusp=True)),
             ("3D offset", dict(stepover_mode="offset3d"))]


def end_to_end(stepover: float, timeout_s: float = 3600) -> list[str]:
    """The second table, from `benchmarks/cusp_item7_e2e.py` under freecadcmd (sphere_on_plate, ball D6, cusp
    0.01 mm, 0.25 mm sampling; the constant step-over at `stepover`)."""
    env = dict(os.environ, TMM_ITEM7_STEPOVER=repr(stepover), TMM_ITEM7_ROOT=str(HERE.parent))
    done = subprocess.run(["freecadcmd", "-c", f"exec(open({str(HERE / 'cusp_item7_e2e.py')!r}).read())"],
                          env=env, cwd=str(HERE.parent), capture_output=True, text=True, timeout=timeout_s)
    rows = [ln for ln in done.stdout.splitlines() if ln.startswith("|")]
    if done.returncode != 0 or not rows:
        return [f"end-to-end run failed (exit {done.returncode}):", done.stdout[-2000:], done.stderr[-2000:]]
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="sphere_on_plate only")
    ap.add_argument("--no-e2e", action="store_true", help="without the FreeCAD end-to-end table")
    ap.add_argument("--window", type=float, default=100.0,
                    help="seed 000: the side in mm of the square region centred on the surface (0: the whole)")
    ap.add_argument("--no-whole", action="store_true", help="seed 000 on the window only, not also on the whole")
    ap.add_argument("--offset3d-only", action="store_true",
                    help="the same as --modes offset3d,offset3d-verify --no-e2e")
    ap.add_argument("--modes", default=",".join(MODES),
                    help=f"the rows to measure, comma-separated from {','.join(MODES)} (e.g. --modes cusp: the "
                         f"constant cusp mode rows only)")
    args = ap.parse_args()
    if args.offset3d_only:
        args.modes, args.no_e2e = "offset3d,offset3d-verify", True
    modes = tuple(m.strip() for m in args.modes.split(",") if m.strip())
    if not modes or any(m not in MODES for m in modes):
        ap.error(f"--modes must name rows from {','.join(MODES)}, got {args.modes!r}")

    def log(s: str) -> None:
        print(s, file=sys.stderr, flush=True)

    print(f"# cycle time: three_axis_time, cutting {FEED * 60:g} mm/min, plunge {PLUNGE * 60:g} mm/min; load: "
          f"{os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} (1, 5, 15 min)", flush=True)
    t_start = time.perf_counter()
    stl = shared_dir() / "benchmarks" / "stl"
    models: list[ModelTable] = []
    ball6 = Cutter.ball(6.0)
    sop = model_rows("sphere_on_plate", load_stl(stl / "sphere_on_plate.stl"), ball6, 0.01, 0.1, log=log,
                     modes=modes)
    models.append(sop)
    print("\n".join(table([sop]) + notes([sop])), flush=True)
    if not args.no_e2e and sop.bisection.row is not None:
        print(f"\n# the wait a user sees, sphere_on_plate through freecadcmd (run_surface, linuxcnc post); before: "
              f"constant step-over {sop.bisection.step_lo:.3f} mm", flush=True)
        print("\n".join(end_to_end(sop.bisection.step_lo)), flush=True)
    if not args.quick:
        def add(m: ModelTable) -> None:  # each model's table as soon as it is measured
            models.append(m)
            print("\n" + "\n".join(table([m]) + notes([m])), flush=True)

        add(model_rows("mount_rush", load_stl(stl / "mount_rush.stl"), ball6, 0.01, 0.1, log=log, modes=modes))
        from seed000_surfaces import INCH, seed000_mesh
        windows = [args.window] + ([] if args.no_whole or not args.window else [0.0])
        for side in windows:
            for name in ("convex", "concave"):
                mesh, _ = seed000_mesh(name)
                lo, hi = mesh.bounds
                c, h = 0.5 * (lo + hi), 0.5 * side
                region = (float(c[0] - h), float(c[1] - h), float(c[0] + h), float(c[1] + h)) if side else None
                where = f"{side:g} mm window" if side else "whole"
                add(model_rows(f"seed 000 {name}, {where}", mesh, Cutter.ball(0.5 * INCH), 0.002 * INCH, 0.2,
                               boundary=region, log=log, modes=modes))
        print("\n# all models")
        print("\n".join(table(models) + notes(models)), flush=True)
    print(f"\n# {time.perf_counter() - t_start:.0f} s in all; load: {os.getloadavg()[0]:.2f} "
          f"{os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}", flush=True)


if __name__ == "__main__":
    main()
