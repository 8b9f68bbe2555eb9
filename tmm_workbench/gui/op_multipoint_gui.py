"""GUI of the 'TMM 5-axis Multipoint' operation: its task panel page, view provider and command.

Same pattern as op_surface_gui: PathOpGui.SetupOperation registers `Path_TMM_Multipoint`; the command creates
the op with our view provider (icon from the add-on's file). The op has base geometry (`Base`: one Bézier or
B-spline face), so PathOpGui's TaskPanel adds its stock Base Geometry page; a face selected before the
command is taken as the op's Base.
"""
from __future__ import annotations

from typing import Any

import FreeCAD
import FreeCADGui
from PySide import QtCore

from tmm_workbench.app import op_multipoint
from tmm_workbench.app.compat import import_gui
from tmm_workbench.gui import op_surface_gui, resources

PathOpGui = import_gui("op_gui")
PathGui = import_gui("path_gui")

ICON = resources.icon("TMM_Multipoint")
# widget name -> property
SPIN_BOXES = {"sideStep": "SideStep", "forwardStep": "ForwardStep", "feedAngle": "FeedAngle",
              "boundaryMargin": "BoundaryMargin", "tiltLimit": "TiltLimit", "tolerance": "Tolerance",
              "axisRetract": "AxisRetract", "surfaceExtension": "SurfaceExtension"}
COMBOS = {"method": "Method", "toolShape": "ToolShape", "footprintAnchor": "FootprintAnchor"}


class TaskPanelOpPage(PathOpGui.TaskPanelPage):
    """Tool controller, coolant, method, footprint and tilt parameters; contact summary and status."""

    def getForm(self) -> Any:
        return FreeCADGui.PySideUic.loadUi(resources.panel("multipoint_op"))

    def setIcon(self, icon: Any) -> None:
        super().setIcon(ICON)

    def initPage(self, obj: Any) -> None:
        self.spins = {prop: PathGui.QuantitySpinBox(getattr(self.form, widget), obj, prop)
                      for widget, prop in SPIN_BOXES.items()}
        for widget, prop in COMBOS.items():
            combo = getattr(self.form, widget)
            combo.clear()
            combo.addItems(obj.getEnumerationsOfProperty(prop))

    def getFields(self, obj: Any) -> None:
        for spin in self.spins.values():
            spin.updateProperty()
        for widget, prop in COMBOS.items():
            value = getattr(self.form, widget).currentText()
            if value and getattr(obj, prop) != value:
                setattr(obj, prop, value)
        zigzag = self.form.zigZag.isChecked()
        if bool(obj.ZigZag) != zigzag:
            obj.ZigZag = zigzag
        self.updateToolController(obj, self.form.toolController)
        self.updateCoolant(obj, self.form.coolantController)

    def setFields(self, obj: Any) -> None:
        for spin in self.spins.values():
            spin.updateSpinBox()
        for widget, prop in COMBOS.items():
            self.selectInComboBox(getattr(obj, prop), getattr(self.form, widget))
        self.form.zigZag.setChecked(bool(obj.ZigZag))
        self.setupToolController(obj, self.form.toolController)
        self.setupCoolant(obj, self.form.coolantController)
        self.showStatus(obj)

    def showStatus(self, obj: Any) -> None:
        try:
            self._show_status(obj)
        except RuntimeError:  # the panel was closed (its widgets are gone) while the op recomputed
            pass

    def _show_status(self, obj: Any) -> None:
        self.form.contacts.setText(obj.ContactSummary)
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
        signals += [self.form.zigZag.stateChanged, self.form.toolController.currentIndexChanged,
                    self.form.coolantController.currentIndexChanged]
        return signals

    def updateData(self, obj: Any, prop: str) -> None:
        if prop in self.spins:
            self.spins[prop].updateSpinBox()
        elif prop in ("Path", "ContactSummary"):
            self.showStatus(obj)


class ViewProvider(op_surface_gui.ViewProvider):
    """The TMM op view provider with this op's icon. Any face may be picked (the op checks its surface)."""

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
    """op_surface_gui.create with this op's view provider."""
    doc = FreeCAD.ActiveDocument
    doc.openTransaction(f"Create {res.name}")
    try:
        obj = res.objFactory(res.name, obj=None, parentJob=res.job)
        if obj.Proxy:
            vp = obj.ViewObject.Proxy
            if not isinstance(vp, ViewProvider):
                obj.ViewObject.Proxy = vp = ViewProvider(obj.ViewObject, res)
            vp.deleteOnReject = True
            obj.ViewObject.Visibility = True
            doc.commitTransaction()
            obj.ViewObject.Document.setEdit(obj.ViewObject, 0)
            return obj
    except op_surface_gui.PathUtils.PathNoTCExistsException:
        from PySide import QtGui

        QtGui.QMessageBox.warning(FreeCADGui.getMainWindow(), "TMM",
                                  "No suitable tool controller found (a bullnose or ballend tool is "
                                  "needed).\nAborting op creation")
    except op_surface_gui.PathOp.PathNoTCException:
        FreeCAD.Console.PrintWarning("TMM: no tool controller, aborting op creation\n")
    doc.abortTransaction()
    doc.recompute()
    return None


Command = PathOpGui.SetupOperation(
    op_multipoint.OP_NAME, op_multipoint.Create, TaskPanelOpPage, ICON,
    QtCore.QT_TRANSLATE_NOOP("TMM_Multipoint", "TMM 5-axis Multipoint"),
    QtCore.QT_TRANSLATE_NOOP("TMM_Multipoint", "5-axis finishing of a Bézier or B-spline face with a toroidal "
                                               "cutter by multipoint positioning (select the face first)"),
    op_multipoint.SetupProperties)
COMMAND_NAME = "Path_" + op_multipoint.OP_NAME
Command.Activated = lambda: create(Command.res)
