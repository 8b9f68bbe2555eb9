"""GUI test of a new user's first steps, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_first_steps.py`.

A new document without a Job: the TMM op buttons are grey and their tooltip says to create a Job first; the TMM
toolbars offer TMM's Job from mesh / STL, not FreeCAD's Job (which lists no mesh as a model). sphere_on_plate read
into a Mesh object and selected, *Job from mesh / STL*: the Job's panel opens with the stock shown (screenshot to env
TMM_GUI_PNG), its tool controller holds a 6 mm ball end mill with non-zero feeds, the stand-in box is hidden and
described; OK closes the panel (no dead widget wrapper kept) and the op buttons are enabled. The outcome goes to env TMM_GUI_RESULT (JSON)."""
import os
import sys
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # its helpers, not its run
from gui_smoke import pump, screenshot  # noqa: E402

gui_runner.helpers_of("gui_state")
from gui_state import click  # noqa: E402

PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui" / "first_job_panel.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_first_steps.json")


def action(text: str) -> QtGui.QAction:
    """The first visible toolbar action with menu text `text`."""
    for bar in FreeCADGui.getMainWindow().findChildren(QtGui.QToolBar):
        for a in bar.actions():
            if a.text().replace("&", "") == text and bar.isVisible():
                return a
    raise AssertionError(f"no toolbar action '{text}'")


def toolbar_texts(name: str) -> list:
    bars = [b for b in FreeCADGui.getMainWindow().findChildren(QtGui.QToolBar) if b.objectName() == name]
    return [a.text().replace("&", "") for b in bars for a in b.actions() if a.text()]


def run() -> dict:
    info: dict = {}
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.app import model_proxy, registry, tools
    from tmm_workbench.core.shared_data import benchmark_file

    doc = FreeCAD.newDocument("TmmGuiFirstSteps")
    pump(0.5)
    surface = action(registry.entry("TMM_Surface").menu_text)
    info["op_without_job"] = [surface.isEnabled(), surface.toolTip()]
    assert not surface.isEnabled() and "Job from mesh / STL" in surface.toolTip(), info["op_without_job"]
    info["path_toolbar"] = toolbar_texts("TMM Path")
    assert info["path_toolbar"] and "Job" not in info["path_toolbar"], info["path_toolbar"]
    stl = os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl"))
    mesh, job = gui_runner.job_from_stl(doc, stl)
    info["job_panel_open"] = bool(FreeCADGui.Control.activeDialog())
    info["stock_visible"] = bool(job.Stock.ViewObject.Visibility)
    tc = job.Tools.Group[0]
    info["tool"] = [tools.shape_name(tc.Tool),   # BitShape (0.20, 1.0) or ShapeID / ShapeName (1.1)
                    float(tc.Tool.Diameter.Value), tc.HorizFeed.Value, tc.VertFeed.Value, tc.SpindleSpeed]
    boxes = [o for o in doc.Objects if model_proxy.is_bounds(o)]
    info["bounds"] = [[o.Label, o.Label2, bool(o.ViewObject.Visibility)] for o in boxes]
    FreeCADGui.SendMsgToActiveView("ViewFit")
    FreeCADGui.activeDocument().activeView().viewIsometric()
    pump(0.3)
    screenshot(PNG)
    click(QtGui.QDialogButtonBox.Ok)
    info["panel_closed"] = not FreeCADGui.Control.activeDialog()
    pump(0.5)
    # FreeCAD's Job panel outlives its widgets: none of their dead wrappers may stay in PySide's map
    info["dead_wrappers_kept"] = gui_runner.dead_wrappers(found_too=False)
    gui_runner.forget_found_widgets()
    info["op_with_job"] = surface.isEnabled()
    gui_runner.close_document(doc)
    return info


gui_runner.run(lambda info: info.update(run()), RESULT)
