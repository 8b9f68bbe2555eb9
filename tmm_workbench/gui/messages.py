"""Failures the user sees: a message box for a failed TMM op, command or post (non-modal, one per message),
one clean line in the report view and the traceback only in the log; the status line text of an op's last
result. Installed as app.hooks' failure hook by gui.startup (headless nothing of this runs)."""
from __future__ import annotations

import sys
import time
import traceback
from typing import Any, Callable, Optional

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

BOX_NAME = "TmmFailureBox"
TITLE = "TMM"


def _restore_tracebacks() -> None:
    if getattr(sys, "tracebacklimit", None) == 0:
        del sys.tracebacklimit


def quiet_traceback() -> None:
    """FreeCAD prints the traceback of an exception leaving an op's execute into the report view; the op
    already printed its one line. Until the event loop runs again (right after the recompute), Python
    formats no traceback frames (PyTraceBack_Print honours sys.tracebacklimit)."""
    FreeCAD.Console.PrintLog("".join(traceback.format_stack(limit=12)))
    sys.tracebacklimit = 0
    QtCore.QTimer.singleShot(0, _restore_tracebacks)


_last_shown: dict[str, float] = {}
REPEAT_S = 5.0  # Cancel after a failed Apply recomputes the op: the same failure again is not a new box


def show_box(text: str, parent: Optional[QtGui.QWidget] = None) -> None:
    """A non-modal warning box (a recompute is never blocked); the same text again within REPEAT_S seconds,
    or while its box is open, shows no second box (the status line and report view still say it)."""
    for w in QtGui.QApplication.topLevelWidgets():
        if isinstance(w, QtGui.QMessageBox) and w.objectName() == BOX_NAME and w.isVisible() and w.text() == text:
            return
    now = time.monotonic()
    if now - _last_shown.get(text, -REPEAT_S) < REPEAT_S:
        return
    _last_shown.clear()
    _last_shown[text] = now
    box = QtGui.QMessageBox(QtGui.QMessageBox.Warning, TITLE, text, QtGui.QMessageBox.Ok,
                            parent or FreeCADGui.getMainWindow())
    box.setObjectName(BOX_NAME)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.setWindowModality(QtCore.Qt.NonModal)
    box.show()


def on_failure(obj: Any, message: str) -> None:
    """app.hooks' failure hook: the box is shown once the recompute is over."""
    label = getattr(obj, "Label", "") if obj is not None else ""
    text = f"{label}: {message}" if label else message
    if obj is not None:
        quiet_traceback()
    QtCore.QTimer.singleShot(0, lambda: show_box(text))


def report(what: str, exc: BaseException) -> None:
    """A command's or post's failure: one line in the report view, the traceback in the log, a box."""
    FreeCAD.Console.PrintLog(traceback.format_exc())
    FreeCAD.Console.PrintError(f"{what}: {exc}\n")
    show_box(f"{what}: {exc}")


def guarded_command(what: str, run: Callable[[], Any]) -> Callable[[], Any]:
    """`run` as a command's Activated: a failure shows its box instead of a traceback."""
    def activated() -> Any:
        try:
            return run()
        except Exception as exc:  # noqa: BLE001 - every failure of a command reaches the user
            report(what, exc)
            return None
    return activated


def result_text(obj: Any) -> str:
    """The op's last result for its panel's status line: moves, cutting passes and cycle time from its
    Path (so also after reopening a document), or '' before the first compute. The op's record of its Path
    is read when it has one (app.path_build: the status line costs the same whatever the path's size); a
    Path read once is recorded on the proxy until the Path changes."""
    from tmm_workbench.app import op_base, path_build

    proxy = getattr(obj, "Proxy", None)
    if getattr(proxy, "cancelled", False):
        return op_base.CANCELLED
    rec = path_build.record_of(obj)
    if rec is not None:
        moves, passes = len(rec), rec.cuts()
    elif getattr(proxy, "path_counts", None) is not None:
        moves, passes = proxy.path_counts
    else:
        moves, passes = _count(obj.Path.Commands)
        if proxy is not None and hasattr(proxy, "path_counts"):
            proxy.path_counts = (moves, passes)
    if not moves:
        return ""
    time = str(getattr(obj, "CycleTime", "") or "")
    return f"{moves} moves, {passes} cut{'s' if passes != 1 else ''}" + (f", cycle time {time}" if time else "")


def _count(commands: Any) -> tuple[int, int]:
    passes, cutting = 0, False  # a cut: feed moves between two rapids
    for c in commands:
        if c.Name in ("G0", "G00"):
            cutting = False
        elif c.Name in ("G1", "G01", "G2", "G02", "G3", "G03") and not cutting:
            passes, cutting = passes + 1, True
    return len(commands), passes
