"""GUI of the 'TMM Roughing' operation: its task panel page (group boxes: tool, model, layers, clearing,
entry and links; FreeCAD's Heights page beside it), view provider and command. The model widgets are the
Surface op's (op_surface_gui); the step-over and helix diameter are % of the tool diameter (plain spin boxes:
FreeCAD has no percent unit)."""
from __future__ import annotations

from typing import Any

from tmm_workbench.app import registry
from tmm_workbench.gui import op_page, op_surface_gui, resources

ENTRY = registry.entry("TMM_Roughing")
ICON = resources.icon(ENTRY.icon)
# widget name -> property
SPIN_BOXES = {"stepDown": "StepDown", "remainingHeight": "RemainingHeight", "finalZ": "FinalZ",
              "stockToLeave": "StockToLeave", "axialStockToLeave": "AxialStockToLeave",
              "chordTolerance": "ChordTolerance", "rampAngle": "RampAngle", "linearDeflection": "LinearDeflection"}
COMBOS = {"layerMode": "LayerMode", "pattern": "Pattern", "direction": "Direction", "entry": "Entry"}
CHECKS = {"flatLayers": "FlatLayers", "useFinalZ": "UseFinalZ", "keepToolDown": "KeepToolDown"}
PERCENTS = {"stepOver": "StepOver", "helixDiameter": "HelixDiameter"}


class PercentFields:
    """Float properties in % shown in QDoubleSpinBoxes (a page mix-in; PERCENTS: widget -> property)."""

    PERCENTS: dict[str, str] = {}

    def get_percents(self, obj: Any) -> None:
        guard = getattr(self, "guard", None)
        for widget, prop in self.PERCENTS.items():
            if guard is not None and prop in guard.refused:
                continue  # a refused value never reaches the op
            value = getattr(self.form, widget).value()
            if abs(getattr(obj, prop) - value) > 1e-9:
                setattr(obj, prop, value)

    def set_percents(self, obj: Any) -> None:
        for widget, prop in self.PERCENTS.items():
            getattr(self.form, widget).setValue(float(getattr(obj, prop)))

    def percent_signals(self) -> list[Any]:
        return [getattr(self.form, w).editingFinished for w in self.PERCENTS]


class TaskPanelOpPage(PercentFields, op_surface_gui.TaskPanelOpPage):
    """Tool controller, coolant, model, layers, clearing and entry parameters of the op."""

    PANEL = "roughing_op"
    ICON = ICON
    SPIN_BOXES = SPIN_BOXES
    COMBOS = COMBOS
    CHECKS = CHECKS
    PERCENTS = PERCENTS

    def get_extra(self, obj: Any) -> None:
        super().get_extra(obj)
        self.get_percents(obj)

    def set_extra(self, obj: Any) -> None:
        super().set_extra(obj)
        self.set_percents(obj)
        self.form.finalZ.setEnabled(bool(obj.UseFinalZ))

    def extra_signals(self) -> list[Any]:
        return super().extra_signals() + self.percent_signals()

    def updateData(self, obj: Any, prop: str) -> None:
        super().updateData(obj, prop)
        if prop == "UseFinalZ":
            self.form.finalZ.setEnabled(bool(obj.UseFinalZ))


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon."""

    ICON = ICON


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider)
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
