"""The event loop while a large op computes and its path is built, run by FreeCAD under Xvfb
(`xvfb-run -a freecad tests/gui/gui_gaps.py`; tests/gui/test_gui_gaps.py, benchmarks/gui_gaps.py).

A Surface op on env TMM_GAPS_STL is made through the API with a coarse step-over, then its StepOver is set to env
TMM_GAPS_STEPOVER (and SampleStep to TMM_GAPS_SAMPLE) and the document recomputed as the panel's OK does, the GUI
progress dialog on. A QTimer ticking every 10 ms records when the event loop ran: the longest gap between two
ticks from the start of the recompute to the first tick after it (the path shown), and that time (OK to path
shown). Then the op's panel opens and one field edit (a spin box's value and editingFinished) is timed, and the
op is posted with tmm_linuxcnc. A second recompute is cancelled from the progress dialog: the op stays valid with
no path, and no error box is shown. Outcome (JSON) to env TMM_GUI_RESULT.
"""
import os
import sys
import time
from pathlib import Path

import FreeCADGui
from PySide import QtCore, QtGui

sys.path.insert(0, str(Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd() / "tests" / "gui"))
import gui_runner  # noqa: E402
from gui_runner import pump  # noqa: E402

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_gaps.json")
TICK_MS = 10


class Ticks:
    """The times the event loop ran a 10 ms timer."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.timer = QtCore.QTimer()
        self.timer.timeout.connect(lambda: self.times.append(time.monotonic()))
        self.timer.start(TICK_MS)

    def gaps(self, start: float, end: float) -> tuple[list[tuple[float, float]], float]:
        """The times between two ticks (or `start` and the first) up to the first tick after `end`, longest first,
        each with when it began (s after `start`); and the time of that first tick after `end` less `start`."""
        seen = [start] + [t for t in self.times if t > start]
        after = next((t for t in seen[1:] if t > end), None)
        if after is None:
            raise AssertionError("the event loop did not run after the recompute")
        upto = [t for t in seen if t <= after]
        return sorted(((b - a, a - start) for a, b in zip(upto, upto[1:])), reverse=True), after - start


def surface_op(info: dict):
    from tmm_workbench.app import api

    stl = os.environ["TMM_GAPS_STL"]
    r = api.run_surface(stl, stepover=2.0, sample_step=1.0, post="tmm_linuxcnc", progress=False, doc_name="Gaps")
    FreeCADGui.ActiveDocument.ActiveView.fitAll()
    pump(0.5)
    op = r.op
    op.StepOver = float(os.environ.get("TMM_GAPS_STEPOVER", "0.1"))
    op.SampleStep = float(os.environ.get("TMM_GAPS_SAMPLE", "0.1"))
    op.Proxy.progress_enabled = True
    return r


def traced_progress(info: dict) -> None:
    """With env TMM_GAPS_TRACE=1: every progress call's time (s since the first) and fraction in info."""
    from tmm_workbench.gui import progress_dialog

    calls = info.setdefault("progress_calls", [])
    call = progress_dialog.DialogProgress.__call__

    def traced(self, fraction: float) -> bool:
        calls.append((round(time.monotonic(), 3), round(fraction, 4)))
        return call(self, fraction)
    progress_dialog.DialogProgress.__call__ = traced
    from tmm_workbench.app import op_base
    from tmm_workbench.app.compat import PathOp

    marks = info.setdefault("marks", [])
    for cls, name in ((PathOp.ObjectOp, "getCycleTimeEstimate"), (op_base.TmmOp, "set_cycle_time"),
                      (op_base.TmmOp, "note_path_change"), (op_base.TmmOp, "add_rows")):
        def wrapped(*args, _f=getattr(cls, name), _n=name, **kwargs):
            marks.append((_n, round(time.monotonic(), 3)))
            try:
                return _f(*args, **kwargs)
            finally:
                marks.append((_n + " end", round(time.monotonic(), 3)))
        setattr(cls, name, wrapped)


