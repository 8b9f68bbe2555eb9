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

from PySide import QtGui

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
