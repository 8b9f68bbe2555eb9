"""A new user's first hour, run by FreeCAD itself under Xvfb: `xvfb-run -a freecad tests/gui/gui_first_hour.py`.

3-axis: an STL (env TMM_GUI_STL, small) read into a Mesh object; *Job from mesh / STL* (its panel, OK); TMM
Roughing and TMM Waterline made by their commands at coarse values, OK; a sketch circle over the model and a TMM
Surface in it with a cusp spacing: its panel refuses a step-over wider than the tool (the field marked, OK shows
why and computes nothing) and warns of a cusp spacing with a flat end mill before computing; the estimate told
before OK against the cutting time of the path OK computes; TMM Simulate on the Job; the Job posted
(tmm_linuxcnc). 5-axis: seed 001's convex Bézier patch machined by the API; with its face selected, the TMM 5-axis
Multipoint command adds an op with the panel's defaults (tool shape from the tool bit), OK; its reopened panel
does not say it will fail; TMM Simulate on the 5-axis Job; the op posted with tarus. Screenshots (800 px wide)
into env TMM_GUI_SHOTS; the outcome to env TMM_GUI_RESULT (JSON) and the exit code."""
import os
import sys
import time
from pathlib import Path

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

ROOT = Path(__file__).resolve().parents[2] if "__file__" in globals() else Path.cwd()
sys.path.insert(0, str(ROOT / "tests" / "gui"))
import gui_runner  # noqa: E402

gui_runner.helpers_of("gui_smoke")  # their helpers, not their runs
from gui_smoke import click_close, close_panel, find_panel, pump  # noqa: E402

gui_runner.helpers_of("gui_user_input")
from gui_user_input import take_box  # noqa: E402

gui_runner.helpers_of("gui_state")
from gui_state import click, screenshot, type_into, visible, wait_closed  # noqa: E402
from gui_state import watch_message_boxes, widen_panel  # noqa: E402

RESULT = Path(os.environ.get("TMM_GUI_RESULT") or ROOT / "out" / "gui_first_hour.json")
SHOT_WIDTH = 800   # small pictures for docs/gui
TIMES: list = []   # (step, monotonic time): where the session's time goes (reported, not asserted)


def shot(name: str) -> str:
    """The main window (gui_state.screenshot, the task panel widened to show its labels) scaled to SHOT_WIDTH px."""
    if FreeCADGui.Control.activeDialog():
        widen_panel(visible(QtGui.QLabel, "status"))
        pump(0.3)
    png = screenshot(name)
    image = QtGui.QImage(png).scaledToWidth(SHOT_WIDTH, QtCore.Qt.SmoothTransformation)
    image = image.convertToFormat(QtGui.QImage.Format_Indexed8)   # 256 colours: a third of the bytes
    assert image.save(png), png
    return png


def enter(fields: dict) -> None:
    """Values entered in the open panel as a user does: a combo box's item chosen by its text, a field typed."""
    for name, text in fields.items():
        widget = visible(QtGui.QWidget, name)
        if isinstance(widget, QtGui.QComboBox):
            index = widget.findText(text)
            assert index >= 0, f"{name} offers no '{text}'"
            widget.setCurrentIndex(index)
            pump(0.2)
        else:
            type_into(widget, text)


def new_op(job, name: str, fields: dict):
    """The op command with nothing selected: the new op's panel, `fields` entered (enter), the panel left open."""
    from tmm_workbench.app import registry

    before = list(job.Operations.Group)
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.runCommand(registry.entry(name).command_name)
    pump(1.5)
    op = next(o for o in job.Operations.Group if o not in before)
    TIMES.append((f"{name} panel open, moves {len(op.Path.Commands)}", time.monotonic()))
    enter(fields)
    return op


def ok(op, info: dict, key: str) -> None:
    """OK: the panel closes, the op computes; its validity and moves into info[key]."""
    click(QtGui.QDialogButtonBox.Ok)
    wait_closed()
    TIMES.append((f"{key} OK", time.monotonic()))
    info[key] = [op.isValid(), len(op.Path.Commands), op.getStatusString()]
    assert op.isValid() and len(op.Path.Commands) > 10, info[key]


def status_text() -> str:
    return visible(QtGui.QLabel, "status").text()


