"""A user at the TMM Surface panel, run by FreeCAD itself: `xvfb-run -a freecad tests/gui/gui_user_input.py`.

Every value is typed key by key into the field and confirmed with Tab, buttons are clicked, message boxes
are found among the top-level widgets and closed, as a user does:
  1. the sample step shows 20 µm (a value from an earlier session); typing "1.5" gives 1.5 mm, not 1.5 µm;
  2. a negative step-over is refused: the field is marked, the op keeps its value, the status line says why;
  3. a sample step of 0.0001 mm is above the work limit: refused on Enter, before any compute; OK then shows
     a message box and computes nothing (the panel stays open);
  4. a sane value again: the status line shows the estimate; Apply computes, the status line shows the result;
  5. step-over 0 typed, OK: a message box, nothing computed;
  6. a missing STL typed, Apply: the op fails, a message box, one line in the report view and no traceback;
  7. a tool controller with horizontal feed 0 and spindle speed 0 (the Job's post linuxcnc writes S): the
     reopened panel says both before computing; Apply fails the op with a message box;
  8. a TMM Waterline page: its ranges from the waterline's params, a sampling step above its work limit
     refused before any compute;
  9. a post that fails shows a message box (and still raises to its caller).
A screenshot per step goes to env TMM_GUI_SHOTS (a folder; docs/gui by default); the outcome to env
TMM_GUI_RESULT (JSON) and the exit code.
"""
import os
import sys
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

sys.path.insert(0, str(Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd() / "tests" / "gui"))
import gui_runner  # noqa: E402
from gui_runner import pump  # noqa: E402

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
SHOTS = Path(os.environ.get("TMM_GUI_SHOTS") or ROOT / "out" / "gui")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_user_input.json")
PAGE = "TmmSurfaceOpPage"
TYPED: dict = {}


def page() -> QtGui.QWidget:
    for w in FreeCADGui.getMainWindow().findChildren(QtGui.QWidget, PAGE):
        if w.isVisible():
            return w
    raise AssertionError(f"the task panel page {PAGE} is not visible")


def field(name: str) -> QtGui.QWidget:
    return page().findChild(QtGui.QWidget, name)


def key(target: QtGui.QWidget, code: int, text: str = "") -> None:
    for kind in (QtCore.QEvent.KeyPress, QtCore.QEvent.KeyRelease):
        QtGui.QApplication.sendEvent(target, QtGui.QKeyEvent(kind, code, QtCore.Qt.NoModifier, text))


def type_into(name: str, text: str) -> None:
    """Select all in the field, type `text` key by key, press Tab (Enter would also press the panel's OK)."""
    widget = field(name)
    line = widget.findChild(QtGui.QLineEdit)
    widget.setFocus()
    pump(0.1)
    line.selectAll()
    for ch in text:
        code = QtCore.Qt.Key_Minus if ch == "-" else QtCore.Qt.Key_Period if ch == "." else 0
        key(line, code, ch)
    TYPED[name] = line.text()  # what the field shows before it is left
    key(widget, QtCore.Qt.Key_Tab)
    pump(0.3)


def button(which: int) -> QtGui.QPushButton:
    for box in FreeCADGui.getMainWindow().findChildren(QtGui.QDialogButtonBox):
        b = box.button(which)
        if b is not None and b.isVisible():
            return b
    raise AssertionError(f"no visible task panel button {which}")


def message_boxes() -> list:
    return [w for w in QtGui.QApplication.topLevelWidgets() if isinstance(w, QtGui.QMessageBox) and w.isVisible()]


def take_box(info: dict, key_name: str) -> str:
    """The one visible message box's text; the box is closed (its OK button) from a timer, as a user would."""
    pump(0.5)
    boxes = message_boxes()
    assert len(boxes) == 1, f"{key_name}: {len(boxes)} message boxes: {[b.text() for b in boxes]}"
    text = boxes[0].text()
    info[key_name] = text
    QtCore.QTimer.singleShot(50, boxes[0].button(QtGui.QMessageBox.Ok).click)
    pump(0.4)
    assert not message_boxes(), f"{key_name}: the box stayed open"
    return text


