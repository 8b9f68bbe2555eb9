"""What the TMM operations' GUIs share: the task panel page pattern, the view provider and the command's
create step.

PathOpGui assumes icons inside FreeCAD's compiled Qt resources (":/icons/<pixmap>.svg"); an add-on has files
instead, so the view provider and the page give the icon's file path, and the command creates the op with
that view provider (same steps as PathOpGui.Create otherwise).
"""
from __future__ import annotations

from typing import Any, Callable

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.app.compat import PathOp, PathUtils, command_prefix, import_gui
from tmm_workbench.gui import field_limits, form_wrappers, messages, resources

PathOpGui = import_gui("op_gui")
PathGui = import_gui("path_gui")


def _show(spin: Any) -> None:
    """The property's value into its spin box (1.1 renamed updateSpinBox to updateWidget)."""
    (getattr(spin, "updateSpinBox", None) or spin.updateWidget)()


class OpPage(PathOpGui.TaskPanelPage):
    """A page of quantity spin boxes, combo boxes and check boxes bound to the op's properties (widget
    name -> property), plus tool controller, coolant and a status line. Subclasses set the class
    attributes and add their own widgets through the *_extra hooks."""

    PANEL = ""                # resources/panels/<PANEL>.ui
    ICON = ""
    SPIN_BOXES: dict[str, str] = {}
    COMBOS: dict[str, str] = {}
    CHECKS: dict[str, str] = {}
    STATUS_PROPS: tuple[str, ...] = ("Path",)  # a change of these refreshes the status line

    def getForm(self) -> Any:
        return form_wrappers.rewrapped(FreeCADGui.PySideUic.loadUi(resources.panel(self.PANEL)))

    def setIcon(self, icon: Any) -> None:
        super().setIcon(self.ICON)  # the view provider hands over a Qt resource path we do not ship

    def initPage(self, obj: Any) -> None:
        self.spins = {prop: PathGui.QuantitySpinBox(getattr(self.form, widget), obj, prop)
                      for widget, prop in self.SPIN_BOXES.items()}
        self.init_limits(obj)
        for widget, prop in self.COMBOS.items():
            combo = getattr(self.form, widget)
            combo.clear()
            combo.addItems(obj.getEnumerationsOfProperty(prop))
        self.init_extra(obj)

    def getFields(self, obj: Any) -> None:
        held = self.guard.held(obj) if getattr(self, "guard", None) else set()
        for prop, spin in self.spins.items():
            if prop not in held:  # a refused value never reaches the op
                spin.updateProperty()
        for widget, prop in self.COMBOS.items():
            value = getattr(self.form, widget).currentText()
            if value and getattr(obj, prop) != value:
                setattr(obj, prop, value)
        for widget, prop in self.CHECKS.items():
            checked = getattr(self.form, widget).isChecked()
            if bool(getattr(obj, prop)) != checked:
                setattr(obj, prop, checked)
        self.get_extra(obj)
        self.updateToolController(obj, self.form.toolController)
        self.updateCoolant(obj, self.form.coolantController)
        if getattr(self, "guard", None) and not held:  # told again with the choices just written (tool, mode)
            self.guard.estimate_text = self.guard.estimate(obj, {})
        self.showStatus(obj)

    def setFields(self, obj: Any) -> None:
        for spin in self.spins.values():
            _show(spin)
        for widget, prop in self.COMBOS.items():
            self.selectInComboBox(getattr(obj, prop), getattr(self.form, widget))
        for widget, prop in self.CHECKS.items():
            getattr(self.form, widget).setChecked(bool(getattr(obj, prop)))
        self.set_extra(obj)
        self.setupToolController(obj, self.form.toolController)
        self.setupCoolant(obj, self.form.coolantController)
        self.showStatus(obj)

    def showStatus(self, obj: Any) -> None:
        try:
            self.show_status(obj)
        except RuntimeError:  # the panel was closed (its widgets are gone) while the op recomputed
            pass

    def show_status(self, obj: Any) -> None:
        self.show_result(obj)

    def getSignalsForUpdate(self, obj: Any) -> list[Any]:
        signals = [getattr(self.form, w).editingFinished for w in self.SPIN_BOXES]
        signals += [getattr(self.form, w).currentIndexChanged for w in self.COMBOS]
        signals += [getattr(self.form, w).stateChanged for w in self.CHECKS]
        signals += self.extra_signals()
        signals += [self.form.toolController.currentIndexChanged, self.form.coolantController.currentIndexChanged]
        return signals

    def updateData(self, obj: Any, prop: str) -> None:
        if prop in self.spins:
            _show(self.spins[prop])
        elif prop in self.STATUS_PROPS:
            self.showStatus(obj)

    # Hooks for a page's own widgets.
    def init_extra(self, obj: Any) -> None:
        pass

    def get_extra(self, obj: Any) -> None:
        pass

    def set_extra(self, obj: Any) -> None:
        pass

    def extra_signals(self) -> list[Any]:
        return []

    # Field limits, work estimate and the status line (gui.field_limits, gui.messages).
    def init_limits(self, obj: Any) -> None:
        self.guard = field_limits.FieldGuard(self, obj)
        self.form.status.setWordWrap(True)

    def show_result(self, obj: Any) -> None:
        """The status line now, and again once the recompute is over (an op that fails empties its Path
        before FreeCAD marks it invalid)."""
        self.fill_status(obj)
        if not getattr(self, "_status_pending", False):
            self._status_pending = True
            QtCore.QTimer.singleShot(0, lambda: self._status_later(obj))

    def _status_later(self, obj: Any) -> None:
        self._status_pending = False
        try:
            self.fill_status(obj)
        except (RuntimeError, ReferenceError):  # the panel or the op went in the meantime
            pass

    def fill_status(self, obj: Any) -> None:
        """The status line: refused values, else the op's error, the tool controller's missing feeds, the
        last result (moves, cuts, cycle time) and the work estimate, and a spindle speed the post needs."""
        from tmm_workbench.app.op_base import feed_problem, spindle_problem

        guard = getattr(self, "guard", None)
        tc = getattr(obj, "ToolController", None)
        errors = guard.problems() if guard else []
        if not errors and not obj.isValid():
            errors = [obj.getStatusString()]
        if not errors and tc is not None and feed_problem(tc):
            errors = [feed_problem(tc)]
        lines = errors or [t for t in (messages.result_text(obj), guard.estimate_text if guard else "") if t]
        spindle = spindle_problem(obj)
        if spindle:
            lines.append(spindle)
        self.form.status.setStyleSheet("color: #c00000" if errors else ("color: #a05000" if spindle else ""))
        self.form.status.setText("\n".join(lines))


