"""GUI of the 'TMM 5-axis Multipoint' operation: its task panel page, view provider and command.

Same pattern as op_surface_gui (op_page): PathOpGui.SetupOperation registers `Path_TMM_Multipoint`; the
command creates the op with our view provider (icon from the add-on's file). The op has base geometry
(`Base`: one Bézier or B-spline face), so PathOpGui's TaskPanel adds its stock Base Geometry page; a face
selected before the command is taken as the op's Base.
"""
from __future__ import annotations

from typing import Any

from tmm_workbench.app import registry
from tmm_workbench.gui import op_page, resources

ENTRY = registry.entry("TMM_Multipoint")
ICON = resources.icon(ENTRY.icon)
# widget name -> property
SPIN_BOXES = {"sideStep": "SideStep", "forwardStep": "ForwardStep", "feedAngle": "FeedAngle",
              "boundaryMargin": "BoundaryMargin", "tiltLimit": "TiltLimit", "tolerance": "Tolerance",
              "axisRetract": "AxisRetract", "surfaceExtension": "SurfaceExtension"}
COMBOS = {"method": "Method", "toolShape": "ToolShape", "footprintAnchor": "FootprintAnchor",
          "passSpacing": "PassSpacing"}


class TaskPanelOpPage(op_page.OpPage):
    """Tool controller, coolant, method, footprint and tilt parameters; contact summary and status."""

    PANEL = "multipoint_op"
    ICON = ICON
    SPIN_BOXES = SPIN_BOXES
    COMBOS = COMBOS
    CHECKS = {"zigZag": "ZigZag"}
    STATUS_PROPS = ("Path", "ContactSummary")

    def show_status(self, obj: Any) -> None:
        self.form.contacts.setText(obj.ContactSummary)
        super().show_status(obj)


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon. Any face may be picked (the op checks its surface)."""

    ICON = ICON


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider, " (a bullnose or ballend tool is needed)")
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
