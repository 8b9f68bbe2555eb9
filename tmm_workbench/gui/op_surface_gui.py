"""GUI of the 'TMM 3-axis Surface' operation: its task panel page, view provider and command.

The command is registered by PathOpGui.SetupOperation like FreeCAD's own ops. PathOpGui assumes
icons inside FreeCAD's compiled Qt resources (":/icons/<pixmap>.svg"); an add-on has files instead,
so the view provider and the page give the icon's file path, and the command creates the op with
that view provider (same steps as PathOpGui.Create otherwise).
"""
from __future__ import annotations

from typing import Any

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.app import model_proxy, op_surface
from tmm_workbench.app.compat import PathOp, PathUtils, import_gui
from tmm_workbench.gui import resources

PathOpGui = import_gui("op_gui")
PathGui = import_gui("path_gui")

ICON = resources.icon("TMM_Surface")
JOB_MODEL = "(Job model)"
# widget name -> property
SPIN_BOXES = {"boundaryMargin": "BoundaryMargin", "stepOver": "StepOver", "sampleStep": "SampleStep",
              "rasterAngle": "RasterAngle", "stockToLeave": "StockToLeave",
              "linearDeflection": "LinearDeflection"}
COMBOS = {"boundaryShape": "BoundaryShape", "pattern": "Pattern"}


class TaskPanelOpPage(PathOpGui.TaskPanelPage):
    """Tool controller, coolant, model, boundary and raster parameters of the op."""

    def getForm(self) -> Any:
        return FreeCADGui.PySideUic.loadUi(resources.panel("surface_op"))

    def setIcon(self, icon: Any) -> None:
        super().setIcon(ICON)  # the view provider hands over a Qt resource path we do not ship

    def initPage(self, obj: Any) -> None:
        self.spins = {prop: PathGui.QuantitySpinBox(getattr(self.form, widget), obj, prop)
                      for widget, prop in SPIN_BOXES.items()}
        for widget, prop in COMBOS.items():
            combo = getattr(self.form, widget)
            combo.clear()
            combo.addItems(obj.getEnumerationsOfProperty(prop))
        self.form.stlFileBrowse.clicked.connect(self.browseStl)

    def model_candidates(self, obj: Any) -> list[Any]:
        """Meshes and top-level Part objects of the document, without the Job's own objects
        (model clones, stock, tool bits) and TMM's stand-in boxes."""
        job = PathUtils.findParentJob(obj)
        own = set()
        if job is not None:
            own = {o.Name for o in job.Model.Group} | {job.Stock.Name if job.Stock else ""}
        out = []
        for o in obj.Document.Objects:
            if o.Name in own or hasattr(o, "PathResource") or model_proxy.is_bounds(o):
                continue
            if o.isDerivedFrom("Mesh::Feature"):
                out.append(o)
            elif (o.isDerivedFrom("Part::Feature") and not o.isDerivedFrom("Part::Part2DObject")
                  and not hasattr(o, "BitShape") and o.getParentGeoFeatureGroup() is None
                  and not o.isDerivedFrom("PartDesign::Feature") and o.Shape.Faces):
                out.append(o)
        return out

    def browseStl(self) -> None:
        name, _ = QtGui.QFileDialog.getOpenFileName(self.form, "STL file", self.form.stlFile.text(),
                                                    "STL (*.stl *.STL);;All files (*)")
        if name:
            self.form.stlFile.setText(name)
            self.pageGetFields()

    def getFields(self, obj: Any) -> None:
        for spin in self.spins.values():
            spin.updateProperty()
        for widget, prop in COMBOS.items():
            value = getattr(self.form, widget).currentText()
            if value and getattr(obj, prop) != value:
                setattr(obj, prop, value)
        stl = self.form.stlFile.text().strip()
        if obj.StlFile != stl:
            obj.StlFile = stl
        model = self.form.model.currentData()
        target = obj.Document.getObject(model) if model else None
        if obj.Model != target:
            obj.Model = target
        self.updateToolController(obj, self.form.toolController)
        self.updateCoolant(obj, self.form.coolantController)

    def setFields(self, obj: Any) -> None:
        for spin in self.spins.values():
            spin.updateSpinBox()
        for widget, prop in COMBOS.items():
            self.selectInComboBox(getattr(obj, prop), getattr(self.form, widget))
        self.form.stlFile.setText(obj.StlFile)
        combo = self.form.model
        combo.blockSignals(True)
        combo.clear()
        combo.addItem(JOB_MODEL, "")
        for o in self.model_candidates(obj):
            combo.addItem(o.Label, o.Name)
        index = combo.findData(obj.Model.Name) if obj.Model is not None else 0
        combo.setCurrentIndex(max(index, 0))
        combo.blockSignals(False)
        self.setupToolController(obj, self.form.toolController)
        self.setupCoolant(obj, self.form.coolantController)
        self.showStatus(obj)

    def showStatus(self, obj: Any) -> None:
        if obj.isValid():
            moves = len(obj.Path.Commands)
            self.form.status.setStyleSheet("")
            self.form.status.setText(f"{moves} path commands" if moves else "")
        else:
            self.form.status.setStyleSheet("color: #c00000")
            self.form.status.setText(obj.getStatusString())

    def getSignalsForUpdate(self, obj: Any) -> list[Any]:
        signals = [getattr(self.form, w).editingFinished for w in SPIN_BOXES]
        signals += [getattr(self.form, w).currentIndexChanged for w in COMBOS]
        signals += [self.form.stlFile.editingFinished, self.form.model.currentIndexChanged,
                    self.form.toolController.currentIndexChanged,
                    self.form.coolantController.currentIndexChanged]
        return signals

    def updateData(self, obj: Any, prop: str) -> None:
        if prop in self.spins:
            self.spins[prop].updateSpinBox()
        elif prop == "Path":
            self.showStatus(obj)


