"""The GUI scripts' runner (FreeCAD runs them under Xvfb: `freecad tests/gui/gui_X.py`): the session once the
main window and its event loop are up, its outcome as JSON for the pytest side, and FreeCAD's exit code."""
from __future__ import annotations

import faulthandler
import gc
import importlib
import json
import os
import sys
import time
import traceback
from pathlib import Path
from typing import Any, Callable

from PySide import QtCore, QtGui

try:
    import shiboken6 as shiboken
except ImportError:  # FreeCAD 0.20 and 1.0: PySide2
    import shiboken2 as shiboken

_STDERR = os.fdopen(os.dup(2), "w")  # the process's stderr (FreeCAD's sys.stderr has no file descriptor)


def helpers_of(script: str) -> Any:
    """Another GUI script imported for its helpers, not its session: importing it schedules its run on the event
    loop (run()), so the scheduling is held off meanwhile."""
    single_shot = QtCore.QTimer.singleShot
    QtCore.QTimer.singleShot = staticmethod(lambda *args: None)
    try:
        return importlib.import_module(script)
    finally:
        QtCore.QTimer.singleShot = single_shot


def pump(seconds: float) -> None:
    """Lets FreeCAD's event loop run for `seconds` (what a user's pause gives it)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
        time.sleep(0.02)


def start_tmm(root: Path) -> None:
    """The checkout at `root` importable (the tests' helpers too) and the TMM workbench active, its toolbars up."""
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    import FreeCADGui

    FreeCADGui.activateWorkbench("TMMWorkbench")
    pump(0.5)


def forget_found_widgets() -> None:
    """Call once a task panel (or a document) has closed. PySide's findChildren makes the parent's wrapper keep a
    wrapper of each child it found. When Qt deletes such a child, FreeCAD (Gui::WrapperManager, for wrappers it
    made itself, e.g. the task dialog's button box) only marks the wrapper dead and PySide (for other children)
    is not told at all: either way the wrapper stays in PySide's address map, and a new Qt object at a reused
    address comes back to Python as it, typed as what was there before: dead ("Internal C++ object
    (QDialogButtonBox) already deleted" for a combo box of the next panel, FreeCAD 0.20) or alive (1.1 crashed
    in QDialogButtonBox::button called on another widget). Every wrapper the main window holds so, dead or not,
    is taken out of the map (shiboken.invalidate, with the wrappers held by those): a later search wraps what is
    there anew."""
    import FreeCADGui

    for child in gc.get_referents(FreeCADGui.getMainWindow()):
        if isinstance(child, QtCore.QObject):
            shiboken.invalidate(child)


def dead_wrappers(found_too: bool = True) -> list[str]:
    """Type names of the wrappers in PySide's address map whose Qt object is gone: each would be handed out for
    the next Qt object made at its address (getAllValidWrappers lists the whole map, dead ones included). Without
    `found_too`, only those held by something other than the main window (which holds our searches' results):
    what the product keeps."""
    import FreeCADGui

    registered = shiboken.getAllValidWrappers()
    dead = [w for w in registered if not shiboken.isValid(w)]
    if not found_too:
        ignored = {id(FreeCADGui.getMainWindow()), id(registered), id(dead)}
        dead = [w for w in dead if any(id(r) not in ignored for r in gc.get_referrers(w))]
    return sorted(type(w).__name__ for w in dead)


def close_document(doc) -> None:
    """Closes `doc` as the GUI does and forgets the wrappers our searches found in its views."""
    import FreeCAD

    FreeCAD.closeDocument(doc.Name)
    pump(0.3)
    forget_found_widgets()


def job_from_stl(doc, stl: str) -> tuple:
    """`stl` read into a Mesh object of `doc`, selected, and TMM's *Job from mesh / STL* run on it as a user does:
    (the mesh, the Job); the Job's panel is left open."""
    import FreeCADGui
    from tmm_workbench.gui import job_cmd

    mesh = job_cmd.import_stl(stl)
    doc.recompute()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(mesh)
    FreeCADGui.runCommand(job_cmd.COMMAND_NAME)
    pump(1.0)
    return mesh, next(o for o in doc.Objects if hasattr(o, "Operations") and hasattr(o, "Stock"))


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
