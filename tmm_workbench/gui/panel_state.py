"""What the op panels' Apply and Cancel keep (issue 15 item 5). FreeCAD's op panel (PathOpGui.TaskPanel) keeps
one undo transaction open from the panel's opening to OK or Cancel, and Cancel aborts it: after a good Apply,
Cancel threw that path away (and in the panel of a new op, the op itself). Here a good Apply (the op computed
and valid) commits what it did and opens a new transaction: Cancel goes back to the last good Apply, the new op
stays. A failed Apply is not committed: Cancel restores the path from before it."""
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


def keep_if_good(panel: Any) -> None:
    obj = panel.obj
    if not obj.isValid():
        return
    doc = obj.Document
    doc.commitTransaction()
    doc.openTransaction(TRANSACTION)
    panel.deleteOnReject = False