class ViewProvider(PathOpGui.ViewProvider):
    """PathOpGui's view provider with the op icon read from the add-on's file, and no selection gate
    (PathSelection only knows FreeCAD's own ops; this op has no base geometry to pick)."""

    def getSelectionFactory(self) -> Any:
        return lambda: None

    def getIcon(self) -> str:
        if self.Object is not None and not self.Object.Active:
            return ":/icons/Path_OpActive.svg"
        return ICON


def attach_view_provider(obj: Any) -> None:
    """Gives an op created from Python (macro, API) the same view provider as the command's."""
    if not isinstance(getattr(obj.ViewObject, "Proxy", None), ViewProvider):
        obj.ViewObject.Proxy = ViewProvider(obj.ViewObject, Command.res)
        obj.ViewObject.Proxy.deleteOnReject = False


def create(res: Any) -> Any:
    """PathOpGui.Create with our view provider."""
    doc = FreeCAD.ActiveDocument
    doc.openTransaction(f"Create {res.name}")
    try:
        obj = res.objFactory(res.name, obj=None, parentJob=res.job)
        if obj.Proxy:
            vp = obj.ViewObject.Proxy  # usually attached already by op_surface.view_provider_hook
            if not isinstance(vp, ViewProvider):
                obj.ViewObject.Proxy = vp = ViewProvider(obj.ViewObject, res)
            vp.deleteOnReject = True  # Cancel in the first edit session removes the new op
            obj.ViewObject.Visibility = True
            doc.commitTransaction()
            obj.ViewObject.Document.setEdit(obj.ViewObject, 0)
            return obj
    except PathUtils.PathNoTCExistsException:
        QtGui.QMessageBox.warning(FreeCADGui.getMainWindow(), "TMM",
                                  "No suitable tool controller found.\nAborting op creation")
    except PathOp.PathNoTCException:
        FreeCAD.Console.PrintWarning("TMM: no tool controller, aborting op creation\n")
    doc.abortTransaction()
    doc.recompute()
    return None


Command = PathOpGui.SetupOperation(
    op_surface.OP_NAME, op_surface.Create, TaskPanelOpPage, ICON,
    QtCore.QT_TRANSLATE_NOOP("TMM_Surface", "TMM 3-axis Surface"),
    QtCore.QT_TRANSLATE_NOOP("TMM_Surface", "3-axis raster finishing of a mesh or a Part model "
                                            "(drop-cutter, TMM kernel)"),
    op_surface.SetupProperties)
COMMAND_NAME = "Path_" + op_surface.OP_NAME
# SetupOperation's command would attach PathOpGui's own view provider; keep its resources and
# registration, create through ours.
Command.Activated = lambda: create(Command.res)
