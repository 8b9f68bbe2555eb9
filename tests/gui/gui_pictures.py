"""GUI test of TMM Simulate's picture, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_pictures.py`.

sphere_on_plate read into a Mesh object, finished by the API with a ball D6 at 0.5 mm step-over (scallops of 0.01 mm); TMM Simulate on its Job: while the
coloured stock shows, the mesh (the model the user sees), the stand-in box and the path are hidden, and shown again
on Close; the legend's band is the tolerance (+-0.01 mm) and follows a new tolerance until the band is set itself;
the extremes beyond the band are told; Auto colours the deviation along the normal on this design with walls, whose
largest value is below the vertical one. Screenshots to env TMM_GUI_PNG (simulate_band.png) and beside it
(simulate_vertical.png). The outcome goes to env TMM_GUI_RESULT (JSON) and the exit code."""
import os
import sys
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import click_close, find_panel, pump, screenshot  # noqa: E402

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "simulate_band.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_pictures.json")


def legend(page) -> dict:
    def value(name: str):
        return page.findChild(QtGui.QLabel, name).property("value")
    return {"min": value("legendMin"), "max": value("legendMax"), "beyond": value("legendBeyond"),
            "title": page.findChild(QtGui.QLabel, "legendTitle").text(),
            "beyond_text": page.findChild(QtGui.QLabel, "legendBeyond").text()}


def visible(obj) -> bool:
    return bool(obj.ViewObject.Visibility)


def widen_panel(page) -> None:
    mw = FreeCADGui.getMainWindow()
    for dock in mw.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.isAncestorOf(page):
            mw.resizeDocks([dock], [430], QtCore.Qt.Horizontal)  # the whole panel in the picture
    pump(0.5)


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    import Mesh

    from tmm_workbench.app.api import run_surface
    from tmm_workbench.core.shared_data import benchmark_file
    from tmm_workbench.gui import simulate_cmd, stock_view

    stl = os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl"))
    doc = FreeCAD.newDocument("TmmGuiPictures")
    mesh = doc.addObject("Mesh::Feature", "sphere_on_plate")
    mesh.Mesh = Mesh.Mesh(stl)
    doc.recompute()
    r = run_surface(mesh, tool="ballend", diameter=6.0, stepover=0.5, sample_step=0.5, progress=True)
    info["mesh_visible_before"] = visible(mesh)
    assert info["mesh_visible_before"], "the mesh is hidden before any simulation"
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(r.job)
    FreeCADGui.runCommand(simulate_cmd.COMMAND_NAME)
    pump(1.0)
    page = find_panel(simulate_cmd.PANEL_NAME)
    page.findChild(QtGui.QDoubleSpinBox, "cell").setValue(0.25)
    tolerance, band = (page.findChild(QtGui.QDoubleSpinBox, n) for n in ("tolerance", "band"))
    direction = page.findChild(QtGui.QComboBox, "direction")
    info["band_default"] = [tolerance.value(), band.value(), direction.currentText()]
    page.findChild(QtGui.QPushButton, "simulate").click()
    pump(1.0)
    info["sim_status"] = page.findChild(QtGui.QLabel, "status").text()
    scene = FreeCADGui.activeDocument().activeView().getSceneGraph()
    info["stock_node"] = stock_view.find_node(scene)
    assert info["stock_node"], f"no coloured stock: {info['sim_status']}"
    info["while_shown"] = {"mesh": visible(mesh), "op": visible(r.op), "stock": visible(r.job.Stock)}
    assert not any(info["while_shown"].values()), info["while_shown"]
    info["legend_auto"] = legend(page)
    info["max_left_vertical"] = page.findChild(QtGui.QLabel, "maxLeft").property("value")
    widen_panel(page)
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(0.3)
    screenshot(PNG)
    direction.setCurrentIndex(direction.findText("Vertical"))
    pump(0.3)
    info["legend_vertical"] = legend(page)
    screenshot(PNG.with_name("simulate_vertical.png"))
    tolerance.setValue(0.02)  # the band follows the tolerance...
    info["band_after_tolerance"] = band.value()
    band.setValue(0.05)       # ...until the user sets it: then it stays
    tolerance.setValue(0.03)
    info["band_set"] = [band.value(), legend(page)["max"]]
    info["stock_node_after_recolour"] = stock_view.find_node(scene)
    info["mesh_hidden_after_recolour"] = not visible(mesh)
    click_close()
    info["after_close"] = {"mesh": visible(mesh), "op": visible(r.op), "node": stock_view.find_node(scene)}
    assert info["after_close"] == {"mesh": True, "op": True, "node": False}, info["after_close"]
    gui_runner.close_document(doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
