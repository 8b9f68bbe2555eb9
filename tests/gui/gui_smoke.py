"""GUI smoke test, run by FreeCAD itself: `xvfb-run -a freecad tests/gui/gui_smoke.py`.

FreeCAD starts, the TMM workbench activates (TMM and Path commands registered), the API makes a Job
with a TMM Surface op, the TMM Surface command adds a second op and opens its task panel, the main
window (with the 3D view rendered offscreen) is grabbed into a PNG; TMM Simulate on that Job shows its
numbers and the stock coloured by deviation (grabbed into gui_simulate.png beside it) and leaves nothing
when closed; the API's 5-axis Multipoint op opens its panel and the 5-axis command adds an op on the
selected face; TMM Roughing and TMM Waterline are made by their commands, their panels open and OK gives
their paths; then a document saved headless (env TMM_GUI_REOPEN, made by make_headless_doc.py) is
reopened and its op's panel opens; the GUI progress dialog reports a Cancel; FreeCAD quits. The outcome
goes to env TMM_GUI_RESULT (a JSON file) and the exit code (os._exit: the GUI would otherwise swallow
SystemExit). Screenshot: env TMM_GUI_PNG, default <repo>/out/gui_smoke.png.
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
PNG = Path(os.environ.get("TMM_GUI_PNG") or ROOT / "out" / "gui_smoke.png")
RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_smoke.json")


def find_panel(name: str = "TmmSurfaceOpPage") -> QtGui.QWidget:
    for w in FreeCADGui.getMainWindow().findChildren(QtGui.QWidget, name):
        if w.isVisible():
            return w
    raise AssertionError(f"the task panel page {name} is not visible")


def close_panel(op) -> None:
    """Closes the op's task panel as its Cancel button does. (Control.closeDialog() would skip PathOpGui's
    clean-up, and its leftover observers crash FreeCAD when a later document makes a tool controller.)"""
    op.ViewObject.Proxy.panel.reject()
    pump(0.3)
    assert not FreeCADGui.Control.activeDialog(), "the task panel stayed open"
    gui_runner.forget_found_widgets()


def screenshot(png: Path) -> None:
    """The main window into `png`."""
    mw = FreeCADGui.getMainWindow()
    png.parent.mkdir(parents=True, exist_ok=True)
    shot = mw.grab()
    # the 3D view draws with OpenGL, which a widget grab misses under Xvfb: render it offscreen
    # and paint it where the view is
    area = mw.findChild(QtGui.QMdiArea)
    view = (area.activeSubWindow() or area.currentSubWindow()).widget()  # none active after a dialog closed
    rect = QtCore.QRect(view.mapTo(mw, QtCore.QPoint(0, 0)), view.size())
    png3d = png.with_name(png.stem + "_3d.png")
    FreeCADGui.activeDocument().activeView().saveImage(str(png3d), rect.width(), rect.height(), "White")
    painter = QtGui.QPainter(shot)
    painter.drawImage(rect, QtGui.QImage(str(png3d)))
    painter.end()
    assert shot.save(str(png)), f"could not write {png}"


def click_close() -> None:
    """The task dialog's Close button, as a user clicks it."""
    for box in FreeCADGui.getMainWindow().findChildren(QtGui.QDialogButtonBox):
        button = box.button(QtGui.QDialogButtonBox.Close)
        if button is not None and button.isVisible():
            button.click()
            pump(0.5)
            gui_runner.forget_found_widgets()
            return
    raise AssertionError("the task panel has no visible Close button")


