"""GUI test of the stock collisions in TMM Simulate, run by FreeCAD itself under Xvfb:
`xvfb-run -a freecad tests/gui/gui_sim_holder.py`.

The API finishes the 40 mm deep cavity (tests/core/cavity.py) with a ball D4 on a 20 mm stick-out in an ER32 collet
chuck (the op keeps the holder clear of the design); TMM Simulate on its Job cuts the raw block, where the shank
meets material no op has cut: the panel says so, the collisions are red markers in the 3D view inside the
simulated stock's node (screenshot to env TMM_GUI_PNG), and Close removes both. The outcome goes to env
TMM_GUI_RESULT (JSON) and the exit code."""
import os
import sys
from pathlib import Path

import FreeCADGui
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import click_close, find_panel, pump, screenshot  # noqa: E402

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "sim_holder.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_sim_holder.json")


def cavity_stl(path: Path) -> str:
    from tests.core.cavity import cavity_mesh

    mesh = cavity_mesh()
    lines = ["solid cavity"]
    for f in mesh.triangles:
        lines.append(" facet normal 0 0 0\n  outer loop")
        lines += [f"   vertex {x:.9g} {y:.9g} {z:.9g}" for x, y, z in mesh.vertices[f]]
        lines.append("  endloop\n endfacet")
    lines.append("endsolid cavity")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def markers_in(scene) -> int:
    """The red markers' count in the collision node under the simulated stock's node (-1: no such node)."""
    from pivy import coin

    from tmm_workbench.gui import stock_view

    search = coin.SoSearchAction()
    search.setName(coin.SbName(stock_view.COLLISIONS_NAME))
    search.setInterest(coin.SoSearchAction.FIRST)
    search.setSearchingAll(True)
    search.apply(scene)
    path = search.getPath()
    if path is None:
        return -1
    names = [path.getNode(i).getName().getString() for i in range(path.getLength())]
    assert stock_view.NODE_NAME in names, f"the collisions are not inside the stock's node: {names}"
    node = path.getTail()
    for i in range(node.getNumChildren()):
        child = node.getChild(i)
        if child.isOfType(coin.SoMarkerSet.getClassTypeId()):
            return int(child.numPoints.getValue())
    return 0


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.gui import simulate_cmd, stock_view

    stl = cavity_stl(PNG.parent / "sim_holder_cavity.stl")
    r = run_surface(stl, tool="ballend", diameter=4.0, stepover=4.0, sample_step=0.5, boundary="model", margin=-5.0,
                    holder="SK40 ER32x70", stick_out=20.0, doc_name="TmmGuiSimHolder", progress=True)
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(r.job)
    FreeCADGui.runCommand(simulate_cmd.COMMAND_NAME)
    pump(1.0)
    sim = find_panel(simulate_cmd.PANEL_NAME)
    sim.findChild(QtGui.QDoubleSpinBox, "cell").setValue(0.5)
    sim.findChild(QtGui.QPushButton, "simulate").click()
    pump(1.0)
    info["sim_status"] = sim.findChild(QtGui.QLabel, "status").text()
    assert "holder/shank collisions with the stock" in info["sim_status"], info["sim_status"]
    scene = FreeCADGui.activeDocument().activeView().getSceneGraph()
    info["stock_node"] = stock_view.find_node(scene)
    info["markers"] = markers_in(scene)
    assert info["stock_node"] and info["markers"] > 0, info
    legend = [w.text() for w in sim.findChildren(QtGui.QLabel) if "red crosses" in w.text()]
    info["legend"] = legend
    assert legend, "no legend line for the collision markers"
    PNG.parent.mkdir(parents=True, exist_ok=True)
    screenshot(PNG)
    click_close()
    info["panel_closed"] = not FreeCADGui.Control.activeDialog()
    info["markers_after_close"] = markers_in(scene)
    info["stock_node_after_close"] = stock_view.find_node(scene)
    assert info["panel_closed"] and info["markers_after_close"] == -1 and not info["stock_node_after_close"], info
    gui_runner.close_document(r.doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
