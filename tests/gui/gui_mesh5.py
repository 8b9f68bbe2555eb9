"""GUI test of the 5-axis mesh op, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_mesh5.py`.

The API makes a 'TMM 5-axis Mesh' op on a small patch (a convex cylinder, radius 60 mm, 24 x 24 mm, written as an
STL here) with a flat D 10; its task panel opens with the op's values (the tool holder group too), the user
types a coarser tolerance and a smaller tilt limit and presses OK: the op is kept, recomputed with them (a Path,
fewer or as many passes, its summary rewritten). The outcome goes to env TMM_GUI_RESULT (JSON) and the exit code.
"""
import math
import os
import sys
from pathlib import Path

import FreeCADGui
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import find_panel, pump  # noqa: E402

RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_mesh5.json")


def patch_stl(path: Path) -> str:
    """A convex cylinder patch (radius 60 mm, axis along X), 24 x 24 mm, as an ASCII STL."""
    z = lambda y: math.sqrt(60.0 ** 2 - y * y)  # noqa: E731
    xs, ys = [-12 + 3 * i for i in range(9)], [-12 + 0.5 * j for j in range(49)]
    lines = ["solid patch"]
    for x0, x1 in zip(xs, xs[1:]):
        for y0, y1 in zip(ys, ys[1:]):
            a, b, c, d = (x0, y0, z(y0)), (x1, y0, z(y0)), (x1, y1, z(y1)), (x0, y1, z(y1))
            for tri in ((a, b, c), (a, c, d)):
                lines += ["facet normal 0 0 1", "outer loop"] + [f"vertex {p[0]} {p[1]} {p[2]}" for p in tri] + \
                    ["endloop", "endfacet"]
    path.write_text("\n".join(lines + ["endsolid patch", ""]))
    return str(path)


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.app.api import run_mesh5

    r = run_mesh5(patch_stl(Path.cwd() / "mesh5_patch.stl"), diameter=10.0, tolerance=0.05, tilt_limit_deg=24.0,
                  yaw_limit_deg=30.0, forward_step=3.0, post=None, doc_name="TmmGuiMesh5", progress=True)
    op = r.op
    info["passes_before"] = op.Proxy.diagnostics["passes"]
    info["summary_before"] = op.Mesh5Summary
    op.ViewObject.Document.setEdit(op.ViewObject, 0)
    pump(1.0)
    page = find_panel("TmmMesh5OpPage")
    tolerance, tilt = page.findChild(QtGui.QWidget, "tolerance"), page.findChild(QtGui.QWidget, "tiltLimit")
    info["fields"] = [tolerance.property("rawValue"), tilt.property("rawValue")]
    assert abs(info["fields"][0] - 0.05) < 1e-9 and abs(info["fields"][1] - 24.0) < 1e-9, info
    # the tool holder group shows the op's whole-tool values (by default the tool controller's holder)
    holder = page.findChild(QtGui.QComboBox, "holder")
    info["holder"] = [holder.currentText(), op.Holder, [holder.itemText(i) for i in range(holder.count())]]
    info["stick_out"] = [page.findChild(QtGui.QWidget, "stickOut").property("rawValue"), op.StickOut.Value]
    info["cleanup_marks_view"] = hasattr(op.ViewObject, "ShowCleanupRegions")
    tolerance.setProperty("rawValue", 0.2)
    tilt.setProperty("rawValue", 18.0)
    pump(0.3)
    op.ViewObject.Proxy.panel.accept()  # OK: the op is kept and recomputed with the typed values
    pump(1.0)
    assert not FreeCADGui.Control.activeDialog(), "the 5-axis mesh panel stayed open"
    info["values_after"] = [op.Tolerance.Value, op.TiltLimit.Value]
    info["valid"], info["commands"] = op.isValid(), len(op.Path.Commands)
    info["passes_after"] = op.Proxy.diagnostics["passes"]
    info["summary_after"] = op.Mesh5Summary
    tips = [t for s in op.Proxy.segments for t in s.tips]
    axes = [a for s in op.Proxy.segments for a in s.axes]
    info["largest_tilt_deg"] = max(math.degrees(math.acos(min(1.0, a[2]))) for a in axes)
    info["positions"] = len(tips)
    gui_runner.close_document(r.doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