def status() -> tuple[str, str]:
    label = page().findChild(QtGui.QLabel, "status")
    return label.text(), label.styleSheet()


def report_text() -> str:
    mw = FreeCADGui.getMainWindow()
    for w in mw.findChildren(QtGui.QTextEdit):
        if "Report" in type(w).__name__ or w.objectName() in ("Report view", "ReportOutput"):
            return w.toPlainText()
    dock = mw.findChild(QtGui.QDockWidget, "Report view")
    edit = dock.findChild(QtGui.QTextEdit) if dock is not None else None
    assert edit is not None, "no report view"
    return edit.toPlainText()


def shot(info: dict, name: str) -> None:
    """The main window, scaled to 800 px wide, into SHOTS/<name>.png (the panel is what the step shows)."""
    SHOTS.mkdir(parents=True, exist_ok=True)
    png = SHOTS / f"{name}.png"
    label = page().findChild(QtGui.QLabel, "status") if FreeCADGui.Control.activeDialog() else None
    for area in FreeCADGui.getMainWindow().findChildren(QtGui.QScrollArea):
        if label is not None and area.isAncestorOf(label):
            area.ensureWidgetVisible(label)  # the status line in the picture
    pump(0.2)
    mw = FreeCADGui.getMainWindow()
    full = mw.grab()
    painter = QtGui.QPainter(full)
    for box in message_boxes():  # a window of its own: painted where it stands over the main window
        painter.drawPixmap(box.frameGeometry().topLeft() - mw.frameGeometry().topLeft(), box.grab())
    painter.end()
    image = full.scaledToWidth(800, QtCore.Qt.SmoothTransformation)
    assert image.save(str(png)), f"could not write {png}"
    info.setdefault("shots", []).append(str(png))


def open_panel(op) -> None:
    op.ViewObject.Document.setEdit(op.ViewObject, 0)
    pump(1.0)
    mw = FreeCADGui.getMainWindow()
    for dock in mw.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.isAncestorOf(page()):
            mw.resizeDocks([dock], [460], QtCore.Qt.Horizontal)
    pump(0.3)