class OpViewProvider(PathOpGui.ViewProvider):
    """PathOpGui's view provider with the op icon read from the add-on's file (class attribute ICON), and
    no selection gate (PathSelection only knows FreeCAD's own ops; each TMM op checks its own input)."""

    ICON = ""
    mark_switches: Any = None

    def attach(self, vobj: Any) -> None:
        super().attach(vobj)
        from tmm_workbench.gui import region_marks_view

        self.mark_switches = region_marks_view.attach(vobj)

    def updateData(self, obj: Any, prop: str) -> None:
        super().updateData(obj, prop)
        from tmm_workbench.gui import region_marks_view

        region_marks_view.refresh(self.mark_switches, getattr(self, "vobj", None), prop)

    def onChanged(self, vobj: Any, prop: str) -> None:
        base = getattr(super(), "onChanged", None)   # FreeCAD 1.x's view provider may have one
        if base is not None:
            base(vobj, prop)
        from tmm_workbench.gui import region_marks_view

        region_marks_view.refresh(self.mark_switches, vobj, prop)

    def getSelectionFactory(self) -> Any:
        return lambda: None

    def getIcon(self) -> str:
        if self.Object is not None and not self.Object.Active:
            return f":/icons/{command_prefix()}OpActive.svg"
        return self.ICON

    def setEdit(self, vobj: Any = None, mode: int = 0) -> bool:
        from tmm_workbench.app import registry
        from tmm_workbench.gui import panel_state

        type_name, self.OpName = self.OpName, registry.user_name(self.OpName)   # the page's title: "TMM Surface"
        try:
            with panel_state.first_step_named(self.Object, PathOpGui):   # the op's name, not "AreaOp Operation"
                return super().setEdit(vobj, mode)
        finally:
            self.OpName = type_name   # FreeCAD saves it with the view provider

    def setupTaskPanel(self, panel: Any) -> None:
        from tmm_workbench.gui import panel_state

        panel_state.commit_on_apply(panel)  # Cancel keeps the last good Apply
        panel_state.drop_fields_on_cancel(panel)  # a field left focused writes nothing after Cancel's abort
        panel_state.forget_widgets_on_close(panel)  # no stale Qt wrappers left (a crash on 1.1)
        field_limits.guard_panel(panel)  # outermost: OK / Apply compute nothing while a value is refused
        super().setupTaskPanel(panel)
        panel_state.release_field_filters(panel)  # on 1.0 no Python event filter on the fields (a crash)


