"""GUI of the 'TMM Waterline' operation: its task panel page (group boxes: tool, model, boundary,
waterline, levels; FreeCAD's Heights page beside it), view provider and command. The model widgets are the
Surface op's (op_surface_gui)."""
from __future__ import annotations

from typing import Any

from tmm_workbench.app import registry
from tmm_workbench.gui import op_page, op_surface_gui, resources

ENTRY = registry.entry("TMM_Waterline")
ICON = resources.icon(ENTRY.icon)
# widget name -> property
SPIN_BOXES = {"boundaryMargin": "BoundaryMargin", "stepDown": "StepDown", "stockToLeave": "StockToLeave",
              "sampleStep": "SampleStep", "chordTolerance": "ChordTolerance", "topZ": "TopZ",
              "bottomZ": "BottomZ", "linearDeflection": "LinearDeflection"}
COMBOS = {"boundaryShape": "BoundaryShape", "direction": "Direction"}
CHECKS = {"useZRange": "UseZRange"}


class TaskPanelOpPage(op_surface_gui.TaskPanelOpPage):
    """Tool controller, coolant, model, boundary, waterline and level parameters of the op."""

    PANEL = "waterline_op"
    ICON = ICON
    SPIN_BOXES = SPIN_BOXES
    COMBOS = COMBOS
    CHECKS = CHECKS

    def set_extra(self, obj: Any) -> None:
        super().set_extra(obj)
        self.show_range(obj)

    def updateData(self, obj: Any, prop: str) -> None:
        super().updateData(obj, prop)
        if prop == "UseZRange":
            self.show_range(obj)

    def show_range(self, obj: Any) -> None:
        for widget in (self.form.topZ, self.form.bottomZ):
            widget.setEnabled(bool(obj.UseZRange))


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon."""

    ICON = ICON


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider)
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
