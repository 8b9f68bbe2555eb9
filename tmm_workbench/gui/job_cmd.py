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
from tmm_workbench.gui import resources

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
                    "TMM_JobFromModel", "Creates a Path Job for the selected mesh or Part object, or for "
                    "an STL file (meshes get a stand-in box as the Job model)")}

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


def create_job_gui(model: Any) -> Any:
    """The Job with PathJobGui's view provider (what Path_Job would make for a solid)."""
    doc = model.Document if hasattr(model, "Document") else (FreeCAD.ActiveDocument or FreeCAD.newDocument())
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    FreeCAD.setActiveDocument(doc.Name)
    job = import_gui("job_gui").Create([jm.job_base], None, openTaskPanel=False)
    jobs.set_default_post(job)  # not FreeCAD's first post in the list
    doc.recompute()
    return job


FreeCADGui.addCommand(COMMAND_NAME, CommandJobFromModel())