def simulate_panel(info: dict, r) -> None:
    """TMM Simulate on the API's Job: the panel at cell 0.5 mm shows the numbers, the coloured stock is in the
    3D view (screenshot), and Close removes it and shows the Job's objects again (nothing left in the
    document)."""
    from tmm_workbench.gui import simulate_cmd, stock_view

    before = sorted(o.Name for o in r.doc.Objects)
    shown = sorted(o.Name for o in r.doc.Objects if o.ViewObject is not None and o.ViewObject.Visibility)
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(r.job)
    FreeCADGui.runCommand(simulate_cmd.COMMAND_NAME)
    pump(1.0)
    page = find_panel(simulate_cmd.PANEL_NAME)
    cell, button = page.findChild(QtGui.QDoubleSpinBox, "cell"), page.findChild(QtGui.QPushButton, "simulate")
    estimate = page.findChild(QtGui.QLabel, "estimate")
    info["sim_cell_range"] = [cell.minimum(), cell.maximum(), cell.suffix()]
    assert info["sim_cell_range"] == [0.005, 10.0, " mm"], info["sim_cell_range"]
    cell.setValue(0.005)  # a grid above the work limits: told at once, nothing simulated
    info["sim_estimate_fine"] = estimate.text()
    assert "will fail" in info["sim_estimate_fine"] and "simulation cells" in info["sim_estimate_fine"], info
    assert not button.isEnabled(), "Simulate stays enabled for a refused cell size"
    cell.setValue(0.5)
    info["sim_estimate"] = estimate.text()
    assert info["sim_estimate"].startswith("about ") and " cells (" in info["sim_estimate"], info
    assert button.isEnabled()
    page.findChild(QtGui.QPushButton, "simulate").click()  # returns when done (the progress dialog pumps)
    pump(1.0)

    def shown_value(name: str):
        return page.findChild(QtGui.QLabel, name).property("value")
    info["sim_status"] = page.findChild(QtGui.QLabel, "status").text()
    info["sim_max_left"] = shown_value("maxLeft")
    info["sim_min_deviation"] = shown_value("minDeviation")
    info["sim_p95"] = shown_value("p95")
    info["sim_removed_cm3"] = shown_value("removedVolume")
    info["sim_cycle_s"] = shown_value("cycleTime")
    info["sim_cell"] = shown_value("cellSize")
    info["sim_collisions"] = page.findChild(QtGui.QLabel, "collisions").text()
    info["sim_legend"] = [page.findChild(QtGui.QLabel, n).text() for n in ("legendMin", "legendZero", "legendMax")]
    info["sim_gouged"] = info["sim_status"].startswith("GOUGED")
    assert info["sim_max_left"] is not None, f"no simulation results: {info['sim_status']}"
    scene = FreeCADGui.activeDocument().activeView().getSceneGraph()
    info["sim_node"] = stock_view.find_node(scene)
    mw = FreeCADGui.getMainWindow()
    for dock in mw.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.isAncestorOf(page):
            mw.resizeDocks([dock], [430], QtCore.Qt.Horizontal)  # the whole panel in the picture
    pump(0.5)
    png = PNG.with_name("gui_simulate.png")
    screenshot(png)
    info["sim_png"] = str(png)
    click_close()
    info["sim_panel_closed"] = not FreeCADGui.Control.activeDialog()
    info["sim_node_removed"] = not stock_view.find_node(scene)
    info["sim_doc_unchanged"] = sorted(o.Name for o in r.doc.Objects) == before
    info["sim_visibility_restored"] = shown == sorted(
        o.Name for o in r.doc.Objects if o.ViewObject is not None and o.ViewObject.Visibility)
    assert info["sim_panel_closed"], "the simulate panel stayed open"


