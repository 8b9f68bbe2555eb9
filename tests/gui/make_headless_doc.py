"""Run by `freecadcmd` before the GUI smoke test: a document made headless with the API (no view
providers saved), for the GUI to reopen. Output: env TMM_GUI_REOPEN. Exit code 1 on failure."""
import os
import sys
import traceback
from pathlib import Path

try:
    sys.path.insert(0, str(Path(globals().get("__file__") or sys.argv[-1]).resolve().parents[2]))
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.core.shared_data import benchmark_file

    run_surface(os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl")),
                stepover=3.0, sample_step=1.5, progress=False, doc_name="TmmHeadless",
                fcstd_path=os.environ["TMM_GUI_REOPEN"])
    code = 0
except BaseException:  # noqa: B902
    traceback.print_exc()
    code = 1
raise SystemExit(code)
