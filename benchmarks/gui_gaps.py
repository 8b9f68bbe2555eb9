"""OK to path shown and the longest gap between two runs of FreeCAD's event loop, on a large Surface op under
Xvfb (tests/gui/gui_gaps.py: a 10 ms QTimer records when the event loop ran while the op recomputes, the GUI
progress dialog on), also the time of one field edit in the op's panel and of its tmm_linuxcnc post. Each
`label=HOME` runs FreeCAD with that HOME (its Mod/TMM link names the TMM to measure), side by side.

    python3 benchmarks/gui_gaps.py now=$HOME                     # mount_rush, step-over 0.015 mm, sample 0.05 mm
    TMM_GAPS_STEPOVER=0.3 TMM_GAPS_SAMPLE=0.1 python3 benchmarks/gui_gaps.py before=/tmp/home-old now=$HOME
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402

STL = Path(os.environ.get("TMM_GAPS_STL") or benchmark_file("stl", "mount_rush.stl"))


def run(home: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "gaps.json"
        env = dict(os.environ, HOME=home, TMM_GUI_RESULT=str(result), QTWEBENGINE_DISABLE_SANDBOX="1",
                   TMM_GAPS_STL=str(STL), TMM_GAPS_STEPOVER=os.environ.get("TMM_GAPS_STEPOVER", "0.015"),
                   TMM_GAPS_SAMPLE=os.environ.get("TMM_GAPS_SAMPLE", "0.05"),
                   TMM_GAPS_CANCEL=os.environ.get("TMM_GAPS_CANCEL", "0"))
        subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad",
                        str(ROOT / "tests" / "gui" / "gui_gaps.py")], env=env, cwd=tmp, timeout=3600,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return json.loads(result.read_text()) if result.is_file() else {"error": "no result"}


def main(args: list[str]) -> None:
    runs = [a.split("=", 1) for a in args] or [["now", os.environ["HOME"]]]
    print(f"{STL.name}, step-over {os.environ.get('TMM_GAPS_STEPOVER', '0.015')} mm, sample step "
          f"{os.environ.get('TMM_GAPS_SAMPLE', '0.05')} mm")
    print("| TMM | moves | OK to path shown s | longest gap s | (at s) | field edit s | tmm_linuxcnc post s |")
    print("|---|---|---|---|---|---|---|")
    for label, home in runs:
        r = run(home)
        if not r.get("ok"):
            print(f"| {label} | failed: {str(r.get('error', ''))[-300:]} |")
            continue
        gap, at = r["gaps_and_when"][0]
        print(f"| {label} | {r['moves']} | {r['ok_to_path_shown_s']:.1f} | {gap:.2f} | {at:.1f} | "
              f"{r['edit_s']:.2f} | {r['post_s']:.2f} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