def multipoint_panel(info: dict) -> None:
    """The 5-axis op: the API's op has our view provider and its panel shows the contact summary; the
    command, with the op's face selected, adds a second op and opens its panel."""
    from tmm_workbench.app.api import run_multipoint
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.app import registry
    from tmm_workbench.core.shared_data import benchmark_file
    from tmm_workbench.gui.op_multipoint_gui import ViewProvider as MultipointViewProvider

    net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
    r = run_multipoint(net, side_step=36.0, forward_step=6.0, posts=(), doc_name="TmmGuiMultipoint",
                       progress=True, surface_extension=12.7, footprint_anchor="tip",
                       pass_spacing="fixed")
    assert isinstance(r.op.ViewObject.Proxy, MultipointViewProvider), type(r.op.ViewObject.Proxy)
    assert Path(r.op.ViewObject.Proxy.getIcon()).is_file(), "the 5-axis op's tree icon is not a file"
    r.op.ViewObject.Document.setEdit(r.op.ViewObject, 0)
    pump(1.0)
    page = find_panel("TmmMultipointOpPage")
    info["multipoint_side_step"] = page.findChild(QtGui.QWidget, "sideStep").property("rawValue")
    info["multipoint_contacts"] = page.findChild(QtGui.QLabel, "contacts").text()
    assert abs(info["multipoint_side_step"] - 36.0) < 1e-9, info["multipoint_side_step"]
    assert info["multipoint_contacts"] == r.op.ContactSummary and "two" in info["multipoint_contacts"], \
        info["multipoint_contacts"]
    # the surface extension and footprint anchor fields show the op's values
    info["mp_extension"] = page.findChild(QtGui.QWidget, "surfaceExtension").property("rawValue")
    anchor = page.findChild(QtGui.QComboBox, "footprintAnchor")
    info["mp_anchor"] = [anchor.currentText(), [anchor.itemText(i) for i in range(anchor.count())]]
    assert abs(info["mp_extension"] - 12.7) < 1e-9, info["mp_extension"]
    assert info["mp_anchor"] == ["Tip", ["Axis", "Tip"]], info["mp_anchor"]
    spacing = page.findChild(QtGui.QComboBox, "passSpacing")
    info["mp_pass_spacing"] = [spacing.currentText(), [spacing.itemText(i) for i in range(spacing.count())]]
    assert info["mp_pass_spacing"] == ["Fixed", ["Even", "Fixed", "Scallop"]], info["mp_pass_spacing"]
    close_panel(r.op)
    obj, face = r.face
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(obj, face)
    FreeCADGui.runCommand(registry.entry("TMM_Multipoint").command_name)
    pump(1.5)
    ops = [o for o in r.job.Operations.Group if o is not r.op]
    assert ops, "the 5-axis command made no op"
    assert ops[0].Base and ops[0].Base[0][1] == (face,), ops[0].Base
    find_panel("TmmMultipointOpPage")
    info["multipoint_command_panel"] = True
    close_panel(ops[0])  # Cancel: the new op goes again
    gui_runner.close_document(r.doc)


