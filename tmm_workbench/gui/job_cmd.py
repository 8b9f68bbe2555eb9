"""Command 'TMM Job from mesh/STL': a Path Job for the selected mesh or Part object, or for an STL
file picked in a dialog (read into a Mesh object, so it shows in the 3D view). Meshes get TMM's
stand-in box as the Job model (see app/model_proxy.py); FreeCAD's own Path_Job covers solids."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.app import job as jobs
from tmm_workbench.app.compat import import_gui
from tmm_workbench.gui import form_wrappers, resources

COMMAND_NAME = "TMM_JobFromModel"


def _selected_model() -> Optional[Any]:
    for o in FreeCADGui.Selection.getSelection():
        if o.isDerivedFrom("Mesh::Feature") or o.isDerivedFrom("Part::Feature"):
            return o
    return None


class CommandJobFromModel:
    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": resources.icon("TMM_JobFromModel"),
                "MenuText": QtCore.QT_TRANSLATE_NOOP("TMM_JobFromModel", "Job from mesh / STL"),
                "ToolTip": QtCore.QT_TRANSLATE_NOOP(
                    "TMM_JobFromModel", "Start here: creates a Path Job for the selected mesh or Part object, or "
                    "for an STL file, with a 6 mm ball end mill and its feeds, and opens the Job's panel on its "
                    "stock (a mesh gets a hidden stand-in box of its bounds as the Job's model)")}

    def IsActive(self) -> bool:
        return True

    def Activated(self) -> None:
        model: Any = _selected_model()
        if model is None:
            name, _ = QtGui.QFileDialog.getOpenFileName(FreeCADGui.getMainWindow(), "STL file", "",
                                                        "STL (*.stl *.STL);;All files (*)")
            if not name:
                return
        try:
            create_job_gui(import_stl(name) if model is None else model)
        except Exception as exc:  # noqa: BLE001 - a box, one report line, the traceback in the log
            from tmm_workbench.gui import messages

            messages.report("TMM Job from model", exc)


def import_stl(path: str) -> Any:
    import Mesh

    doc = FreeCAD.ActiveDocument or FreeCAD.newDocument()
    obj = doc.addObject("Mesh::Feature", Path(path).stem)
    obj.Mesh = Mesh.Mesh(path)
    return obj


def create_job_gui(model: Any, open_panel: bool = True) -> Any:
    """The Job with PathJobGui's view provider (what Path_Job would make for a solid), a ball end mill with feeds
    in its tool controller, its stock shown, and (`open_panel`) the Job's panel open on the stock, where a new
    user sets it up."""
    doc = model.Document if hasattr(model, "Document") else (FreeCAD.ActiveDocument or FreeCAD.newDocument())
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    FreeCAD.setActiveDocument(doc.Name)
    job = import_gui("job_gui").Create([jm.job_base], None, openTaskPanel=False)
    jobs.set_default_post(job)  # not FreeCAD's first post in the list
    jobs.start_tool(job)
    doc.recompute()
    if job.Stock is not None and job.Stock.ViewObject is not None:
        job.Stock.ViewObject.Visibility = True
    proxy = job.ViewObject.Proxy
    if open_panel and hasattr(proxy, "editObject") and not FreeCADGui.Control.activeDialog():
        proxy.deleteOnReject = False  # Cancel closes the panel, the Job stays
        proxy.editObject(job.Stock)
        panel = getattr(proxy, "taskPanel", None)
        if panel is not None and hasattr(panel, "cleanup"):  # 0.20 to 1.1's Job panel
            forget_form_on_close(panel)
    return job


def forget_form_on_close(panel: Any) -> None:
    """FreeCAD's Job panel stays alive after it closes, holding the wrappers of its deleted widgets (handed out for
    the next widgets at those addresses: a crash on 1.1): they leave PySide's map once Qt has deleted them."""
    cleanup = panel.cleanup

    def cleanup_and_forget(resetEdit: bool) -> Any:
        try:
            return cleanup(resetEdit)
        finally:
            form = getattr(panel, "form", None)
            if form is not None:
                QtCore.QTimer.singleShot(0, lambda: form_wrappers.forget(form))

    panel.cleanup = cleanup_and_forget


FreeCADGui.addCommand(COMMAND_NAME, CommandJobFromModel())
