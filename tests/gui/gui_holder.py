"""GUI test of the whole tool's pictures and command, run by FreeCAD itself under Xvfb:
`xvfb-run -a freecad tests/gui/gui_holder.py`.

A Surface op (API) with a ball D4 on a 20 mm stick-out in an ER32 collet chuck over the 40 mm deep cavity of
tests/core/cavity.py: its view draws the places the holder left (HolderRegions) as points, one per region point,
hidden and shown again by the view property ShowHolderRegions; TMM Shortest stick-out on the Job shows its box
with the op's shortest stick-out; a screenshot goes to env TMM_GUI_PNG (default out/gui/holder_regions.png).
The outcome goes to env TMM_GUI_RESULT (JSON) and the exit code.
"""
import os
import sys
from pathlib import Path

import FreeCADGui
from PySide import QtCore, QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
sys.path.insert(0, str(ROOT / "tests" / "freecad"))
_single_shot = QtCore.QTimer.singleShot
QtCore.QTimer.singleShot = staticmethod(lambda *args: None)  # the smoke script's helpers, not its run
try:
    import gui_smoke  # noqa: E402,F401 (loads the smoke script's helpers)
    from gui_smoke import pump, screenshot  # noqa: E402
finally:
    QtCore.QTimer.singleShot = _single_shot

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "holder_regions.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_holder.json")


def run() -> dict:
    info: dict = {}
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    FreeCADGui.activateWorkbench("TMMWorkbench")
    pump(0.5)
    from fc_test_holder import FAST, HOLDER, cavity_stl
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.gui import holder_regions_view, stick_out_cmd

    r = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmGuiHolder", **{**FAST, "progress": True})
    vobj = r.op.ViewObject
    vp = vobj.Proxy
    info["regions"] = len(r.op.HolderRegions)
    info["drawn"] = holder_regions_view.drawn(vp.regions_switch)
    assert info["regions"] > 10 and info["drawn"] == info["regions"], info
    vobj.ShowHolderRegions = False
    pump(0.2)
    info["drawn_hidden"] = holder_regions_view.drawn(vp.regions_switch)
    vobj.ShowHolderRegions = True
    pump(0.2)
    info["drawn_again"] = holder_regions_view.drawn(vp.regions_switch)
    assert info["drawn_hidden"] == 0 and info["drawn_again"] == info["regions"], info
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(0.5)
    screenshot(PNG)
    info["png"] = str(PNG)
    # the command on the Job: its box names the op and the stick-out
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(r.job)
    pump(0.2)
    info["command_active"] = bool(FreeCADGui.Command.get(stick_out_cmd.COMMAND_NAME).isActive())
    FreeCADGui.runCommand(stick_out_cmd.COMMAND_NAME)
    pump(1.0)
    boxes = [w for w in QtGui.QApplication.topLevelWidgets()
             if isinstance(w, QtGui.QMessageBox) and w.objectName() == stick_out_cmd.BOX_NAME and w.isVisible()]
    info["box"] = boxes[0].text() if boxes else ""
    assert info["command_active"] and r.op.Label in info["box"] and "stick-out" in info["box"], info
    for box in boxes:
        box.close()
    gui_runner.close_document(r.doc)
    return info


import gui_runner  # noqa: E402

gui_runner.run(lambda info: info.update(run()), RESULT)
