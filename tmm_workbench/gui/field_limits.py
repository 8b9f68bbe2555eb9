"""Panel fields that cannot run away: every length / angle field of a TMM op page gets the minimum and maximum
of its params Spec (app.work_estimate.spec_for), keeps its default unit (a bare number typed means mm or deg,
never the unit the field last displayed: after 20 µm a typed "1.5" was 1.5 µm and froze FreeCAD at 17 GB),
and every entered value runs the work estimate before it reaches the op: a value out of range or above the
work limit is marked on its field, named in the status line, never written, and OK / Apply refuse to compute
while one is pending (a message box says why)."""
from __future__ import annotations

import math
import re
from typing import Any, Optional

import FreeCAD
from PySide import QtGui

from tmm_workbench.app import work_estimate
from tmm_workbench.core.errors import TmmError
from tmm_workbench.gui import messages

BARE_NUMBER = re.compile(r"^\s*[-+]?(\d+[.,]?\d*|[.,]\d+)([eE][-+]?\d+)?\s*$")
REFUSED_STYLE = "background-color: #ffd0d0"
UNITS = {"App::PropertyAngle": "deg"}  # else mm: App::PropertyDistance / Length


def default_unit(obj: Any, prop: str) -> str:
    return UNITS.get(obj.getTypeIdOfProperty(prop), "mm")


def _with_unit(line: QtGui.QLineEdit, unit: str, text: str) -> None:
    """A bare number typed into the field gets the field's default unit, the cursor staying before it."""
    if BARE_NUMBER.match(text):
        number = text.strip()
        line.setText(f"{number} {unit}")
        line.setCursorPosition(len(number))


def entered_value(widget: Any) -> Optional[float]:
    """What the field's text says in mm / deg (the widget itself keeps its last valid value for text out of
    its range); None when the text is no quantity."""
    line = widget.findChild(QtGui.QLineEdit)
    text = line.text() if line is not None else ""
    try:
        return float(FreeCAD.Units.Quantity(text.replace(",", ".")).Value)
    except Exception:  # noqa: BLE001 - FreeCAD raises ValueError or its own parser errors
        return None


