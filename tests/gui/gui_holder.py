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
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
sys.path.insert(0, str(ROOT / "tests" / "freecad"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import close_panel, find_panel, pump, screenshot  # noqa: E402

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "holder_regions.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_holder.json")


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from fc_test_holder import FAST, HOLDER, cavity_stl
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.gui import region_marks_view, stick_out_cmd

    r = run_surface(cavity_stl(), holder=HOLDER, stick_out=20.0, doc_name="TmmGuiHolder", **{**FAST, "progress": True})
    vobj = r.op.ViewObject
    vp = vobj.Proxy
    info["regions"] = len(r.op.HolderRegions)
    info["drawn"] = region_marks_view.drawn(vp.mark_switches, "HolderRegions")
    assert info["regions"] > 10 and info["drawn"] == info["regions"], info
    vobj.ShowHolderRegions = False
    pump(0.2)
    info["drawn_hidden"] = region_marks_view.drawn(vp.mark_switches, "HolderRegions")
    vobj.ShowHolderRegions = True
    pump(0.2)
    info["drawn_again"] = region_marks_view.drawn(vp.mark_switches, "HolderRegions")
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
    # a rest op after it: its rest cells drawn; its panel offers the Job's other tool controller as reference
    rest = run_surface(job=r.job, tool="ballend", diameter=3.0, stepover=0.3, region="rest", sample_step=0.5,
                       boundary="model", progress=False, post=None)
    rvp = rest.op.ViewObject.Proxy
    info["rest_marks"] = len(rest.op.RestRegions)
    info["rest_drawn"] = region_marks_view.drawn(rvp.mark_switches, "RestRegions")
    assert info["rest_marks"] > 10 and info["rest_drawn"] == info["rest_marks"], info
    r.op.ViewObject.Visibility = False   # its marks hide with it
    pump(0.2)
    info["hidden_op_drawn"] = region_marks_view.drawn(vp.mark_switches, "HolderRegions")
    assert info["hidden_op_drawn"] == 0, info
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(0.5)
    screenshot(PNG.with_name("rest_regions.png"))
    rest.op.ViewObject.Document.setEdit(rest.op.ViewObject, 0)
    pump(1.0)
    page = find_panel("TmmSurfaceOpPage")
    reference = page.findChild(QtGui.QComboBox, "restReference")
    info["reference_items"] = [reference.itemText(i) for i in range(reference.count())]
    info["rest_from"] = page.findChild(QtGui.QComboBox, "restFrom").currentText()
    assert info["rest_from"] == "EarlierOps" and r.op.ToolController.Label in info["reference_items"], info
    close_panel(rest.op)
    gui_runner.close_document(r.doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
