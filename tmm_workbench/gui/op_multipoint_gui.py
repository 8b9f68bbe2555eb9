"""GUI of the 'TMM 5-axis Multipoint' operation: its task panel page, view provider and command.

Same pattern as op_surface_gui (op_page): PathOpGui.SetupOperation registers `Path_TMM_Multipoint`; the
command creates the op with our view provider (icon from the add-on's file). The op has base geometry
(`Base`: one Bézier or B-spline face), so PathOpGui's TaskPanel adds its stock Base Geometry page; a face
selected before the command is taken as the op's Base.
"""
from __future__ import annotations

from typing import Any

from tmm_workbench.app import op_multipoint
from tmm_workbench.gui import op_page, resources

ICON = resources.icon("TMM_Multipoint")
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


def attach_view_provider(obj: Any) -> None:
    """Gives an op created from Python (macro, API) the same view provider as the command's."""
    op_page.attach_view_provider(obj, ViewProvider, Command.res)


def create(res: Any) -> Any:
    return op_page.create(res, ViewProvider, " (a bullnose or ballend tool is needed)")


Command = op_page.command(op_multipoint, TaskPanelOpPage, ICON, "TMM 5-axis Multipoint",
                          "5-axis finishing of a Bézier or B-spline face with a toroidal cutter by multipoint "
                          "positioning (select the face first)", create)
COMMAND_NAME = "Path_" + op_multipoint.OP_NAME
