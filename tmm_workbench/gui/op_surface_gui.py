"""GUI of the 'TMM 3-axis Surface' operation: its task panel page, view provider and command (the
pattern shared with the other TMM ops is in op_page)."""
from __future__ import annotations

from typing import Any

from PySide import QtGui

from tmm_workbench.app import model_proxy, op_surface, registry, stages
from tmm_workbench.app.compat import PathUtils
from tmm_workbench.gui import offset_start_panel, op_page, pencil_panel, region_panel, resources, surface_depths_gui

ENTRY = registry.entry("TMM_Surface")
ICON = resources.icon(ENTRY.icon)
JOB_MODEL = "(Job model)"
# widget name -> property, from the op's stages (app.stages); StepOverPercent and StartPoint: surface_depths_gui
SPIN_BOXES, COMBOS, CHECKS = stages.widgets(op_surface.STAGES)


class TaskPanelOpPage(surface_depths_gui.DepthFields, op_page.OpPage):
    """Tool controller, coolant, model, boundary and raster parameters of the op."""

    PANEL = "surface_op"
    ICON = ICON
    SPIN_BOXES = SPIN_BOXES
    COMBOS = COMBOS
    CHECKS = CHECKS

    def init_extra(self, obj: Any) -> None:
        self.form.stlFileBrowse.clicked.connect(self.browseStl)
        region_panel.init_fields(self, obj)
        pencil_panel.init_fields(self, obj)

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

    def get_extra(self, obj: Any) -> None:
        stl = self.form.stlFile.text().strip()
        if obj.StlFile != stl:
            obj.StlFile = stl
        model = self.form.model.currentData()
        target = obj.Document.getObject(model) if model else None
        if obj.Model != target:
            obj.Model = target
        region_panel.get_fields(self, obj)
        pencil_panel.get_fields(self, obj)
        offset_start_panel.get_fields(self, obj)
        self.get_depths(obj)

    def set_extra(self, obj: Any) -> None:
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
        region_panel.set_fields(self, obj)
        pencil_panel.set_fields(self, obj)
        offset_start_panel.set_fields(self, obj)
        self.set_depths(obj)

    def extra_signals(self) -> list[Any]:
        return ([self.form.stlFile.editingFinished, self.form.model.currentIndexChanged] + region_panel.signals(self)
                + self.depth_signals() + offset_start_panel.signals(self) + pencil_panel.signals(self))

    def updateData(self, obj: Any, prop: str) -> None:
        super().updateData(obj, prop)
        if prop in surface_depths_gui.ENABLING:
            self.enable_depths(obj)
        if prop == "PencilSource":
            pencil_panel.enable(self, obj)


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon."""

    ICON = ICON


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider)
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
