"""What the op panels' Apply and Cancel keep. FreeCAD's op panel (PathOpGui.TaskPanel) keeps
one undo transaction open from the panel's opening to OK or Cancel, and Cancel aborts it: after a good Apply,
Cancel threw that path away (and in the panel of a new op, the op itself). Here a good Apply (the op computed
and valid) commits what it did and opens a new transaction: Cancel goes back to the last good Apply, the new op
stays. A failed Apply is not committed: Cancel restores the path from before it.

Cancel must also be the panel's last word: PathOpGui never disconnects the fields' update signals, and a field
that still has the keyboard focus when the panel closes emits editingFinished after reject() has aborted the
transaction; its value then reached the op outside any transaction (kept, and computed by reject's recompute).
So once Cancel is pressed, the pages' update handler does nothing (`drop_fields_on_cancel`).

A closed panel must not leave Python wrappers of its Qt widgets behind (`forget_widgets_on_close`)."""
from __future__ import annotations

import gc
import sys
from contextlib import contextmanager
from typing import Any, Iterator

from PySide import QtCore, QtGui



def transaction_name(obj: Any) -> str:
    """The undo step of an op panel's edits: the action and the op's label (as the user named it)."""
    return f"Edit {obj.Label}"


FREECAD_STEP = "AreaOp Operation"   # the name FreeCAD's op panel gives the undo step it opens


@contextmanager
def first_step_named(obj: Any, op_gui: Any) -> Iterator[None]:
    """While FreeCAD's op panel is built (`op_gui`: its module, PathOpGui), the undo step it opens is named as the
    panel's later steps are, not FreeCAD's FREECAD_STEP. It opens the step before building its pages, which write
    the op: a step opened afterwards would split them in two, so the name is given as it asks for its
    translation."""
    translate = op_gui.translate
    name = transaction_name(obj)
    op_gui.translate = lambda context, text, *args: name if text == FREECAD_STEP else translate(context, text, *args)
    try:
        yield
    finally:
        op_gui.translate = translate


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


def field_controllers(panel: Any) -> list[tuple[Any, Any]]:
    """(controller, field) for each of FreeCAD's quantity field controllers (PathGuiUtil.QuantitySpinBox: a
    parentless Python QObject installed as its field's event filter) held by the panel's pages."""
    found = []
    for page in getattr(panel, "featurePages", []):
        for value in list(vars(page).values()):
            for c in value.values() if isinstance(value, dict) else (value,):
                widget = getattr(c, "widget", None)
                if isinstance(c, QtCore.QObject) and hasattr(c, "eventFilter") and isinstance(widget, QtCore.QObject):
                    found.append((c, widget))
    return found


# Where a Python event filter is unsafe: PySide2 (Qt 5) on Python 3.13 and later, i.e. Debian 13's FreeCAD 1.0
# (0.20 runs PySide2 on 3.11, 1.1 PySide6: no crash seen there in any run).
FILTERS_CRASH = QtCore.qVersion().startswith("5.") and sys.version_info >= (3, 13)


def release_field_filters(panel: Any) -> None:
    """Where FILTERS_CRASH: each field controller stops filtering its field, once the panel is set up (FreeCAD's
    pages make all their controllers in initPage, during setupUi). There a Python eventFilter can be handed an
    event whose address a deleted Qt object's wrapper still holds: PySide then reads the event as that object and
    crashes (SIGSEGV in getMetaDataFromQObject at `event.type()` in the controller's eventFilter; in CI, and at
    the first round of a loop of focus changes and Cancels, also with the filters removed only at close).
    Without the filter no event crosses into Python there. What the filter did, show the op's value when the
    field gets the focus, is lost there; the pages show every change of the op anyway (setFields). Elsewhere
    the filters stay: on 1.1 a field left showing a refused value in another unit (0.1 um) would read the
    next typed number in that unit."""
    if not FILTERS_CRASH:
        return
    for controller, widget in field_controllers(panel):
        widget.removeEventFilter(controller)


def forget_widgets_on_close(panel: Any) -> None:
    """Once the panel has closed, the Python wrappers of its Qt widgets are freed at once. The closed panel lives
    on in reference cycles (its pages hold its bound methods, our wrappers above hold it) until Python's
    collector runs, and with it wrappers of widgets Qt has deleted: its button box (PathOpGui keeps it from
    modifyStandardButtons), its forms. Such a wrapper stays in PySide's address map (FreeCAD only marks the
    wrappers it made dead, PySide is not told of the others' deletion), and a new Qt object at the same address
    comes back to Python as it, typed as what was there before: dead ("already deleted") or alive as the wrong
    class (a crash). The button box is dropped at once, the rest by a collection once the task view has let the
    panel go (the next turn of the event loop)."""
    cleanup = panel.cleanup

    def cleanup_and_forget(resetEdit: bool) -> Any:
        try:
            return cleanup(resetEdit)
        finally:
            panel.buttonBox = None
            QtCore.QTimer.singleShot(0, gc.collect)

    panel.cleanup = cleanup_and_forget


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
    doc.openTransaction(transaction_name(obj))
    panel.deleteOnReject = False
