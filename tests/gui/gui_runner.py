"""The GUI scripts' runner (FreeCAD runs them under Xvfb: `freecad tests/gui/gui_X.py`): the session once the
main window and its event loop are up, its outcome as JSON for the pytest side, and FreeCAD's exit code."""
from __future__ import annotations

import faulthandler
import json
import os
import sys
import traceback
from pathlib import Path
from typing import Callable

from PySide import QtCore

_STDERR = os.fdopen(os.dup(2), "w")  # the process's stderr (FreeCAD's sys.stderr has no file descriptor)


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
