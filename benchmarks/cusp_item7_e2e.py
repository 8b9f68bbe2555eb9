"""The wait a user sees for each spacing of the 3-axis Surface op (issue 14 item 7; run by
`benchmarks/cusp_item7.py`, which passes the constant step-over it found): `run_surface` on sphere_on_plate.stl
(ball D6, cusp 0.01 mm, 0.25 mm sampling, the op's defaults otherwise), then FreeCAD's linuxcnc post again on
the op. "OK to path" is run_surface's time less that second post (the recompute: strategy, linker, Path, as
`benchmarks/adaptive_end_to_end.py` measures it).

    HOME=/tmp/home-x TMM_ITEM7_STEPOVER=0.145 freecadcmd -c "exec(open('benchmarks/cusp_item7_e2e.py').read())"
"""
from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(os.environ.get("TMM_ITEM7_ROOT") or Path.cwd())
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from cusp_item7 import E2E_MODES  # noqa: E402
from user_wait import user_wait  # noqa: E402

from tmm_workbench.app.api import run_surface  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402


def wait(label: str, out: Path, stepover: float, **kw) -> dict:
    name = "".join(ch if ch.isalnum() else "_" for ch in label)
    t0 = time.perf_counter()
    r = run_surface(str(shared_dir() / "benchmarks" / "stl" / "sphere_on_plate.stl"), doc_name=f"item7_{name}",
                    diameter=6.0, sample_step=0.25, stepover=stepover, cusp=0.01, progress=False,
                    gcode_path=str(out / f"{name}.ngc"), **kw)
    return user_wait(r, time.perf_counter() - t0, out / f"{name}_again.ngc")


def main() -> None:
    stepover = float(os.environ["TMM_ITEM7_STEPOVER"])
    out = Path(tempfile.mkdtemp(prefix="tmm_item7_"))
    print("| spacing | moves | G-code lines | OK to path s | post s | total s | total: before / this |")
    print("|---|---|---|---|---|---|---|")
    before = None
    for label, kw in E2E_MODES:
        r = wait(label, out, stepover, **kw)
        before = before or r["total"]
        shown = f"{label} {stepover:.3f} mm" if kw["stepover_mode"] == "stepover" else label
        print(f"| {shown} | {r['moves']} | {r['lines']} | {r['ok_to_path']:.1f} | {r['post_s']:.1f} | "
              f"{r['total']:.1f} | {before / r['total']:.2f}x |", flush=True)


main()
