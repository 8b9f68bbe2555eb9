"""What FreeCAD itself spends, in one C++ call the event loop cannot interrupt, when an op's Path is set: the
`Path.Path(list)` of the commands and the assignment to the Path property (its copy and ViewProviderPath's
rebuild of every command's segments, done whether the object is shown or hidden), then the first render, on a
synthetic straight-move path of N commands, under Xvfb. It bounds the longest event-loop gap any add-on can reach
on an op of N moves: ViewProviderPath::updateData rebuilds the whole path on each Path change.

    python3 benchmarks/path_property_gap.py [N ...]      # default 250000 1000000
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RESULT = "TMM_PPG_RESULT"


def measure_in_freecad() -> None:
    """Runs inside the FreeCAD GUI (started by main): writes the timings as JSON and quits."""
    import FreeCAD
    import FreeCADGui
    import Path as FcPath
    from PySide import QtCore, QtGui

    def session() -> None:
        out: dict = {}
        try:
            doc = FreeCAD.newDocument("gap")
            for n in [int(v) for v in os.environ["TMM_PPG_SIZES"].split()]:
                for shown in (True, False):
                    obj = doc.addObject("Path::Feature", "P")
                    obj.ViewObject.Visibility = shown
                    cmds = [FcPath.Command("G1", {"X": (j % 1000) * 0.05, "Y": (j // 1000) * 0.05,
                                                  "Z": 0.01 * (j % 7), "F": 1000.0}) for j in range(n)]
                    t0 = time.monotonic()
                    path = FcPath.Path(cmds)
                    t1 = time.monotonic()
                    obj.Path = path
                    t2 = time.monotonic()
                    QtGui.QApplication.processEvents()
                    FreeCADGui.updateGui()
                    t3 = time.monotonic()
                    out[f"{n} {'shown' if shown else 'hidden'}"] = [t1 - t0, t2 - t1, t3 - t2]
                    doc.removeObject(obj.Name)
                    del cmds, path
                    QtGui.QApplication.processEvents()
        except Exception as exc:  # reported to the runner, which prints it
            out["error"] = repr(exc)
        with open(os.environ[RESULT], "w") as f:
            json.dump(out, f)
        QtGui.QApplication.quit()

    QtCore.QTimer.singleShot(1000, session)


def main(sizes: list[str]) -> None:
    sizes = sizes or ["250000", "1000000"]
    with tempfile.TemporaryDirectory() as tmp:
        result = Path(tmp) / "ppg.json"
        env = dict(os.environ, TMM_PPG_SIZES=" ".join(sizes), QTWEBENGINE_DISABLE_SANDBOX="1")
        env[RESULT] = str(result)
        subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad", __file__], env=env,
                       cwd=tmp, timeout=3600, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        r = json.loads(result.read_text()) if result.is_file() else {"error": "no result"}
    if "error" in r:
        sys.exit(f"failed: {r['error']}")
    print("| commands | object | Path.Path(list) s | obj.Path = path s (copy + view rebuild) | first events s |")
    print("|---|---|---|---|---|")
    for key, (make, assign, events) in r.items():
        n, shown = key.split()
        print(f"| {int(n):,} | {shown} | {make:.2f} | {assign:.2f} | {events:.2f} |")


if os.environ.get(RESULT):
    measure_in_freecad()
elif __name__ == "__main__":
    main(sys.argv[1:])