def job_from_stl(info: dict, stl: str):
    doc = FreeCAD.newDocument("TmmFirstHour")
    mesh, job = gui_runner.job_from_stl(doc, stl)
    info["job_panel"] = bool(FreeCADGui.Control.activeDialog())
    click(QtGui.QDialogButtonBox.Ok)
    wait_closed()
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    return doc, mesh, job


def circle_sketch(doc, mesh):
    """A sketch circle over the model's right half, as a user draws the region to finish."""
    import Part

    bb = mesh.Mesh.BoundBox
    sketch = doc.addObject("Sketcher::SketchObject", "FinishRegion")
    centre = FreeCAD.Vector(bb.XMin + 0.65 * bb.XLength, bb.YMin + 0.5 * bb.YLength, 0)
    sketch.addGeometry(Part.Circle(centre, FreeCAD.Vector(0, 0, 1), 0.15 * min(bb.XLength, bb.YLength)))
    sketch.Placement.Base.z = bb.ZMax
    doc.recompute()
    return sketch


def probe(info: dict, op, step: str) -> None:
    info.setdefault("probes", []).append([step, len(op.Path.Commands)])


def flat_end_mill(job):
    """A second tool controller in the Job: a 6 mm flat end mill with the ball's feeds."""
    from tmm_workbench.app import tools
    from tmm_workbench.app.compat import PathToolController

    ball = job.Tools.Group[0]
    tc = PathToolController.Create("TC: Flat 6", tools.make_tool_bit(job.Document, "endmill", 6.0), 2)
    tc.HorizFeed, tc.VertFeed, tc.SpindleSpeed = ball.HorizFeed, ball.VertFeed, ball.SpindleSpeed
    job.Proxy.addToolController(tc)
    job.Document.recompute()
    return tc


def refusals(info: dict, op, flat) -> None:
    """In the open Surface panel: a step-over wider than the tool is refused (OK computes nothing and says why); a
    cusp spacing with a flat end mill is warned on the status line before anything is computed."""
    enter({"stepOverMode": "StepOver", "stepOver": "500 mm"})
    info["wide_stepover_status"] = status_text()
    click(QtGui.QDialogButtonBox.Ok)
    take_box(info, "wide_stepover_box")
    info["wide_stepover_panel_open"] = bool(FreeCADGui.Control.activeDialog())
    probe(info, op, "refused OK")
    enter({"stepOver": "1 mm", "stepOverMode": "Cusp"})
    probe(info, op, "cusp mode")
    ball = op.ToolController.Label
    enter({"toolController": flat.Label, "cuspHeight": "0.05 mm"})   # the user picks the flat end mill
    probe(info, op, "flat tool")
    info["flat_cusp_status"] = status_text()
    shot("hour_2_flat_cusp_warned")
    enter({"toolController": ball})


def cusp_finish(info: dict, doc, mesh, job):
    """A TMM Surface in a sketch circle with a cusp spacing: refusals first, the estimate told, OK computes."""
    from tmm_workbench.app import path_build, work_estimate
    from tmm_workbench.core.sim.cycle_time import three_axis_time

    sketch = circle_sketch(doc, mesh)
    flat = flat_end_mill(job)
    op = new_op(job, "TMM_Surface", {"region": "Sketch", "regionSketch": sketch.Label, "sampleStep": "0.5 mm"})
    info["surface_label"] = op.Label
    probe(info, op, 'new op')
    refusals(info, op, flat)
    est = work_estimate.estimate(op)   # what the status line tells (asserted there)
    info["estimate_text"] = est.text()
    info["estimate_s"] = est.cutting_seconds
    info["surface_status_before"] = status_text()
    shot("hour_3_cusp_finish_panel")
    ok(op, info, "surface")
    info["surface_undo"] = list(doc.UndoNames)
    info["surface_tool"] = op.ToolController.Label
    tc = op.ToolController
    tips, feeds = path_build.line_moves(op.Proxy.path_record)
    info["computed_cutting_s"] = three_axis_time(tips, feeds, tc.HorizRapid.Value, tc.VertRapid.Value).cutting_seconds
    return op