class FieldGuard:
    """The limits of one op page's quantity fields (`page.SPIN_BOXES`: widget -> property), and the values
    refused in it (`refused`: property -> message)."""

    def __init__(self, page: Any, obj: Any) -> None:
        self.page, self.obj = page, obj
        self.refused: dict[str, str] = {}
        self.typed_refusals: dict[str, str] = {}  # typed out of range: the field went back to its value
        self.estimate_text = ""
        self.widgets = {prop: getattr(page.form, w) for w, prop in page.SPIN_BOXES.items()}
        for prop, widget in self.widgets.items():
            self.bind(widget, prop)
        # plain spin boxes in % of the tool diameter (those the page's form has: a subclass may have its own)
        self.percents = {prop: getattr(page.form, w) for w, prop in getattr(page, "PERCENTS", {}).items()
                         if hasattr(page.form, w)}
        for prop, widget in self.percents.items():
            spec = work_estimate.spec_for(obj.Proxy, prop)
            if spec is not None and spec.low is not None:
                widget.setRange(spec.low, spec.high if spec.high is not None else 100.0)
        self.estimate_text = self.estimate(obj, {})

    @staticmethod
    def estimate(obj: Any, entered: dict[str, float]) -> str:
        """The status line's estimate of the op's values ('' when it cannot be told); raises nothing."""
        try:
            est = work_estimate.estimate(obj, entered)
            return est.text() if est is not None else ""
        except TmmError as exc:
            return f"will fail: {exc}"
        except Exception as exc:  # noqa: BLE001 - an estimate that cannot run must not break the panel
            return f"no estimate ({exc})"

    def bind(self, widget: Any, prop: str) -> None:
        unit = default_unit(self.obj, prop)
        spec = work_estimate.spec_for(self.obj.Proxy, prop)
        low = spec.low if spec is not None and spec.low is not None else -work_estimate.OPEN_HIGH[unit]
        high = spec.high if spec is not None and spec.high is not None else work_estimate.OPEN_HIGH[unit]
        widget.setProperty("minimum", float(low))
        widget.setProperty("maximum", float(high))
        widget.setProperty("unit", unit)
        widget.setProperty("tmmUnit", unit)
        span = f"{low:g} .. {high:g} {unit}" + (" (0: derived)" if spec is not None and spec.optional else "")
        what = _documentation(self.obj, prop)   # what the value does, then its range and unit
        widget.setToolTip((f"{what}\n" if what else "") + f"{spec.label if spec else prop}: {span}; a bare number "
                          f"is in {unit}")
        line = widget.findChild(QtGui.QLineEdit)
        if line is not None:
            line.textEdited.connect(lambda text, prop=prop, line=line, unit=unit: self.typed(prop, line, unit, text))

    def typed(self, prop: str, line: QtGui.QLineEdit, unit: str, text: str) -> None:
        """Each key: the default unit added to a bare number, and a value out of range marked at once (the
        spin box itself would silently go back to its last value when the field is left)."""
        _with_unit(line, unit, text)
        value = entered_value(self.widgets[prop])
        self.typed_refusals.pop(prop, None)
        spec = work_estimate.spec_for(self.obj.Proxy, prop)
        if value is not None:
            try:
                work_estimate.check_value(self.obj.Proxy, prop, value)
            except TmmError as exc:
                self.typed_refusals[prop] = str(exc)
        elif text.strip().startswith("-") and spec is not None and spec.low is not None and spec.low >= 0:
            # the spin box takes no digit after a minus below its minimum: say why
            self.typed_refusals[prop] = f"{spec.label} must be {spec.range_text()}, got a negative value"
        self.refused = {p: m for p, m in self.refused.items() if p != prop}
        self.refused.update({p: m for p, m in self.typed_refusals.items() if p == prop})
        self.mark()
        self.page.showStatus(self.obj)

    def held(self, obj: Any) -> set[str]:
        """Checks the values entered but not yet written (range, then the work estimate with all of them);
        returns the properties whose value must not be written, marks their fields."""
        entered: dict[str, float] = {}
        refused: dict[str, str] = {}
        for prop, widget in self.widgets.items():
            if not widget.isEnabled() or (hasattr(widget, "isReadOnly") and widget.isReadOnly()):
                continue  # off, or bound to an expression
            value = entered_value(widget)
            current = getattr(obj, prop)
            current = float(current.Value) if hasattr(current, "Value") else float(current)
            if value is None:
                refused[prop] = f"{prop}: '{widget.findChild(QtGui.QLineEdit).text()}' is not a quantity"
                continue
            if math.isclose(value, current, rel_tol=1e-12, abs_tol=1e-12):
                continue
            try:
                work_estimate.check_value(obj.Proxy, prop, value)
                entered[prop] = value
            except TmmError as exc:
                refused[prop] = str(exc)
        for prop, widget in self.percents.items():
            value = float(widget.value())
            if not widget.isEnabled() or abs(value - float(getattr(obj, prop))) <= 1e-9:
                continue
            try:  # the spin box's range is closed: an open end (0 % step-over) is refused here
                work_estimate.check_value(obj.Proxy, prop, value)
                entered[prop] = value
            except TmmError as exc:
                refused[prop] = str(exc)
        self.estimate_text = self.estimate(obj, entered)
        failing = self.estimate_text.startswith("will fail: ")
        if failing and entered and self.estimate(obj, {}) != self.estimate_text:  # caused by what was entered
            hit = [prop for prop in entered if prop in self.widgets or prop in self.percents]
            for prop in hit:
                refused[prop] = self.estimate_text[len("will fail: "):]
            if hit:
                self.estimate_text = ""
        for prop, message in self.typed_refusals.items():
            refused.setdefault(prop, message)
        self.refused = refused
        self.mark()
        return set(refused)

    def mark(self) -> None:
        for prop, widget in {**self.widgets, **self.percents}.items():
            message = self.refused.get(prop, "")
            widget.setProperty("tmmRefused", message)
            widget.setStyleSheet(REFUSED_STYLE if message else "")

    def problems(self) -> list[str]:
        return list(dict.fromkeys(self.refused.values()))


def guard_panel(panel: Any) -> None:
    """PathOpGui's TaskPanel: OK and Apply read the fields first and, while a page holds a refused value,
    compute nothing and show why (the panel stays open)."""
    def refusals() -> list[str]:
        panel.panelGetFields()
        return [p for page in panel.featurePages for p in getattr(getattr(page, "guard", None), "problems",
                                                                      lambda: [])()]

    accept, clicked = panel.accept, panel.clicked

    def guarded_accept(resetEdit: bool = True) -> Any:
        problems = refusals()
        if problems:
            messages.show_box("Not computed, a value is refused:\n" + "\n".join(problems))
            return False
        return accept(resetEdit)

    def guarded_clicked(button: Any) -> Any:
        if button == QtGui.QDialogButtonBox.Apply:
            problems = refusals()
            if problems:
                messages.show_box("Not computed, a value is refused:\n" + "\n".join(problems))
                return None
        return clicked(button)

    panel.accept, panel.clicked = guarded_accept, guarded_clicked


def _documentation(obj: Any, prop: str) -> str:
    """The property's own description (its tooltip in the property editor), '' when FreeCAD has none."""
    try:
        return str(obj.getDocumentationOfProperty(prop) or "")
    except Exception:  # noqa: BLE001 - an object without it (a plain Python one) has no description to add
        return ""
