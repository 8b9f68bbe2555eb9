"""A loaded panel's widgets as Python wrappers of what they are.

FreeCAD's .ui loader sets each named widget as an attribute of the form, through PySide's one-wrapper-per-address
map. A wrapper of a widget Qt has deleted can still be in that map (FreeCAD marks the wrappers it made dead and
leaves them there; PySide is not told when Qt deletes a widget it did not create; a closed panel or a search's
results keep them alive until Python's collector runs), and a new widget at the same address is then handed out
as it: dead ("Internal C++ object already deleted"), or alive but typed as what was there before (a check box as
a plain QWidget: "'QWidget' object has no attribute 'isChecked'", FreeCAD 1.0 in CI). Such an attribute is taken
out of the map and wrapped anew. (docs/gui/README.md, "Python wrappers of deleted widgets".)"""
from __future__ import annotations

from typing import Any

from PySide import QtCore

try:
    import shiboken6 as shiboken
except ImportError:  # FreeCAD 0.20 and 1.0: PySide2
    import shiboken2 as shiboken


def rewrapped(form: Any) -> Any:
    """`form` with every named-widget attribute wrapped anew from the widget found under that name. No method is
    called on the loaded wrappers first: a stale one can look valid to shiboken and still crash on its first call
    (FreeCAD 1.1 in CI: SIGSEGV in `metaObject()` on such a wrapper), so each is taken out of the map unseen and the
    search wraps what is at that address now, typed by Qt's own meta object. Returns `form`."""
    for name, widget in list(vars(form).items()):
        if not isinstance(widget, QtCore.QObject):
            continue
        shiboken.invalidate(widget)  # out of the map: the search below wraps the live widget
        found = form.findChild(QtCore.QObject, name)
        if found is not None:
            setattr(form, name, found)
    return form


def forget(form: Any) -> None:
    """A closed panel's form and its named widgets taken out of the wrapper map, once Qt has deleted them (a panel
    FreeCAD keeps alive after it closes would hold their dead wrappers, handed out for the next widgets at those
    addresses)."""
    for widget in [form] + [w for w in vars(form).values() if isinstance(w, QtCore.QObject)]:
        if not shiboken.isValid(widget):
            shiboken.invalidate(widget)
