"""The 3-axis Surface panel's group 'Depths, passes and start point' (properties in
app.surface_passes): the step-over unit (mm or % of the tool diameter), final depth, finishing passes and
their step-down, start point. Bound through OpPage's tables where FreeCAD has a widget for the property
(quantity spin boxes, the unit combo box, check boxes); the % step-over, the pass count and the start point's
X and Y are plain spin boxes handled here. A page whose form has no such group (a subclass with its own .ui)
is left alone."""
from __future__ import annotations

from typing import Any

import FreeCAD

from tmm_workbench.app.surface_passes import PERCENT
from tmm_workbench.core.strategies.finish_passes import MAX_PASSES

# widget name -> property, merged into op_surface_gui's tables
# the properties whose change enables or disables fields
ENABLING = ("StepOverUnit", "StepOverMode", "UseFinalDepth", "FinishPasses", "UseStartPoint", "VerifyCusp", "Pattern")


class DepthFields:
    """A page mix-in: get_depths / set_depths / depth_signals / enable_depths, called from the page's hooks."""

    form: Any
    PERCENTS = {"stepOverPercent": "StepOverPercent"}  # checked by gui.field_limits (range, work estimate)

    def has_depths(self) -> bool:
        return hasattr(self.form, "depthsGroup")

    def get_depths(self, obj: Any) -> None:
        if not self.has_depths():
            return
        percent = self.form.stepOverPercent.value()
        guard = getattr(self, "guard", None)
        refused = guard is not None and "StepOverPercent" in guard.refused  # held by gui.field_limits
        if not refused and abs(obj.StepOverPercent - percent) > 1e-9:
            obj.StepOverPercent = percent
        passes = self.form.finishPasses.value()
        if obj.FinishPasses != passes:
            obj.FinishPasses = passes
        x, y = self.form.startX.value(), self.form.startY.value()
        if abs(obj.StartPoint.x - x) > 1e-9 or abs(obj.StartPoint.y - y) > 1e-9:
            obj.StartPoint = FreeCAD.Vector(x, y, obj.StartPoint.z)
        self.enable_depths(obj)

    def set_depths(self, obj: Any) -> None:
        if not self.has_depths():
            return
        self.form.finishPasses.setRange(1, MAX_PASSES)
        self.form.stepOverPercent.setValue(float(obj.StepOverPercent))
        self.form.finishPasses.setValue(int(obj.FinishPasses))
        self.form.startX.setValue(float(obj.StartPoint.x))
        self.form.startY.setValue(float(obj.StartPoint.y))
        self.enable_depths(obj)

    def depth_signals(self) -> list[Any]:
        if not self.has_depths():
            return []
        return [self.form.stepOverPercent.editingFinished, self.form.finishPasses.editingFinished,
                self.form.startX.editingFinished, self.form.startY.editingFinished]

    def enable_depths(self, obj: Any) -> None:
        """Only the fields that act are enabled: the step-over in its unit with StepOver spacing, the cusp height
        with a cusp spacing, VerifyCusp or the pencil's creases, the cusp slope limit with a cusp spacing, the
        spiral's direction with the spiral, the final depth when used, the step-down with more than one pass, the
        start point when used."""
        if not self.has_depths():
            return
        try:
            spacing = obj.StepOverMode == "StepOver"
            percent = obj.StepOverUnit == PERCENT
            pattern = getattr(obj, "Pattern", "")
            self.form.stepOverPercent.setEnabled(spacing and percent)
            self.form.stepOver.setEnabled(spacing and not percent)
            self.form.cuspHeight.setEnabled(not spacing or bool(getattr(obj, "VerifyCusp", False))
                                            or pattern == "Pencil")
            self.form.cuspSlopeLimit.setEnabled(not spacing)
            self.form.spiralDirection.setEnabled(pattern == "Spiral")
            self.form.finalDepth.setEnabled(bool(obj.UseFinalDepth))
            self.form.stepDown.setEnabled(int(obj.FinishPasses) > 1)
            self.form.startX.setEnabled(bool(obj.UseStartPoint))
            self.form.startY.setEnabled(bool(obj.UseStartPoint))
        except RuntimeError:  # the panel was closed (its widgets are gone)
            pass