def zlevel_panels(info: dict) -> None:
    """TMM Roughing and TMM Waterline, each made by its command in a Job on a Part block with a pocket: its
    panel opens (step-over in % of the diameter, the page fits a 1000 px screen without scrolling), OK
    recomputes it and the Job holds its path."""
    import Part
    from tmm_workbench.app import job as jobs
    from tmm_workbench.app import registry, tools

    doc = FreeCAD.newDocument("TmmGuiZlevel")
    block = doc.addObject("Part::Feature", "PocketBlock")
    block.Shape = Part.makeBox(40, 30, 10).cut(Part.makeBox(20, 12, 10, FreeCAD.Vector(10, 9, 5)))
    doc.recompute()
    job = jobs.create_job(doc, block)
    jobs.set_tool(job, tools.make_tool_bit(doc, "endmill", 6.0), 20.0, 5.0, 10000)
    doc.recompute()
    for name, page_name in (("TMM_Roughing", "TmmRoughingOpPage"), ("TMM_Waterline", "TmmWaterlineOpPage")):
        before = list(job.Operations.Group)
        FreeCADGui.Selection.clearSelection()
        FreeCADGui.runCommand(registry.entry(name).command_name)
        pump(1.5)
        ops = [o for o in job.Operations.Group if o not in before]
        assert ops, f"the {name} command made no op"
        op = ops[0]
        page = find_panel(page_name)
        key = name.split("_")[1].lower()
        info[f"{key}_page_height"] = page.sizeHint().height()
        assert info[f"{key}_page_height"] < 760, f"the {name} page needs {info[f'{key}_page_height']} px"
        if name == "TMM_Waterline":   # its rest row: RestOnly, off as the new op
            rest_only = page.findChild(QtGui.QCheckBox, "restOnly")
            info["waterline_rest_only"] = [rest_only.isChecked(), op.RestOnly]
            assert info["waterline_rest_only"] == [False, False], info["waterline_rest_only"]
        if name == "TMM_Roughing":
            step_over = page.findChild(QtGui.QDoubleSpinBox, "stepOver")
            info["roughing_step_over"] = [step_over.value(), step_over.suffix().strip()]
            assert info["roughing_step_over"] == [op.StepOver, "%"], info["roughing_step_over"]
            good = step_over.value()
            step_over.setValue(0.0)  # 0 % is outside (0, 100) %: marked, never written to the op
            step_over.editingFinished.emit()
            pump(0.3)
            info["roughing_zero_step_over"] = [step_over.property("tmmRefused"), op.StepOver]
            assert "step-over must be in (0, 100) %" in (info["roughing_zero_step_over"][0] or ""), info
            assert info["roughing_zero_step_over"][1] == good, info["roughing_zero_step_over"]
            step_over.setValue(good)
            step_over.editingFinished.emit()
            pump(0.3)
            assert not step_over.property("tmmRefused"), step_over.property("tmmRefused")
        info[f"{key}_step_down"] = page.findChild(QtGui.QWidget, "stepDown").property("rawValue")
        assert abs(info[f"{key}_step_down"] - op.StepDown.Value) < 1e-9, info[f"{key}_step_down"]
        FreeCADGui.activeDocument().activeView().viewIsometric()
        FreeCADGui.SendMsgToActiveView("ViewFit")
        pump(0.3)
        screenshot(PNG.with_name(f"gui_{key}.png"))
        op.ViewObject.Proxy.panel.accept()  # OK: the op is kept and recomputed
        pump(1.0)
        assert not FreeCADGui.Control.activeDialog(), f"the {name} panel stayed open"
        info[f"{key}_valid"] = op.isValid()
        info[f"{key}_commands"] = len(op.Path.Commands)
        assert op.isValid() and len(op.Path.Commands) > 10, (name, op.getStatusString())
        assert op in job.Operations.Group
    gui_runner.close_document(doc)


def stale_form_attribute(info: dict) -> None:
    """gui/form_wrappers.rewrapped: a panel's check box handed out as a plain QWidget wrapper (what a stale wrapper
    at a reused address gives: FreeCAD 1.0 in CI) comes back as a QCheckBox; a right one comes back as its class."""
    from tmm_workbench.gui import form_wrappers, resources

    form = FreeCADGui.PySideUic.loadUi(resources.panel("surface_op"))
    right, name = form.verifyCusp, "arcFitting"
    box = form.findChild(QtGui.QCheckBox, name)
    address = gui_runner.shiboken.getCppPointer(box)[0]
    gui_runner.shiboken.invalidate(box)  # out of PySide's map: the next wrapper of that address is registered there
    setattr(form, name, gui_runner.shiboken.wrapInstance(address, QtGui.QWidget))
    info["stale_attribute_type"] = type(getattr(form, name)).__name__
    form_wrappers.rewrapped(form)
    info["rewrapped_type"] = type(getattr(form, name)).__name__
    info["rewrapped_same_object"] = getattr(form, name).objectName() == name
    info["right_kept"] = type(form.verifyCusp).__name__ == type(right).__name__ == "QCheckBox" \
        and form.verifyCusp.objectName() == "verifyCusp"
    form.deleteLater()