def session(info: dict) -> dict:
    gui_runner.start_tmm(ROOT)
    mw = FreeCADGui.getMainWindow()
    report = mw.findChild(QtGui.QDockWidget, "Report view")
    if report is not None:
        report.show()
        mw.resizeDocks([report], [110], QtCore.Qt.Vertical)
    from tmm_workbench.app.api import run_surface
    from tmm_workbench.core.shared_data import benchmark_file

    stl = os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl"))
    r = run_surface(stl, stepover=2.0, sample_step=1.0, doc_name="TmmGuiUser", progress=False)
    op, doc = r.op, r.doc
    assert op.isValid(), op.getStatusString()
    op.SampleStep = 0.02  # what an earlier session left: the field opens showing µm
    doc.recompute()
    commands_before = len(op.Path.Commands)
    open_panel(op)
    info["status_open"] = status()  # the estimate of the op's values, before anything is typed
    assert "about" in info["status_open"][0] and "CL points" in info["status_open"][0], info["status_open"]

    # 1. the µm trap: a bare number is mm
    sample = field("sampleStep")
    info["sample_text_before"] = sample.findChild(QtGui.QLineEdit).text()
    assert "µm" in info["sample_text_before"] or "um" in info["sample_text_before"], info["sample_text_before"]
    type_into("sampleStep", "1.5")
    info["sample_text_typed"] = sample.findChild(QtGui.QLineEdit).text()
    info["sample_raw"] = sample.property("rawValue")
    info["sample_prop"] = op.SampleStep.Value
    info["sample_min_max"] = [sample.property("minimum"), sample.property("maximum")]
    assert abs(info["sample_raw"] - 1.5) < 1e-12 and abs(info["sample_prop"] - 1.5) < 1e-12, info
    shot(info, "01_bare_number_is_mm")

    # 2. a negative step-over
    type_into("stepOver", "-1")
    step = field("stepOver")
    info["stepover_typed"] = TYPED["stepOver"]
    info["stepover_text"] = step.findChild(QtGui.QLineEdit).text()
    info["stepover_refused"] = step.property("tmmRefused")
    info["stepover_prop"] = op.StepOver.Value
    info["stepover_min"] = step.property("minimum")
    info["status_negative"] = status()
    assert info["stepover_prop"] == 2.0, info["stepover_prop"]
    assert "step-over must be > 0 mm, got a negative value" in (info["stepover_refused"] or ""), info
    assert "step-over must be > 0 mm" in info["status_negative"][0], info["status_negative"]
    assert info["stepover_min"] == 0.0, info["stepover_min"]
    shot(info, "02_negative_refused")
    type_into("stepOver", "2")

    # 3. above the work limit: refused on Enter, OK computes nothing
    type_into("sampleStep", "0.0001")
    info["limit_refused"] = sample.property("tmmRefused")
    info["status_limit"] = status()
    assert "CL points" in (info["limit_refused"] or ""), info["limit_refused"]
    assert "CL points" in info["status_limit"][0] and "c00000" in info["status_limit"][1], info["status_limit"]
    assert abs(op.SampleStep.Value - 1.5) < 1e-12, op.SampleStep.Value
    shot(info, "03_work_limit_refused")
    button(QtGui.QDialogButtonBox.Ok).click()
    text = take_box(info, "box_limit")
    assert "Not computed" in text and "CL points" in text, text
    assert FreeCADGui.Control.activeDialog(), "OK closed the panel with a refused value"
    assert len(op.Path.Commands) == commands_before, "OK computed with a refused value"

    # 4. a sane value: the estimate; Apply: the result
    type_into("sampleStep", "1")
    info["status_estimate"] = status()
    assert not sample.property("tmmRefused"), sample.property("tmmRefused")
    assert "about" in info["status_estimate"][0] and "CL points" in info["status_estimate"][0], info
    assert "passes, cutting about 00:" in info["status_estimate"][0], info["status_estimate"]  # and its time
    button(QtGui.QDialogButtonBox.Apply).click()
    pump(1.5)
    info["status_apply"] = status()
    assert op.isValid() and abs(op.SampleStep.Value - 1.0) < 1e-12, op.getStatusString()
    assert "moves" in info["status_apply"][0] and " cut" in info["status_apply"][0], info["status_apply"]
    assert not message_boxes(), [b.text() for b in message_boxes()]
    shot(info, "04_status_after_apply")

    # 5. step-over 0, OK: a box, nothing computed
    type_into("stepOver", "0")
    info["stepover_zero_refused"] = field("stepOver").property("tmmRefused")
    button(QtGui.QDialogButtonBox.Ok).click()
    shot(info, "05_stepover_zero_box")
    text = take_box(info, "box_stepover_zero")
    assert "step-over must be a positive length" in text, text
    assert FreeCADGui.Control.activeDialog() and op.StepOver.Value == 2.0, op.StepOver.Value
    type_into("stepOver", "2")

    # 6. a missing STL, Apply: the op fails with a box; the report view has its line and no traceback
    missing = str(Path(stl).with_name("no_such_model.stl"))
    line = page().findChild(QtGui.QLineEdit, "stlFile")
    line.setFocus()
    pump(0.1)
    line.selectAll()
    for ch in missing:
        key(line, 0, ch)
    key(line, QtCore.Qt.Key_Tab)
    pump(0.3)
    before = report_text()
    button(QtGui.QDialogButtonBox.Apply).click()
    pump(1.0)
    shot(info, "06_missing_stl_box")
    text = take_box(info, "box_missing_stl")
    assert "file not found" in text and "no_such_model.stl" in text, text
    added = report_text()[len(before):]
    info["report_missing_stl"] = added
    info["status_missing_stl"] = status()
    assert "file not found" in added and "Traceback" not in added, added
    assert not op.isValid() and "file not found" in info["status_missing_stl"][0], info["status_missing_stl"]
    assert "c00000" in info["status_missing_stl"][1], info["status_missing_stl"]  # red: the op's error
    assert len(op.Path.Commands) == 0, "a failed op keeps no path"
    line.setFocus()
    pump(0.1)
    line.selectAll()
    key(line, QtCore.Qt.Key_Backspace)
    key(line, QtCore.Qt.Key_Tab)
    pump(0.3)
    button(QtGui.QDialogButtonBox.Apply).click()
    pump(1.5)
    assert op.isValid(), op.getStatusString()
    op.ViewObject.Proxy.panel.reject()
    pump(0.5)

    # 7. a tool controller with no horizontal feed: the panel says so before computing; Apply fails the op
    tc = op.ToolController
    tc.HorizFeed = 0.0
    tc.SpindleSpeed = 0.0  # and no spindle speed, with a post that writes S
    r.job.PostProcessor = "linuxcnc"
    open_panel(op)
    info["status_zero_feed"] = status()
    assert "HorizFeed must be a feed > 0" in info["status_zero_feed"][0], info["status_zero_feed"]
    assert "SpindleSpeed is 0 rpm" in info["status_zero_feed"][0], info["status_zero_feed"]
    shot(info, "07_zero_feed_panel")
    type_into("stepOver", "2.5")
    button(QtGui.QDialogButtonBox.Apply).click()
    pump(1.0)
    text = take_box(info, "box_zero_feed")
    assert "HorizFeed must be a feed > 0" in text, text
    assert not op.isValid(), "an op with feed 0 computed"
    op.ViewObject.Proxy.panel.reject()
    pump(0.5)
    gui_runner.close_document(doc)
    waterline_panel(info)
    return info


