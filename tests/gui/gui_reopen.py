"""GUI test of a saved document's reopening, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_reopen.py`.

One Job with each TMM op the API makes (3-axis Surface, Roughing, Waterline on a mesh; 5-axis Multipoint on a Bézier
face in a second document), saved, closed and reopened: the report view gets no error while the documents load
(FreeCAD 0.20 printed "setAttr failed" for each tool controller). Before saving, the Surface op's panel: a good
Apply's undo step is named after the op ("Edit <label>"), not "TMM operation". The report view's text after each reopen goes
to env TMM_GUI_RESULT (JSON) with the exit code."""
import os
import sys
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402
from gui_runner import pump  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import close_panel  # noqa: E402


RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_reopen.json")


def report_view() -> QtGui.QTextEdit:
    return FreeCADGui.getMainWindow().findChild(QtGui.QTextEdit, "Report view")


def reopened_messages(path: Path, name: str) -> str:
    """The report view's text from opening `path` (its document `name` closed first)."""
    gui_runner.close_document(FreeCAD.getDocument(name))
    report = report_view()
    report.clear()
    doc = FreeCAD.openDocument(str(path))
    pump(1.0)
    text = report.toPlainText()
    gui_runner.close_document(doc)
    return text


def applied_undo_steps(op) -> list:
    """The op's panel: Apply (commits what opening the panel wrote), a change (the op's comment), Apply: the undo
    steps, newest first (then Cancel). Apply is what the task view calls on its button (panel.clicked)."""
    op.Label = "Finish sphere"
    op.Document.clearUndos()  # the stack keeps the last 20 steps: only the panel's from here
    op.ViewObject.Document.setEdit(op.ViewObject, 0)
    pump(1.0)
    panel = op.ViewObject.Proxy.panel
    panel.clicked(QtGui.QDialogButtonBox.Apply)
    pump(0.5)
    op.Comment = "finish after the roughing"
    panel.clicked(QtGui.QDialogButtonBox.Apply)
    pump(0.5)
    steps = list(op.Document.UndoNames)
    close_panel(op)
    return steps


def run(out: Path) -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.app import api
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.shared_data import benchmark_file

    stl = os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl"))
    r = api.run_surface(stl, stepover=3.0, sample_step=1.0, doc_name="TmmGuiReopen", progress=False)
    api.run_roughing(job=r, tool="endmill", diameter=6.0, step_down=10.0, stepover_percent=80.0,
                     progress=False)
    api.run_waterline(job=r, tool="ballend", diameter=6.0, step_down=10.0, sample_step=1.0, progress=False)
    net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
    m = api.run_multipoint(net, scallop=1.0, forward_step=10.0, posts=(), doc_name="TmmGuiReopen5", progress=False)
    info["ops"] = sorted(o.Name for o in r.doc.Objects if o.Name.startswith("TMM_"))
    info["undo"] = applied_undo_steps(r.op)
    for doc, key in ((r.doc, "mesh"), (m.doc, "face")):
        path = out / f"{doc.Name}.FCStd"
        doc.saveAs(str(path))
        info[f"{key}_messages"] = reopened_messages(path, doc.Name)
    return info


gui_runner.run(lambda info: info.update(run(RESULT.parent)), RESULT)