def sample_stacks(info: dict) -> None:
    """With env TMM_GAPS_TRACE=1: the main thread's innermost TMM frames every 0.1 s (where a gap is spent)."""
    import threading
    import traceback

    main = threading.main_thread().ident
    samples = info.setdefault("stacks", [])

    def run() -> None:
        while not info.get("stop_sampling"):
            frame = sys._current_frames().get(main)
            if frame is not None:
                where = [f"{Path(f.filename).name}:{f.lineno}:{f.name}" for f in traceback.extract_stack(frame)
                         if "tmm_workbench" in f.filename or "PathScripts" in f.filename]
                samples.append((round(time.monotonic(), 2), where[-3:]))
            time.sleep(0.1)
    threading.Thread(target=run, daemon=True).start()


def timed_recompute(op, info: dict) -> None:
    if os.environ.get("TMM_GAPS_TRACE") == "1":
        traced_progress(info)
        sample_stacks(info)
    ticks = Ticks()
    pump(0.2)
    t0 = time.monotonic()
    op.Document.recompute()
    t1 = time.monotonic()
    info["t0"], info["stop_sampling"] = t0, True
    pump(0.5)
    ticks.timer.stop()
    gaps, shown = ticks.gaps(t0, t1)
    info.update(recompute_s=t1 - t0, ok_to_path_shown_s=shown, longest_gap_s=gaps[0][0], gaps_and_when=gaps[:5],
                ticks=len(ticks.times), moves=op.Path.Size,
                valid=op.isValid(), status=op.getStatusString())


def timed_edit(op, info: dict) -> None:
    """One field edit in the op's open panel, as a user types it (a value, then Tab): from the focus leaving the
    field to the status line written again (its second writing waits for the event loop)."""
    op.ViewObject.Document.setEdit(op.ViewObject, 0)
    pump(1.0)
    spin = next(w for w in FreeCADGui.getMainWindow().findChildren(QtGui.QWidget, "boundaryMargin")
                if w.isVisible() or w.window().isVisible())
    edit = spin.findChild(QtGui.QLineEdit)
    spin.setFocus()
    edit.selectAll()
    edit.insert("0.5 mm")
    t0 = time.monotonic()
    QtGui.QApplication.sendEvent(spin, QtGui.QFocusEvent(QtCore.QEvent.FocusOut, QtCore.Qt.TabFocusReason))
    QtGui.QApplication.processEvents()
    info["edit_s"] = time.monotonic() - t0
    info["edit_value"] = op.BoundaryMargin.Value
    info["status_line"] = next(w for w in FreeCADGui.getMainWindow().findChildren(QtGui.QLabel, "status")
                               if w.isVisible() or w.window().isVisible()).text()
    op.ViewObject.Proxy.panel.reject()
    pump(0.5)
    gui_runner.forget_found_widgets()


def timed_post(op, info: dict) -> None:
    from tmm_workbench.app import posts

    t0 = time.monotonic()
    text = posts.export("tmm_linuxcnc", [op.ToolController, op])
    info.update(post_s=time.monotonic() - t0, post_lines=text.count("\n"))


def cancelled_recompute(op, info: dict) -> None:
    """Cancel pressed in the progress dialog once it shows."""
    def press_cancel() -> None:
        for d in FreeCADGui.getMainWindow().findChildren(QtGui.QProgressDialog):
            if d.isVisible():
                d.cancel()
                return
        QtCore.QTimer.singleShot(50, press_cancel)
    boxes_before = len([w for w in QtGui.QApplication.topLevelWidgets() if isinstance(w, QtGui.QMessageBox)])
    op.StepOver = op.StepOver.Value * 0.999
    QtCore.QTimer.singleShot(50, press_cancel)
    op.Document.recompute()
    pump(0.5)
    boxes = [w for w in QtGui.QApplication.topLevelWidgets() if isinstance(w, QtGui.QMessageBox) and w.isVisible()]
    info.update(cancel_valid=op.isValid(), cancel_status=op.getStatusString(), cancel_moves=op.Path.Size,
                cancel_boxes=len(boxes) - boxes_before, cancel_flag=bool(op.Proxy.cancelled))


def session(info: dict) -> None:
    FreeCADGui.activateWorkbench("TMMWorkbench")
    r = surface_op(info)
    timed_recompute(r.op, info)
    timed_edit(r.op, info)
    timed_post(r.op, info)
    if os.environ.get("TMM_GAPS_CANCEL", "1") == "1":
        cancelled_recompute(r.op, info)


gui_runner.run(session, RESULT)