def waterline_panel(info: dict) -> None:
    """8. Another op's page: the TMM Waterline fields take their ranges from the waterline's params, and a
    sampling step of 0.00001 mm is refused by the waterline's own estimate before any compute."""
    import Part
    from tmm_workbench.app import job as jobs
    from tmm_workbench.app import registry, tools

    global PAGE
    doc = FreeCAD.newDocument("TmmGuiUserWaterline")
    block = doc.addObject("Part::Feature", "PocketBlock")
    block.Shape = Part.makeBox(40, 30, 10).cut(Part.makeBox(20, 12, 10, FreeCAD.Vector(10, 9, 5)))
    doc.recompute()
    job = jobs.create_job(doc, block)
    jobs.set_tool(job, tools.make_tool_bit(doc, "endmill", 6.0), 20.0, 5.0, 10000)
    op = registry.create("TMM_Waterline", job)
    op.Proxy.progress_enabled = False
    doc.recompute()
    assert op.isValid(), op.getStatusString()
    PAGE = "TmmWaterlineOpPage"
    open_panel(op)
    info["wl_ranges"] = {name: [field(name).property("minimum"), field(name).property("maximum")]
                         for name in ("stepDown", "sampleStep", "chordTolerance", "topZ")}
    assert info["wl_ranges"]["chordTolerance"] == [0.0001, 1.0], info["wl_ranges"]  # the params' [0.0001, 1] mm
    assert info["wl_ranges"]["stepDown"][0] == 0.0 and info["wl_ranges"]["topZ"] == [-10000.0, 10000.0], info
    commands = len(op.Path.Commands)
    type_into("sampleStep", "0.00001")
    info["wl_refused"] = field("sampleStep").property("tmmRefused")
    assert "waterline drops and points" in (info["wl_refused"] or ""), info["wl_refused"]
    shot(info, "08_waterline_limit_refused")
    button(QtGui.QDialogButtonBox.Apply).click()
    text = take_box(info, "box_wl_limit")
    assert "Not computed" in text and len(op.Path.Commands) == commands and op.isValid(), text
    op.ViewObject.Proxy.panel.reject()
    pump(0.5)
    # 9. a post that fails (FreeCAD's Post command calls the same export): a box, the error still raised
    from tmm_workbench.app import posts
    from tmm_workbench.core.errors import TmmError

    try:
        posts.export("tarus", [op.ToolController, op], args="--a-min 0")
        raise AssertionError("the tarus post took --a-min without --a-max")
    except TmmError as exc:
        info["post_error"] = str(exc)
    text = take_box(info, "box_post")
    assert text.startswith("post 'tarus': ") and "--a-min" in text, text
    gui_runner.close_document(doc)



gui_runner.run(session, RESULT)
