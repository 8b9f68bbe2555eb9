"""GUI of the 'TMM 5-axis Multipoint' operation: its task panel page, view provider and command.

Same pattern as op_surface_gui (op_page): PathOpGui.SetupOperation registers `Path_TMM_Multipoint`; the
command creates the op with our view provider (icon from the add-on's file). The op has base geometry
(`Base`: one Bézier or B-spline face), so PathOpGui's TaskPanel adds its stock Base Geometry page; a face
selected before the command is taken as the op's Base.

The view provider also draws the tool axes: every `AxisEvery`-th cutting position as a
line `AxisLength` long from the tip up the axis, coloured by contact status or tilt (`AxisColouring`),
shown while `ShowToolAxes` is on. They come from the last computation's per-position results, or, after a
document is reopened (the results are not saved), from the Path's G1 moves (tilt colours then).
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.app import op_multipoint, registry, stages
from tmm_workbench.core import path5
from tmm_workbench.core.preview.tool_axes import COLOURINGS, axis_lines, legend
from tmm_workbench.core.strategies.multipoint import STATUS_FAILED
from tmm_workbench.gui import op_page, resources

ENTRY = registry.entry("TMM_Multipoint")
ICON = resources.icon(ENTRY.icon)
# widget name -> property
SPIN_BOXES = {"sideStep": "SideStep", "forwardStep": "ForwardStep", "feedAngle": "FeedAngle",
              "boundaryMargin": "BoundaryMargin", "tiltLimit": "TiltLimit", "tolerance": "Tolerance",
              "axisRetract": "AxisRetract", "surfaceExtension": "SurfaceExtension", "scallop": "Scallop"}
COMBOS = {"method": "Method", "toolShape": "ToolShape", "footprintAnchor": "FootprintAnchor",
          "passSpacing": "PassSpacing"}
_HOLDER_SPINS, _HOLDER_COMBOS, _ = stages.widgets(op_multipoint.TOOL_STAGES)  # the "Tool holder" group
SPIN_BOXES.update(_HOLDER_SPINS)
COMBOS.update(_HOLDER_COMBOS)


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

    # the side step warned about as it is typed, before any compute
    def init_extra(self, obj: Any) -> None:
        self.obj = obj
        self.form.passSpacing.currentIndexChanged.connect(self.warn_side_step)
        self.form.sideStep.valueChanged.connect(self.warn_side_step)
        self.form.toolController.currentIndexChanged.connect(self.warn_side_step)

    def set_extra(self, obj: Any) -> None:
        self.warn_side_step()

    def warn_side_step(self, *_: Any) -> None:
        """Shows under the side step whether the typed value leaves uncut strips for the op's tool."""
        from tmm_workbench.app import tools

        text = ""
        try:
            spacing = op_multipoint.PASS_SPACINGS.get(self.form.passSpacing.currentText(), "")
            step = float(self.form.sideStep.property("rawValue"))
            tc = getattr(self.obj, "ToolController", None)
            if tc is not None:
                text = op_multipoint.uncut_strip_warning(spacing, step, tools.cutter_from_tool(tc.Tool))
        except Exception:  # noqa: BLE001 - no tool or a tool the op refuses: the compute names it
            text = ""
        self.form.sideStepWarning.setText(text)
        self.form.sideStepWarning.setVisible(bool(text))


# view-provider properties of the tool axes: (type, name, tooltip, default)
AXIS_PROPERTIES = (
    ("App::PropertyBool", "ShowToolAxes", "Draw the tool axis at the cutting positions", True),
    ("App::PropertyIntegerConstraint", "AxisEvery", "Draw every n-th position's axis", (4, 1, 100000, 1)),
    ("App::PropertyEnumeration", "AxisColouring",
     "Contact: green two contacts, orange one; Tilt: blue vertical to red at the tilt limit", list(COLOURINGS)),
    ("App::PropertyLength", "AxisLength", "Length of the drawn axes", 15.0),
)


def ensure_axis_properties(vobj: Any) -> None:
    """Adds the tool-axis properties missing on `vobj` (a new op, or one saved before they existed)."""
    for kind, name, tip, default in AXIS_PROPERTIES:
        if not hasattr(vobj, name):
            vobj.addProperty(kind, name, "Tool axes", tip)
            setattr(vobj, name, default)


