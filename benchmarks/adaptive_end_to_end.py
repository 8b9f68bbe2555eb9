"""The time a user waits for the 3-axis Surface op with the adaptive step-over (issue 14 items 1 and 7): from OK
to the path (the op's recompute through `run_surface`: strategy, linker, Path) and FreeCAD's post, with the pass
placement in the kernel (native.adaptive_raster) and in the numpy reference (tests/core/adaptive_raster_reference.py,
as before the port), side by side. sphere_on_plate.stl, ball D6, cusp 0.01 mm, 0.25 mm sampling, as
benchmarks/cusp_spacing.py.

Run with FreeCAD's Python:
    HOME=/tmp/home-x freecadcmd -c "exec(open('benchmarks/adaptive_end_to_end.py').read())"
    TMM_E2E_KERNEL_ONLY=1 ... (skip the reference: about 3 minutes less)
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT))

from benchmarks.user_wait import user_wait  # noqa: E402
from tests.core import adaptive_raster_reference  # noqa: E402
from tmm_workbench.app.api import run_surface  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.strategies.surface import pattern  # noqa: E402


def run(label: str, out: Path, reference: bool) -> dict:
    placed = pattern.adaptive_pass_offsets
    if reference:  # the strategy imported the function by name: swap it there for the run
        pattern.adaptive_pass_offsets = adaptive_raster_reference.adaptive_pass_offsets
    try:
        t0 = time.perf_counter()
        r = run_surface(str(shared_dir() / "benchmarks" / "stl" / "sphere_on_plate.stl"), doc_name=f"e2e_{label}",
                        diameter=6.0, sample_step=0.25, stepover_mode="adaptive", cusp=0.01, progress=False,
                        gcode_path=str(out / f"{label}.ngc"))
        total = time.perf_counter() - t0
    finally:
        pattern.adaptive_pass_offsets = placed
    return user_wait(r, total, out / f"{label}_again.ngc")


def main() -> None:
    out = Path(tempfile.mkdtemp(prefix="tmm_e2e_"))
    cases = [("kernel", False)]
    if not os.environ.get("TMM_E2E_KERNEL_ONLY"):
        cases.append(("numpy reference", True))
    rows = [run(label.replace(" ", "_"), out, ref) for label, ref in cases]
    print("| pass placement | moves | G-code lines | OK to path s | post s | total s |")
    print("|---|---|---|---|---|---|")
    for (label, _), r in zip(cases, rows):
        print(f"| {label} | {r['moves']} | {r['lines']} | {r['ok_to_path']:.1f} | {r['post_s']:.1f} | {r['total']:.1f} |")


main()