def attach_view_provider(obj: Any, view_provider: type, res: Any) -> None:
    """Gives an op created from Python (macro, API) the same view provider as the command's."""
    if not isinstance(getattr(obj.ViewObject, "Proxy", None), view_provider):
        obj.ViewObject.Proxy = view_provider(obj.ViewObject, res)
        obj.ViewObject.Proxy.deleteOnReject = False


def create(res: Any, view_provider: type, no_tool_text: str) -> Any:
    """PathOpGui.Create with our view provider: the new op in one undo step, its task panel open."""
    from tmm_workbench.app import registry

    doc = FreeCAD.ActiveDocument
    doc.openTransaction(f"Create {registry.user_name(res.name)}")
    try:
        obj = res.objFactory(res.name, obj=None, parentJob=res.job)
        if obj.Proxy:
            vp = obj.ViewObject.Proxy  # usually attached already by the op's view-provider hook
            if not isinstance(vp, view_provider):
                obj.ViewObject.Proxy = vp = view_provider(obj.ViewObject, res)
            vp.deleteOnReject = True  # Cancel in the first edit session removes the new op
            obj.ViewObject.Visibility = True
            doc.commitTransaction()
            obj.ViewObject.Document.setEdit(obj.ViewObject, 0)
            return obj
    except PathUtils.PathNoTCExistsException:
        QtGui.QMessageBox.warning(FreeCADGui.getMainWindow(), "TMM",
                                  f"No suitable tool controller found{no_tool_text}.\nAborting op creation")
    except PathOp.PathNoTCException:
        FreeCAD.Console.PrintWarning("TMM: no tool controller, aborting op creation\n")
    doc.abortTransaction()
    doc.recompute()
    return None


# an op's button is grey until the document has a Job (PathOpGui's IsActive): its tooltip and status tip say so
NEEDS_JOB = "Greyed out until the document has a Job: create one first with TMM > Job from mesh / STL."


def command(entry: Any, page: type, create_op: Callable[[Any], Any]) -> Any:
    """PathOpGui.SetupOperation's command for a registry entry (resources and registration), creating
    through `create_op`: its own would attach PathOpGui's view provider."""
    op_module = entry.app()
    tooltip = f"{entry.tooltip.rstrip('.')}. {NEEDS_JOB}"
    cmd = PathOpGui.SetupOperation(entry.name, op_module.Create, page, resources.icon(entry.icon),
                                   entry.menu_text, tooltip, op_module.SetupProperties)
    cmd.Activated = lambda: create_op(cmd.res)
    return cmd


class OpGui:
    """What one op's GUI module registers: its command (from the op registry entry), its view provider for
    ops made by the command and by Python (API, macros)."""

    def __init__(self, entry: Any, page: type, view_provider: type, no_tool_text: str = "") -> None:
        self.entry, self.view_provider, self.no_tool_text = entry, view_provider, no_tool_text
        self.command = command(entry, page, self.create)

    def create(self, res: Any) -> Any:
        return create(res, self.view_provider, self.no_tool_text)

    def attach_view_provider(self, obj: Any) -> None:
        attach_view_provider(obj, self.view_provider, self.command.res)