def axis_source(obj: Any) -> Optional[tuple[np.ndarray, np.ndarray, Optional[np.ndarray], float]]:
    """(tips, axes, status or None, tilt limit deg) of the op's cutting positions: the last computation's
    results, else the Path's feed moves; None when there is nothing to draw."""
    proxy = getattr(obj, "Proxy", None)
    res = getattr(proxy, "results", None)
    limit = float(getattr(getattr(obj, "TiltLimit", None), "Value", 45.0))
    if res is not None and len(res):
        good = res["status"] != STATUS_FAILED
        return res["tip"][good], res["axis"][good], res["status"][good], limit
    moves = [m for m in path5.decode_commands((c.Name, c.Parameters) for c in obj.Path.Commands)
             if m.name == "G1" and not np.isnan(m.tip).any()]
    if not moves:
        return None
    return np.array([m.tip for m in moves]), np.array([m.axis for m in moves]), None, limit


class ViewProvider(op_page.OpViewProvider):
    """The TMM op view provider with this op's icon. Any face may be picked (the op checks its surface).
    Draws the tool axes under its root node (a switch, toggled by ShowToolAxes)."""

    ICON = ICON
    axes_switch: Any = None

    def attach(self, vobj: Any) -> None:
        super().attach(vobj)
        from pivy import coin

        ensure_axis_properties(vobj)
        self.axes_switch = coin.SoSwitch()
        self.axes_switch.setName("TmmToolAxes")
        vobj.RootNode.addChild(self.axes_switch)
        self.refresh_axes()

    def updateData(self, obj: Any, prop: str) -> None:
        super().updateData(obj, prop)
        if prop == "Path":
            self.refresh_axes()

    def onChanged(self, vobj: Any, prop: str) -> None:
        super().onChanged(vobj, prop)   # the marks (holder, rest) of every TMM op
        if prop in ("ShowToolAxes", "AxisEvery", "AxisColouring", "AxisLength", "Visibility"):
            self.refresh_axes()

    def axis_count(self) -> int:
        """Axes drawn now (0 when hidden): what the switch shows."""
        sw = self.axes_switch
        if sw is None or sw.whichChild.getValue() < 0 or sw.getNumChildren() == 0:
            return 0
        return int(sw.getChild(0).getChild(4).numVertices.getNum())

    def refresh_axes(self) -> None:
        from pivy import coin

        sw, vobj = self.axes_switch, getattr(self, "vobj", None)
        if sw is None or vobj is None or not hasattr(vobj, "ShowToolAxes"):
            return
        sw.removeAllChildren()
        sw.whichChild = coin.SO_SWITCH_NONE
        # the switch is the root node's child, beside the display modes hiding the op hides: hidden with it
        if not (vobj.ShowToolAxes and vobj.Visibility):
            return
        try:
            source = axis_source(vobj.Object)
        except Exception:  # noqa: BLE001 - a Path the decoder cannot read: nothing drawn, never a failure
            return
        if source is None:
            return
        tips, axes, status, limit = source
        points, colours = axis_lines(tips, axes, int(vobj.AxisEvery), float(vobj.AxisLength.Value),
                                     vobj.AxisColouring, status, limit)
        sep = coin.SoSeparator()
        material = coin.SoMaterial()
        material.diffuseColor.setValues(0, len(colours), colours.tolist())
        binding = coin.SoMaterialBinding()
        binding.value = coin.SoMaterialBinding.PER_PART
        coords = coin.SoCoordinate3()
        coords.point.setValues(0, len(points), points.tolist())
        lines = coin.SoLineSet()
        lines.numVertices.setValues(0, len(colours), [2] * len(colours))
        style = coin.SoDrawStyle()
        style.lineWidth = 1.5
        for node in (style, material, binding, coords, lines):
            sep.addChild(node)
        sep.addChild(legend_node(legend(vobj.AxisColouring, status is not None, limit), points))
        sw.addChild(sep)
        sw.whichChild = 0


def legend_node(lines: list, points: np.ndarray) -> Any:
    """The axes' colour legend as screen-aligned text beside the highest axis end (drawn over the model):
    each line a text of its own colour, pushed down by empty lines before it."""
    from pivy import coin

    top = points[int(np.argmax(points[:, 2]))]
    root = coin.SoAnnotation()
    root.setName("TmmToolAxesLegend")
    move = coin.SoTranslation()
    move.translation = coin.SbVec3f(*map(float, top))
    root.addChild(move)
    for i, (text, rgb) in enumerate(lines):
        colour = coin.SoBaseColor()
        colour.rgb = coin.SbColor(*map(float, rgb))
        label = coin.SoText2()
        label.string.setValues(0, i + 1, [""] * i + [text])
        root.addChild(colour)
        root.addChild(label)
    return root


GUI = op_page.OpGui(ENTRY, TaskPanelOpPage, ViewProvider, " (a bullnose or ballend tool is needed)")
Command = GUI.command
attach_view_provider = GUI.attach_view_provider
COMMAND_NAME = ENTRY.command_name
