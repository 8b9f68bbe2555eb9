"""The GUI scripts' runner (FreeCAD runs them under Xvfb: `freecad tests/gui/gui_X.py`): the session once the
main window and its event loop are up, its outcome as JSON for the pytest side, and FreeCAD's exit code."""
from __future__ import annotations

import faulthandler
import gc
import json
import os
import sys
import traceback
from pathlib import Path
from typing import Callable

from PySide import QtCore

try:
    import shiboken6 as shiboken
except ImportError:  # FreeCAD 0.20 and 1.0: PySide2
    import shiboken2 as shiboken

_STDERR = os.fdopen(os.dup(2), "w")  # the process's stderr (FreeCAD's sys.stderr has no file descriptor)


def forget_found_widgets() -> None:
    """Call once a task panel (or a document) has closed. PySide's findChildren makes the parent's wrapper keep a
    wrapper of each child it found, and PySide is not told when Qt deletes a child it did not create: the main
    window's wrapper then keeps wrappers of the closed panel's widgets, and a new Qt object at a reused address
    comes back to Python as one of them, typed as what was there before (FreeCAD 1.1 crashed in
    QDialogButtonBox::button called on another widget, after about 36 panels closed with the collector off).
    Every wrapper the main window holds so is invalidated (with the wrappers held by those): a later search
    wraps what is there anew."""
    import FreeCADGui

    for child in gc.get_referents(FreeCADGui.getMainWindow()):
        if isinstance(child, QtCore.QObject) and shiboken.isValid(child):
            shiboken.invalidate(child)


def run(session: Callable[[dict], None], result: Path) -> None:
    """Schedules `session(info)`; `info` (filled step by step, so a failure keeps what was seen before it),
    with "ok" and any "error" traceback, goes to `result`; then FreeCAD quits at once (no save-changes
    dialog) with 0 when the session returned, 1 when it raised."""

    def main() -> None:
        # FreeCAD's own SIGSEGV handler prints only the C stack; faulthandler (installed over it, and chaining to
        # it) first prints the Python stack of every thread, so a crash in CI names the line that led to it.
        faulthandler.enable(file=_STDERR, all_threads=True)
        code, info = 1, {}
        try:
            session(info)
            code = 0
        except BaseException:  # noqa: B902 - every failure must reach the exit code
            info["error"] = traceback.format_exc()
            sys.stderr.write(info["error"])
        info["ok"] = code == 0
        result.parent.mkdir(parents=True, exist_ok=True)
        result.write_text(json.dumps(info, indent=1, default=str))
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)

    QtCore.QTimer.singleShot(500, main)
