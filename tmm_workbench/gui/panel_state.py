"""What the op panels' Apply and Cancel keep (issue 15 item 5). FreeCAD's op panel (PathOpGui.TaskPanel) keeps
one undo transaction open from the panel's opening to OK or Cancel, and Cancel aborts it: after a good Apply,
Cancel threw that path away (and in the panel of a new op, the op itself). Here a good Apply (the op computed
and valid) commits what it did and opens a new transaction: Cancel goes back to the last good Apply, the new op
stays. A failed Apply is not committed: Cancel restores the path from before it.

Cancel must also be the panel's last word: PathOpGui never disconnects the fields' update signals, and a field
that still has the keyboard focus when the panel closes emits editingFinished after reject() has aborted the
transaction; its value then reached the op outside any transaction (kept, and computed by reject's recompute).
So once Cancel is pressed, the pages' update handler does nothing (`drop_fields_on_cancel`)."""
from __future__ import annotations

from typing import Any

from PySide import QtCore, QtGui

TRANSACTION = "TMM operation"


def commit_on_apply(panel: Any) -> None:
    """Wraps the panel's button handler (FreeCAD calls `panel.clicked(button)`)."""
    clicked = panel.clicked

    def clicked_and_kept(button: Any) -> None:
        clicked(button)
        if button == QtGui.QDialogButtonBox.Apply:
            keep_if_good(panel)

    panel.clicked = clicked_and_kept


def drop_fields_on_cancel(panel: Any) -> None:
    """Before the panel registers its signal handlers (PathOpGui's setupUi connects each page's pageGetFields):
    the pages' handlers read no field once reject() has begun. Only reject: accept reads the fields itself."""
    cancelled: list[bool] = []
    for page in panel.featurePages:
        page.pageGetFields = _unless(cancelled, page.pageGetFields)
    reject = panel.reject

    def rejected(resetEdit: bool = True) -> Any:
        cancelled.append(True)
        return reject(resetEdit)

    panel.reject = rejected


def pin_spin_controllers(panel: Any) -> None:
    """FreeCAD's CAM pages bind each quantity field through a parentless Python QObject
    (PathGuiUtil.QuantitySpinBox) installed as the field's event filter. When the panel closes the page, and
    with it that object, can go before the field does, and an event still queued for the field (its focus
    leaving) then reaches a filter whose Python side is gone: FreeCAD 1.0 crashed so once (SIGSEGV in PySide's
    getMetaDataFromQObject, a field focused at Cancel). Each controller is held by a connection to its field's
    `destroyed` signal, so it lives exactly as long as the field it filters."""
    for page in getattr(panel, "featurePages", []):
        for value in list(vars(page).values()):
            for c in value.values() if isinstance(value, dict) else (value,):
                widget = getattr(c, "widget", None)
                if isinstance(c, QtCore.QObject) and hasattr(c, "eventFilter") and isinstance(widget, QtCore.QObject):
                    if not c.property("tmmPinned"):
                        c.setProperty("tmmPinned", True)
                        widget.destroyed.connect(lambda *_, c=c: c)


def pin_on_close(panel: Any) -> None:
    """pin_spin_controllers as OK or Cancel closes the panel (the pages have all their fields by then)."""
    accept, reject = panel.accept, panel.reject

    def accepted(resetEdit: bool = True) -> Any:
        pin_spin_controllers(panel)
        return accept(resetEdit)

    def rejected(resetEdit: bool = True) -> Any:
        pin_spin_controllers(panel)
        return reject(resetEdit)

    panel.accept, panel.reject = accepted, rejected


def _unless(cancelled: list[bool], get_fields: Any) -> Any:
    def page_get_fields() -> None:  # no parameters: Qt hands a signal's arguments only to those who take them
        if not cancelled:
            get_fields()
    return page_get_fields


def keep_if_good(panel: Any) -> None:
    obj = panel.obj
    if not obj.isValid():
        return
    doc = obj.Document
    doc.commitTransaction()
    doc.openTransaction(TRANSACTION)
    panel.deleteOnReject = False
