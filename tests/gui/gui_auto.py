"""TMM Auto in the GUI, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_auto.py`.

An STL (env TMM_GUI_STL) read into a Mesh object and selected; the TMM toolbar offers TMM Auto; its panel with a
recipe (modelling foam, the draft finish, an output folder: env TMM_GUI_OUT): a tool library file that does not
exist is refused on the status line with the panel open and nothing added; a run cancelled in its progress dialog
(shown at once) leaves the document as it was, the panel open; then OK plans: the Job with its ops stays in the document,
selected, the result box names the ops and the report, the output folder holds report.html naming them.
Screenshots into env TMM_GUI_SHOTS; the outcome to env TMM_GUI_RESULT (JSON) and the exit code."""
import os
import sys
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_state")
from gui_state import click, pump, screenshot, visible, wait_closed  # noqa: E402

RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_auto.json")
OUT = Path(os.environ.get("TMM_GUI_OUT") or ROOT / "out" / "gui_auto")
STL = os.environ.get("TMM_GUI_STL", "")


def choose(name: str, value: str) -> None:
    """A combo box's item chosen by its value, as a user picks it."""
    box = visible(QtGui.QComboBox, name)
    index = box.findData(value)
    assert index >= 0, f"{name} offers no {value}"
    box.setCurrentIndex(index)


def type_text(name: str, text: str) -> None:
    edit = visible(QtGui.QLineEdit, name)
    edit.setFocus()
    edit.selectAll()
    edit.insert(text)
    pump(0.2)


def names(doc) -> list:
    return sorted(o.Name for o in doc.Objects)


def cancel_progress(seen: list) -> QtCore.QTimer:
    """Clicks Cancel on each progress dialog that shows (as a user does); their labels into `seen`."""
    def look() -> None:
        for w in QtGui.QApplication.topLevelWidgets():
            if isinstance(w, QtGui.QProgressDialog) and w.isVisible() and not w.wasCanceled():
                seen.append(w.labelText())
                w.cancel()
    timer = QtCore.QTimer()
    timer.timeout.connect(look)
    timer.start(100)
    return timer


def result_box() -> str:
    from tmm_workbench.gui import auto_cmd

    for _ in range(50):
        for w in QtGui.QApplication.topLevelWidgets():
            if w.objectName() == auto_cmd.BOX_NAME and w.isVisible():
                text = w.text()
                w.close()
                return text
        pump(0.1)
    raise AssertionError("no TMM Auto result box")


def session(info: dict) -> None:
    from tmm_workbench.gui import auto_cmd, job_cmd

    FreeCADGui.activateWorkbench("TMMWorkbench")
    pump(0.5)
    toolbar = FreeCADGui.getMainWindow().findChild(QtGui.QToolBar, "TMM")
    info["toolbar"] = [a.text() for a in toolbar.actions()]
    doc = FreeCAD.newDocument("TmmAuto")
    mesh = job_cmd.import_stl(STL)
    doc.recompute()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(mesh)
    FreeCADGui.SendMsgToActiveView("ViewFit")
    before = names(doc)
    FreeCADGui.runCommand(auto_cmd.COMMAND_NAME)
    pump(0.5)
    choose("material", "modelling_foam")
    choose("finish", "draft")
    type_text("outputDir", str(OUT))
    # a refused recipe: the status line says why, the panel stays, nothing added
    type_text("library", str(OUT.parent / "no_such_tools.yaml"))
    click(QtGui.QDialogButtonBox.Ok)
    info["refused_status"] = visible(QtGui.QLabel, "status").text()
    info["refused_panel_open"] = bool(FreeCADGui.Control.activeDialog())
    info["refused_unchanged"] = names(doc) == before
    type_text("library", "")
    # cancelled at the first progress dialog: the document as it was, the panel open
    from tmm_workbench.gui import progress_dialog

    seen: list = []
    timer = cancel_progress(seen)
    shown_after, progress_dialog.SHOW_AFTER_S = progress_dialog.SHOW_AFTER_S, 0.0   # shown at once: a fast op too
    click(QtGui.QDialogButtonBox.Ok)
    progress_dialog.SHOW_AFTER_S = shown_after
    timer.stop()
    info["cancelled_at"] = seen
    info["cancelled_status"] = visible(QtGui.QLabel, "status").text()
    info["cancelled_panel_open"] = bool(FreeCADGui.Control.activeDialog())
    info["cancelled_unchanged"] = names(doc) == before
    info["cancelled_out_exists"] = OUT.exists()
    screenshot("auto_1_panel")
    # planned
    click(QtGui.QDialogButtonBox.Ok)
    wait_closed(240)
    info["box"] = result_box()
    jobs = [o for o in doc.Objects if hasattr(o, "Operations") and hasattr(o, "Stock")]
    info["jobs"] = [j.Label for j in jobs]
    info["ops"] = [[op.Label, op.isValid(), len(op.Path.Commands)] for op in jobs[0].Operations.Group] if jobs else []
    info["selected"] = [o.Name for o in FreeCADGui.Selection.getSelection()]
    info["job_name"] = jobs[0].Name if jobs else None
    info["files"] = sorted(p.name for p in OUT.iterdir())
    info["html"] = (OUT / "report.html").read_text()
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(0.5)
    screenshot("auto_2_job")
    gui_runner.close_document(doc)


gui_runner.run(session, RESULT)
