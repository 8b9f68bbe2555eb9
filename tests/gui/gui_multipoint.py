"""GUI test of the 5-axis op (issue 15 item 4), run by FreeCAD itself under Xvfb:
`xvfb-run -a freecad tests/gui/gui_multipoint.py`.

The API makes a 5-axis op with the side step from a scallop on seed 001's convex patch; its view shows the
tool axes (every n-th position, coloured by contact status: the colours counted against the op's results),
hidden and shown again by the view property, every position with AxisEvery 1, tilt colours; the task panel
opens with the Scallop field (mm) and the Scallop spacing, warns as a fixed side step wider than the tool
cuts is typed (and not with the scallop rule), and fits a 1000 px screen; a screenshot with the
axes goes to env TMM_GUI_PNG (default docs/gui/multipoint_axes.png); TMM Simulate on the Job simulates the
5-axis path and shows its numbers. The outcome goes to env TMM_GUI_RESULT (JSON) and the exit code.
"""
import os
import sys
from pathlib import Path

import FreeCADGui
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import click_close, close_panel, find_panel, pump, screenshot  # noqa: E402

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "multipoint_axes.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_multipoint.json")


def colours_of(vp) -> list:
    sep = vp.axes_switch.getChild(0)
    material = sep.getChild(1)
    return [tuple(round(c, 3) for c in material.diffuseColor[i].getValue())
            for i in range(material.diffuseColor.getNum())]