def smoke() -> dict:
    info: dict = {}
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from tmm_workbench.app.compat import freecad_version

    if freecad_version() >= (1, 0):  # TMM's ops in FreeCAD's CAM workbench, before the TMM workbench loads
        FreeCADGui.activateWorkbench("CAMWorkbench")
        pump(1.0)
        bars = [b for b in FreeCADGui.getMainWindow().findChildren(QtGui.QToolBar)
                if b.objectName() == "New Operations"]
        texts = {a.text() for b in bars for a in b.actions()}
        info["cam_toolbar"] = sorted(t for t in texts if "TMM" in t)
        for text in ("TMM 3-axis Surface", "TMM 5-axis Multipoint", "TMM Roughing", "TMM Waterline"):
            assert text in texts, f"'{text}' is not in the CAM workbench's New Operations toolbar: {sorted(texts)}"
    FreeCADGui.activateWorkbench("TMMWorkbench")
    pump(0.5)
    info["workbench"] = FreeCADGui.activeWorkbench().name()
    assert info["workbench"] == "TMMWorkbench", info["workbench"]
    from tmm_workbench.app import registry
    from tmm_workbench.gui import workbench

    commands = set(FreeCADGui.listCommands())
    ops = [e.command_name for e in registry.OPS]
    for cmd in ops + ["TMM_JobFromModel"] + workbench.path_commands(workbench.JOB_TOOLS + workbench.TOOL_TOOLS):
        assert cmd in commands, f"command {cmd} missing"
    assert registry.entry("TMM_Multipoint").command_name in commands, "the 5-axis Multipoint command is missing"

    from tmm_workbench.app.api import run_surface
    from tmm_workbench.core.shared_data import benchmark_file
    from tmm_workbench.gui.op_surface_gui import ViewProvider

    stl = os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl"))
    r = run_surface(stl, stepover=2.0, sample_step=1.0, doc_name="TmmGuiSmoke", progress=True)
    info["api_moves"] = len(r.toolpath)
    assert isinstance(r.op.ViewObject.Proxy, ViewProvider), "API op lacks the TMM view provider"
    assert Path(r.op.ViewObject.Proxy.getIcon()).is_file(), "the op's tree icon is not a file"
    assert r.job.ViewObject.Proxy is not None, "API Job lacks PathJobGui's view provider"
    r.job.ViewObject.Visibility = True
    FreeCADGui.SendMsgToActiveView("ViewFit")
    FreeCADGui.activeDocument().activeView().viewIsometric()

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.runCommand(registry.entry("TMM_Surface").command_name)  # the op command: new op + its task panel
    pump(1.5)
    ops = [o for o in r.job.Operations.Group if o is not r.op]
    assert ops, "the command made no op"
    info["panel_open"] = FreeCADGui.Control.activeDialog()
    assert info["panel_open"], "no task dialog open"
    page = find_panel()
    info["panel_step_over"] = page.findChild(QtGui.QWidget, "stepOver").property("rawValue")
    off = page.findChild(QtGui.QComboBox, "offModel")
    info["panel_off_model"] = [off.currentText(), [off.itemText(i) for i in range(off.count())]]
    assert info["panel_off_model"] == [ops[0].OffModel, ["Floor", "Skip"]], info["panel_off_model"]
    # the region group box (issue 14 item 3): its choices and the op's values
    reg = page.findChild(QtGui.QComboBox, "region")
    info["panel_region"] = [reg.currentText(), [reg.itemText(i) for i in range(reg.count())]]
    assert info["panel_region"] == ["Box", ["Box", "Faces", "Sketch", "Rest"]], info["panel_region"]
    pattern = page.findChild(QtGui.QComboBox, "pattern")
    assert "Spiral" in [pattern.itemText(i) for i in range(pattern.count())], "no Spiral pattern in the panel"
    # the pencil's sources (CleanUp: seed 000's strips) and its curve and file rows, enabled with their source
    source = page.findChild(QtGui.QComboBox, "pencilSource")
    pencil_curve = page.findChild(QtGui.QComboBox, "pencilCurve")
    pencil_file = page.findChild(QtGui.QLineEdit, "pencilFile")
    info["panel_pencil"] = [[source.itemText(i) for i in range(source.count())], pencil_curve.currentText(),
                            pencil_curve.isEnabled(), pencil_file.isEnabled()]
    assert info["panel_pencil"] == [["Creases", "Outline", "File", "CleanUp"], "(none)", False, False], \
        info["panel_pencil"]
    ops[-1].PencilSource = "File"
    pump(0.3)
    info["panel_pencil_file_enabled"] = [pencil_file.isEnabled(), pencil_curve.isEnabled()]
    assert info["panel_pencil_file_enabled"] == [True, False], info["panel_pencil_file_enabled"]
    ops[-1].PencilSource = "Creases"
    # the 3D offset's start (issue 14 item 1): Boundary as the new op, the curve chooser empty
    start = page.findChild(QtGui.QComboBox, "offsetStart")
    curve = page.findChild(QtGui.QComboBox, "offsetCurve")
    info["panel_offset_start"] = [start.currentText(), [start.itemText(i) for i in range(start.count())],
                                  curve.currentText()]
    assert info["panel_offset_start"] == ["Boundary", ["Boundary", "Curve"], "(none)"], info["panel_offset_start"]
    info["panel_slope_max"] = page.findChild(QtGui.QWidget, "slopeMax").property("rawValue")
    assert info["panel_slope_max"] == 90.0, info["panel_slope_max"]
    verify = page.findChild(QtGui.QCheckBox, "verifyCusp")  # issue 14 item 4: off, as the new op
    info["panel_verify_cusp"] = None if verify is None else verify.isChecked()
    assert info["panel_verify_cusp"] is False and ops[-1].VerifyCusp is False, info["panel_verify_cusp"]
    mw = FreeCADGui.getMainWindow()
    for dock in mw.findChildren(QtGui.QDockWidget):
        if dock.isVisible() and dock.isAncestorOf(page):
            mw.resizeDocks([dock], [430], QtCore.Qt.Horizontal)  # the whole panel in the picture
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(1.0)

    screenshot(PNG)
    info["png"] = str(PNG)
    # after the picture: a face selected in the 3D view becomes the region (Use selected faces)
    region_box = r.doc.addObject("Part::Box", "RegionBox")
    r.doc.recompute()
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(region_box, "Face6")
    page.findChild(QtGui.QPushButton, "regionFacesButton").click()
    info["panel_region_faces"] = [ops[0].Region, [[o.Name, list(subs)] for o, subs in ops[0].RegionFaces]]
    assert info["panel_region_faces"] == ["Faces", [["RegionBox", ["Face6"]]]], info["panel_region_faces"]
    assert "RegionBox.Face6" in page.findChild(QtGui.QLabel, "regionFacesInfo").text()
    FreeCADGui.Selection.clearSelection()
    close_panel(ops[0])  # Cancel: the new op goes again
    if r.doc.getObject("RegionBox") is not None:  # Cancel undoes what the panel did, the box too
        r.doc.removeObject("RegionBox")

    stale_form_attribute(info)
    simulate_panel(info, r)

    multipoint_panel(info)

    zlevel_panels(info)

    reopen = os.environ.get("TMM_GUI_REOPEN")
    if reopen:  # a document saved headless: op and Job get their view providers, the panel opens
        doc = FreeCAD.openDocument(reopen)
        op = doc.getObject("TMM_Surface")
        assert op is not None and len(op.Path.Commands) > 10, "reopened op has no path"
        assert isinstance(op.ViewObject.Proxy, ViewProvider), type(op.ViewObject.Proxy)
        assert doc.getObject("Job").ViewObject.Proxy is not None, "reopened Job lacks a view provider"
        op.ViewObject.Document.setEdit(op.ViewObject, 0)
        pump(0.5)
        info["reopened_panel"] = FreeCADGui.Control.activeDialog()
        assert info["reopened_panel"], "no task panel for the reopened op"
        close_panel(op)
        gui_runner.close_document(doc)

    # the GUI progress: a dialog with Cancel that turns into a False from the callback
    from tmm_workbench.app import progress
    from tmm_workbench.gui import progress_dialog

    reporter = progress.reporter("smoke")
    assert isinstance(reporter, progress_dialog.DialogProgress), type(reporter)
    reporter.t0 -= 10  # as if the computation had run a while: the dialog shows
    assert reporter(0.25) is True
    reporter.dialog.cancel()
    info["cancel_seen"] = reporter(0.5) is False
    reporter.finish()
    assert info["cancel_seen"], "cancel in the progress dialog was not reported"
    return info



gui_runner.run(lambda info: info.update(smoke()), RESULT)