def simulate(info: dict, job, key: str, cell: float) -> None:
    """TMM Simulate on `job` at `cell` mm: its numbers into info[key], a screenshot, Close."""
    from tmm_workbench.gui import simulate_cmd

    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(job)
    FreeCADGui.runCommand(simulate_cmd.COMMAND_NAME)
    pump(1.0)
    page = find_panel(simulate_cmd.PANEL_NAME)
    page.findChild(QtGui.QDoubleSpinBox, "cell").setValue(cell)
    page.findChild(QtGui.QPushButton, "simulate").click()   # returns when done
    FreeCADGui.activeDocument().activeView().viewIsometric()
    FreeCADGui.SendMsgToActiveView("ViewFit")
    pump(1.0)
    info[key] = {"status": page.findChild(QtGui.QLabel, "status").text(),
                 "max_left": page.findChild(QtGui.QLabel, "maxLeft").property("value"),
                 "min_deviation": page.findChild(QtGui.QLabel, "minDeviation").property("value")}
    shot(f"hour_{key}")
    click_close()


def three_axis(info: dict, stl: str) -> None:
    from tmm_workbench.app import posts

    doc, mesh, job = job_from_stl(info, stl)
    shot("hour_1_job_from_stl")
    rough = new_op(job, "TMM_Roughing", {"stepDown": "6 mm", "stepOver": "60", "stockToLeave": "0.5 mm"})
    ok(rough, info, "roughing")
    rough.ViewObject.Document.setEdit(rough.ViewObject, 0)   # a second look: one layer less
    pump(1.0)
    enter({"stepDown": "8 mm"})
    ok(rough, info, "roughing")
    info["roughing_label"] = rough.Label
    info["roughing_undo"] = list(doc.UndoNames)
    water = new_op(job, "TMM_Waterline", {"stepDown": "4 mm", "sampleStep": "1 mm"})
    ok(water, info, "waterline")
    finish = cusp_finish(info, doc, mesh, job)
    TIMES.append(("surface estimate vs path", time.monotonic()))
    simulate(info, job, "4_simulate_3axis", 0.5)
    TIMES.append(("simulated", time.monotonic()))
    text = posts.export(job.PostProcessor, [job.Tools.Group[0], rough, water, finish])
    info["post"] = [job.PostProcessor, text.count("\n"), text.count("G1")]
    gui_runner.close_document(doc)


def five_axis(info: dict) -> None:
    from tmm_workbench.app import posts, registry
    from tmm_workbench.app.api import run_multipoint
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.shared_data import benchmark_file

    net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
    r = run_multipoint(net, side_step=36.0, forward_step=6.0, pass_spacing="fixed", posts=(), doc_name="TmmFirstHour5",
                       progress=True)
    obj, face = r.face
    r.doc.removeObject(r.op.Name)   # the API's op made the Job and the face; the user's op is the command's
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(obj, face)
    FreeCADGui.runCommand(registry.entry("TMM_Multipoint").command_name)
    pump(1.5)
    op = r.job.Operations.Group[-1]
    info["mp_defaults"] = [op.ToolShape, op.PassSpacing, op.Scallop.Value, len(op.Path.Commands)]
    # coarse values (the scallop spacing simulates each pass); the tool shape as the panel offers it
    enter({"passSpacing": "Fixed", "sideStep": "36 mm", "forwardStep": "6 mm"})
    ok(op, info, "multipoint")
    info["multipoint_label"] = op.Label
    op.ViewObject.Document.setEdit(op.ViewObject, 0)   # the reopened panel's status line
    pump(1.0)
    info["mp_reopened_status"] = status_text()
    close_panel(op)
    simulate(info, r.job, "5_simulate_5axis", 2.0)
    text = posts.export("tarus", [op.ToolController, op])
    info["tarus"] = [text.count("\n"), sum(1 for line in text.splitlines() if " A" in line and " C" in line)]
    gui_runner.close_document(r.doc)


def session(info: dict) -> None:
    timer = watch_message_boxes(info)
    TIMES.append(("start", time.monotonic()))
    gui_runner.start_tmm(ROOT)
    from tmm_workbench.core.shared_data import benchmark_file

    try:
        three_axis(info, os.environ.get("TMM_GUI_STL") or str(benchmark_file("stl", "sphere_on_plate.stl")))
        TIMES.append(("3-axis done", time.monotonic()))
        five_axis(info)
        TIMES.append(("5-axis done", time.monotonic()))
    finally:
        info["times"] = [[step, round(t - TIMES[0][1], 1)] for step, t in TIMES]
        timer.stop()


gui_runner.run(session, RESULT)