def legend_lines(vp) -> list:
    """The texts of the axes' legend under the op's axes switch."""
    from pivy import coin

    search = coin.SoSearchAction()
    search.setType(coin.SoText2.getClassTypeId())
    search.setInterest(coin.SoSearchAction.ALL)
    search.apply(vp.axes_switch)
    paths = search.getPaths()
    texts = [paths[i].getTail().string for i in range(paths.getLength())]
    return [t[t.getNum() - 1].getString() for t in texts]


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.app.api import run_multipoint
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.preview.tool_axes import CONTACT_RGB
    from tmm_workbench.core.shared_data import benchmark_file
    from tmm_workbench.gui import simulate_cmd
    from tmm_workbench.gui.op_multipoint_gui import ViewProvider

    net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
    r = run_multipoint(net, scallop=0.5, forward_step=6.0, posts=(), doc_name="TmmGuiMultipointAxes",
                       progress=True)
    op, vobj = r.op, r.op.ViewObject
    clone = op.Base[0][0]
    face = (getattr(clone, "Objects", None) or [clone])[0]  # what the user sees: the Job's model is a clone of it
    assert face.ViewObject.Visibility, "the face is hidden before any simulation"
    assert isinstance(vobj.Proxy, ViewProvider), type(vobj.Proxy)
    vp = vobj.Proxy
    good = r.results.status != 2
    info["positions"] = int(good.sum())
    info["every"] = int(vobj.AxisEvery)
    info["axes_shown"] = vp.axis_count()
    assert vobj.ShowToolAxes and info["axes_shown"] == len(range(0, info["positions"], info["every"])), info
    # contact colours: one per drawn position, green two contacts, orange one
    status = r.results.status[good][::info["every"]]
    want = [tuple(round(c, 3) for c in CONTACT_RGB[int(s)]) for s in status]
    info["contact_colours_match"] = colours_of(vp) == want
    assert info["contact_colours_match"], "the axes' colours are not the positions' contact status"
    vobj.ShowToolAxes = False
    pump(0.2)
    info["axes_hidden"] = vp.axis_count()
    assert info["axes_hidden"] == 0, info
    vobj.ShowToolAxes = True
    pump(0.2)
    info["legend_lines"] = legend_lines(vp)
    assert info["legend_lines"][:2] == ["tool axes: contact", "green: two contacts"], info["legend_lines"]
    vobj.Visibility = False  # the axes hide with their op (not only with ShowToolAxes)
    pump(0.2)
    info["axes_op_hidden"] = vp.axis_count()
    vobj.Visibility = True
    pump(0.2)
    info["axes_op_shown"] = vp.axis_count()
    assert info["axes_op_hidden"] == 0 and info["axes_op_shown"] == info["axes_shown"], info
    vobj.AxisEvery = 1
    pump(0.2)
    info["axes_every_1"] = vp.axis_count()
    assert info["axes_every_1"] == info["positions"], info
    vobj.AxisColouring = "Tilt"
    pump(0.2)
    tilt_colours = colours_of(vp)
    info["tilt_colours_distinct"] = len(set(tilt_colours))
    assert info["tilt_colours_distinct"] > 10, info  # a ramp over the tilts, not the two contact colours
    vobj.AxisEvery = 3
    # the panel: Scallop spacing and field with its unit, fits without scrolling
    vobj.Document.setEdit(vobj, 0)
    pump(1.0)
    page = find_panel("TmmMultipointOpPage")
    spacing = page.findChild(QtGui.QComboBox, "passSpacing")
    info["pass_spacing"] = [spacing.currentText(), [spacing.itemText(i) for i in range(spacing.count())]]
    assert info["pass_spacing"] == ["Scallop", ["Even", "Fixed", "Scallop"]], info["pass_spacing"]
    scallop = page.findChild(QtGui.QWidget, "scallop")
    info["scallop_field"] = [scallop.property("rawValue"), scallop.property("unit")]
    assert abs(info["scallop_field"][0] - 0.5) < 1e-9, info["scallop_field"]
    # a fixed side step wider than the tool cuts is warned as it is typed, before any compute
    warning = page.findChild(QtGui.QLabel, "sideStepWarning")
    info["warning_scallop"] = warning.isVisible()
    spacing.setCurrentIndex(spacing.findText("Fixed"))
    side = page.findChild(QtGui.QWidget, "sideStep")
    side.setProperty("rawValue", 30.0)
    pump(0.3)
    info["warning_fixed_30"] = [warning.isVisible(), warning.text()]
    side.setProperty("rawValue", 20.0)
    pump(0.3)
    info["warning_fixed_20"] = warning.isVisible()
    assert not info["warning_scallop"] and not info["warning_fixed_20"], info
    assert info["warning_fixed_30"][0] and "uncut strips" in info["warning_fixed_30"][1], info
    spacing.setCurrentIndex(spacing.findText("Scallop"))
    side.setProperty("rawValue", 30.0)
    pump(0.3)
    info["warning_scallop_30"] = warning.isVisible()
    assert not info["warning_scallop_30"], info
    side.setProperty("rawValue", 18.0)
    info["page_height"] = page.sizeHint().height()
    assert info["page_height"] < 760, f"the 5-axis page needs {info['page_height']} px"
    task_view = next(w for w in FreeCADGui.getMainWindow().findChildren(QtGui.QScrollArea)
                     if w.isVisible() and w.widget() is not None and w.widget().isAncestorOf(page))
    info["task_panel_height"] = task_view.widget().sizeHint().height()
    assert info["task_panel_height"] <= 1000, f"the task panel needs {info['task_panel_height']} px"
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(0.5)
    screenshot(PNG)
    info["png"] = str(PNG)
    close_panel(op)
    # TMM Simulate shows the 5-axis result
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(r.job)
    FreeCADGui.runCommand(simulate_cmd.COMMAND_NAME)
    pump(1.0)
    sim = find_panel(simulate_cmd.PANEL_NAME)
    sim.findChild(QtGui.QDoubleSpinBox, "cell").setValue(1.0)
    sim.findChild(QtGui.QPushButton, "simulate").click()
    pump(1.0)
    info["sim_status"] = sim.findChild(QtGui.QLabel, "status").text()
    info["sim_max_left"] = sim.findChild(QtGui.QLabel, "maxLeft").property("value")
    info["sim_min_deviation"] = sim.findChild(QtGui.QLabel, "minDeviation").property("value")
    assert info["sim_max_left"] is not None, f"TMM Simulate gave no 5-axis result: {info['sim_status']}"
    # the face and the axes out of the way of the coloured stock, back on Close
    info["sim_face_visible"], info["sim_axes"] = bool(face.ViewObject.Visibility), vp.axis_count()
    assert not info["sim_face_visible"] and info["sim_axes"] == 0, info
    screenshot(PNG.with_name("multipoint_simulate.png"))
    click_close()
    info["closed_face_visible"], info["closed_axes"] = bool(face.ViewObject.Visibility), vp.axis_count()
    assert info["closed_face_visible"] and info["closed_axes"] > 0, info
    gui_runner.close_document(r.doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
