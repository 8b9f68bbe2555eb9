"""GUI of the 'TMM 5-axis Mesh' operation: its task panel page (group boxes: tool, model, 5-axis finishing,
posture, tool holder; FreeCAD's Heights page beside it), view provider and command. The model widgets are the
Surface op's (op_surface_gui)."""
from __future__ import annotations

from tmm_workbench.app import op_mesh5, registry, stages
from tmm_workbench.gui import op_page, op_surface_gui, resources

ENTRY = registry.entry("TMM_Mesh5")
ICON = resources.icon(ENTRY.icon)
# widget name -> property
SPIN_BOXES = {"tolerance": "Tolerance", "forwardStep": "ForwardStep", "feedAngle": "FeedAngle",
              "chordTolerance": "ChordTolerance", "axisRetract": "AxisRetract", "leastTilt": "LeastTilt",
              "tiltLimit": "TiltLimit", "yawLimit": "YawLimit", "gridStep": "GridStep",
              "linearDeflection": "LinearDeflection"}
COMBOS: dict[str, str] = {}
CHECKS = {"zigZag": "ZigZag", "simulateLeft": "SimulateLeft"}
_HOLDER_SPINS, _HOLDER_COMBOS, _ = stages.widgets(op_mesh5.TOOL_STAGES)  # the "Tool holder" group
SPIN_BOXES.update(_HOLDER_SPINS)
COMBOS.update(_HOLDER_COMBOS)


class TaskPanelOpPage(op_surface_gui.TaskPanelOpPage):
    """Tool controller, coolant, model, 5-axis finishing and posture parameters of the op."""

    PANEL = "mesh5_op"
    ICON = ICON
    SPIN_BOXES = SPIN_BOXES
    COMBOS = COMBOS
    CHECKS = CHECKS


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon."""

    ICON = ICON


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider)
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
