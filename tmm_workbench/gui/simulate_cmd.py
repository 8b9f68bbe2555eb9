"""Command 'TMM Simulate': the selected Job's stock (or one op's) cut by its tool paths and
compared with the design, in a task panel (the numbers of api.simulate, a colour legend) and in the 3D view
(the simulated stock as a mesh coloured by its deviation, RdBu_r as the heat map PNG, grey where there is no
design). The mesh is a Coin node of the view's scene graph, not a document object: closing the panel
removes it and leaves the document as it was (the Job's objects hidden meanwhile are shown again)."""
from __future__ import annotations

import shutil
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any, Optional

import numpy as np

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.sim import compare
from tmm_workbench.core.sim.cycle_time import hms
from tmm_workbench.gui import resources
from tmm_workbench.gui.deviation_legend import DeviationLegend
from tmm_workbench.gui.stock_view import collision_node, stock_node

COMMAND_NAME = "TMM_Simulate"
PANEL_NAME = "TmmSimulatePanel"
CELL_3AXIS, CELL_5AXIS = 0.1, 0.25  # mm: 5-axis sweeps are sub-stepped, so a finer grid costs much more
RED = "color: #c00000; font-weight: bold"


# --- target ------------------------------------------------------------------------------------------
def _is_job(obj: Any) -> bool:
    return hasattr(obj, "Operations") and hasattr(obj, "Stock")


def _is_op(obj: Any) -> bool:
    return hasattr(obj, "Path") and hasattr(obj, "ToolController") and not _is_job(obj)


def selected_target() -> Optional[Any]:
    """The one selected Job, or the one selected Path op inside a Job; None otherwise."""
    from tmm_workbench.app.simulation import job_of

    sel = FreeCADGui.Selection.getSelection()
    if len(sel) != 1:
        return None
    obj = sel[0]
    if _is_job(obj) or (_is_op(obj) and job_of(obj) is not None):
        return obj
    return None


def _is_five_axis(op: Any) -> bool:
    """TMM writes the tool axis (U, V, W) on every motion of a 5-axis path and none on a 3-axis one."""
    return any("W" in c.Parameters for c in op.Path.Commands)


def default_cell(target: Any) -> float:
    from tmm_workbench.app.simulation import job_of, operations

    ops = operations(job_of(target)) if _is_job(target) else [target]
    try:
        return CELL_5AXIS if any(_is_five_axis(op) for op in ops) else CELL_3AXIS
    except Exception:  # a broken op: the simulation will say what is wrong
        return CELL_3AXIS


# --- text ---------------------------------------------------------------------------------------------
def mm(value: float) -> str:
    return f"{value:+.4f} mm"


def cm3(mm3: float) -> str:
    return f"{mm3 / 1000.0:.3f} cm³"


def collisions_text(collisions: list) -> str:
    if not collisions:
        return "none"
    label, move, depth = collisions[0]
    return f"{len(collisions)} (first: op '{label}', move {move}, {depth:.3f} mm deep)"


def ops_text(ops: list) -> str:
    return "\n".join(f"{o.label}: {hms(o.cycle_seconds)} ({'5' if o.five_axis else '3'}-axis, {o.moves} moves)"
                     for o in ops)


def _buttons(flags: Any) -> int:
    """FreeCAD reads the standard buttons as an int (PySide6's flags are Python enums: take .value)."""
    return int(getattr(flags, "value", flags))


# --- the panel ----------------------------------------------------------------------------------------
# (label names, row text): a row of several labels shows them side by side
RESULT_ROWS = ((("maxLeft",), "Max material left"), (("minDeviation",), "Min deviation (gouge)"),
               (("p50", "p95", "p99"), "p50 / p95 / p99"),
               (("removedVolume",), "Removed volume"), (("remainingVolume",), "Remaining above design"),
               (("cycleTime",), "Cycle time"), (("opTimes",), "Per op"), (("collisions",), "Rapid collisions"),
               (("cellSize",), "Cell size"), (("simTime",), "Simulation time"), (("heatMap",), "Heat map"))
# the deviation's direction: (combo text, how the legend says it); Auto picks the normal where walls are steep
DIRECTIONS = (("Auto (along the normal where walls are steep)", ""), ("Along the normal", "along the normal"),
              ("Vertical", "vertical"))


def _spin(name: str, value: float, decimals: int, low: float, high: float, step: float) -> QtGui.QDoubleSpinBox:
    spin = QtGui.QDoubleSpinBox()
    spin.setObjectName(name)
    spin.setDecimals(decimals)
    spin.setRange(low, high)
    spin.setSingleStep(step)
    spin.setSuffix(" mm")
    spin.setValue(value)
    return spin


class SimulatePanel:
    """Inputs (cell, tolerance), the Simulate button, the results and legend; the coloured stock in the view."""

    def __init__(self, target: Any) -> None:
        from tmm_workbench.app.simulation import job_of

        self.target, self.job = target, job_of(target)
        self.scene: Any = None
        self.node: Any = None
        self.hidden: list[Any] = []      # view objects we hid, to show again
        self.report: Any = None          # the last simulation's, recoloured when the band or direction changes
        self.tmp = Path(tempfile.mkdtemp(prefix="tmm_simulate_"))
        self.runs = 0
        self.form = self._build_form()
        # Control.closeDialog() (another command, a closed document) skips reject(): clean up on the form's end
        self.form.destroyed.connect(lambda *_: self.cleanup())
        self.observer: Optional[_DocumentGone] = _DocumentGone(self.job.Document.Name)
        FreeCAD.addDocumentObserver(self.observer)

    # FreeCAD's task dialog protocol (0.20, 1.0, 1.1)
    def getStandardButtons(self) -> int:
        return _buttons(QtGui.QDialogButtonBox.Close)

    def reject(self) -> bool:
        self.cleanup()
        return True

    def accept(self) -> bool:
        return self.reject()

    def isAllowedAlterDocument(self) -> bool:
        return False

    # the form
    def _build_form(self) -> QtGui.QWidget:
        form = QtGui.QWidget()
        form.setObjectName(PANEL_NAME)
        form.setWindowTitle("TMM Simulate")
        form.setWindowIcon(QtGui.QIcon(resources.icon("TMM_Simulate")))
        layout = QtGui.QVBoxLayout(form)
        layout.addWidget(self._inputs_box())
        self.status = QtGui.QLabel("")
        self.status.setObjectName("status")
        self.status.setWordWrap(True)
        layout.addWidget(self.status)
        layout.addWidget(self._results_box())
        layout.addStretch(1)
        return form

    def _inputs_box(self) -> QtGui.QGroupBox:
        box = QtGui.QGroupBox("Simulation")
        grid = QtGui.QFormLayout(box)
        kind = "Job" if _is_job(self.target) else "op"
        of_job = "" if kind == "Job" else f" of Job '{self.job.Label}'"
        target = QtGui.QLabel(f"{kind} '{self.target.Label}'{of_job}")
        target.setObjectName("target")
        grid.addRow("Stock of", target)
        self.cell = _spin("cell", default_cell(self.target), 3, 0.005, 10.0, 0.05)
        self.cell.setToolTip("Size of the simulation grid's square cells: finer shows finer scallops, "
                             "and takes (1 / cell)² longer")
        self.tolerance = _spin("tolerance", 0.01, 4, 0.0, 10.0, 0.005)
        self.tolerance.setToolTip("Cells below the design by more than this are gouges")
        self.band = _spin("band", self.tolerance.value(), 4, 0.0001, 100.0, 0.005)
        self.band.setToolTip("The colours of the stock span -band .. +band (white on the design); cells beyond "
                             "the band take the darkest blue or red. Follows the tolerance until changed")
        self.direction = QtGui.QComboBox()
        self.direction.setObjectName("direction")
        self.direction.addItems([text for text, _ in DIRECTIONS])
        self.direction.setToolTip("The deviation coloured: vertical (what the simulation measures), or along the "
                                  "design's normal (the vertical one times the cosine of the slope: a wall's "
                                  "vertical +2 mm is a few µm along its normal)")
        grid.addRow("Cell size", self.cell)
        grid.addRow("Tolerance", self.tolerance)
        grid.addRow("Colour band ±", self.band)
        grid.addRow("Deviation", self.direction)
        self.tolerance.valueChanged.connect(self.follow_tolerance)
        self.band.valueChanged.connect(lambda *_: self.recolour())
        self.direction.currentIndexChanged.connect(lambda *_: self.recolour())
        self.band_tolerance = self.tolerance.value()  # the band follows the tolerance while they are equal
        self.button = QtGui.QPushButton("Simulate")
        self.button.setObjectName("simulate")
        self.button.clicked.connect(self.simulate)
        grid.addRow(self.button)
        self.estimate = QtGui.QLabel("")
        self.estimate.setObjectName("estimate")
        self.estimate.setWordWrap(True)
        grid.addRow(self.estimate)
        self.cell.valueChanged.connect(lambda *_: self.check_cell())
        self.check_cell()
        return box

    def check_cell(self) -> None:
        """The grid the entered cell size makes, told before any simulation: its cells, or the refusal (a
        grid above the work limits) with Simulate disabled."""
        from tmm_workbench.app.work_estimate import apply_work_limits
        from tmm_workbench.app.simulation import simulation_grid

        try:
            apply_work_limits()
            g = simulation_grid(self.target, self.cell.value())
        except TmmError as exc:
            self.estimate.setText(f"will fail: {exc}")
            self.estimate.setStyleSheet(RED)
            self.button.setEnabled(False)
            return
        self.estimate.setText(f"about {g.nx * g.ny:.3g} cells ({g.nx} x {g.ny})")
        self.estimate.setStyleSheet("")
        self.button.setEnabled(True)

    def _results_box(self) -> QtGui.QGroupBox:
        box = QtGui.QGroupBox("Results (vertical deviation: + left, - gouge)")
        box.setObjectName("results")
        grid = QtGui.QFormLayout(box)
        self.legend = DeviationLegend()
        grid.addRow(self.legend.widget)  # first: it explains the 3D view, and stays in sight
        self.values: dict[str, QtGui.QLabel] = {}
        for names, text in RESULT_ROWS:
            row = QtGui.QHBoxLayout()
            for name in names:
                label = QtGui.QLabel("-")
                label.setObjectName(name)
                label.setWordWrap(len(names) == 1)
                label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse | QtCore.Qt.LinksAccessibleByMouse)
                row.addWidget(label, 1)
                self.values[name] = label
            grid.addRow(text, row)
        self.values["heatMap"].setOpenExternalLinks(True)
        box.setEnabled(False)
        self.results = box
        return box

    def _set(self, name: str, text: str, value: Optional[float] = None, style: str = "") -> None:
        label = self.values[name]
        label.setText(text)
        label.setStyleSheet(style)
        label.setProperty("value", value)  # the number itself, for macros and tests

    def _say(self, text: str, error: bool = False) -> None:
        self.status.setText(text)
        self.status.setStyleSheet(RED if error else "")

    # simulating
    def simulate(self) -> None:
        from tmm_workbench.app import api

        self.remove_node()
        self.clear_results()
        self.report = None
        self.runs += 1
        png = self.tmp / f"deviation_{self.runs}.png"
        self._say("simulating...")
        self.button.setEnabled(False)
        QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
        t0 = time.monotonic()
        try:
            report = api.simulate(self.target, cell=self.cell.value(), tolerance=self.tolerance.value(),
                                  png_path=png, progress=True)
        except Cancelled:
            self._say("cancelled")
            return
        except TmmError as exc:
            self._say(str(exc), error=True)
            return
        except Exception as exc:  # a bug: the console has the traceback, the panel a line (no dialog)
            FreeCAD.Console.PrintError(traceback.format_exc())
            self._say(f"simulation failed: {type(exc).__name__}: {exc}", error=True)
            return
        finally:
            QtGui.QApplication.restoreOverrideCursor()
            self.check_cell()
        self.show_report(report, time.monotonic() - t0)
        self.report = report
        try:
            self.show_node(report)
        except Exception as exc:  # the numbers stand; say why the view has no coloured stock
            FreeCAD.Console.PrintError(traceback.format_exc())
            self._say(f"{self.status.text()}; not shown in the 3D view: {exc}", error=True)

    def clear_results(self) -> None:
        """No numbers of an earlier run beside a new one's error or cancel."""
        for name in self.values:
            self._set(name, "-")
        self.legend.clear()
        self.results.setEnabled(False)

    def show_report(self, r: Any, seconds: float) -> None:
        verdict = (f"GOUGED: {r.gouge_cells} cells below the design by more than {r.tolerance:g} mm"
                   if r.gouged else "no gouge")
        hits = sum(found.count for _, found in r.stock_collisions)
        self._say(verdict + (f"; {len(r.collisions)} rapids cut stock" if r.collisions else "")
                  + (f"; {hits} holder/shank collisions with the stock (red in the 3D view)" if hits else ""),
                  error=bool(r.gouged or r.collisions or hits))
        self._set("maxLeft", mm(r.max_left), r.max_left)
        self._set("minDeviation", mm(r.min_deviation), r.min_deviation, RED if r.gouged else "")
        for p in (50, 95, 99):
            v = float(r.percentiles.get(p, 0.0))
            self._set(f"p{p}", f"{v:+.4f}", v)
        self._set("removedVolume", cm3(r.removed_volume), r.removed_volume / 1000.0)
        self._set("remainingVolume", cm3(r.remaining_volume), r.remaining_volume / 1000.0)
        self._set("cycleTime", hms(r.cycle_seconds), r.cycle_seconds)
        self._set("opTimes", ops_text(r.ops))
        self._set("collisions", collisions_text(r.collisions), float(len(r.collisions)),
                  RED if r.collisions else "")
        grid = r.simulation.grid
        self._set("cellSize", f"{r.cell:g} mm ({grid.nx} x {grid.ny} cells)", r.cell)
        kernel = sum(o.seconds for o in r.ops)
        self._set("simTime", f"{seconds:.2f} s (cutting {kernel:.2f} s)", seconds)
        link = QtCore.QUrl.fromLocalFile(str(r.png)).toString() if r.png else ""
        self._set("heatMap", f'<a href="{link}">deviation map (PNG)</a>' if link else "-")
        self.results.setEnabled(True)

    def shown_deviation(self, sim: Any) -> tuple[np.ndarray, str]:
        """The deviation the colours show and its direction's words: the vertical one the simulation measures,
        or its estimate along the design's normal (Auto: where the design has steep walls)."""
        along = DIRECTIONS[max(0, self.direction.currentIndex())][1]
        design = getattr(sim, "design", None)
        if design is None:
            return sim.comparison.deviation, "vertical"
        if not along:
            along = "along the normal" if compare.has_steep_walls(design, sim.grid.cell) else "vertical"
        if along == "vertical":
            return sim.comparison.deviation, along
        return compare.normal_deviation(sim.comparison.deviation, design, sim.grid.cell), along

    def show_node(self, r: Any, fit: bool = True) -> None:
        sim = r.simulation
        view = FreeCADGui.getDocument(self.job.Document.Name).activeView()
        if not hasattr(view, "getSceneGraph"):
            raise TmmError("the document's active view is not a 3D view")
        deviation, along = self.shown_deviation(sim)
        band = self.band.value()
        node, block = stock_node(sim.grid, sim.result.heights, deviation, r.tolerance, band)
        found = sim.result.stock_collisions
        if found is not None and found.count:  # a child of the stock: hidden and removed with it
            node.addChild(collision_node(found.positions))
        self.scene = view.getSceneGraph()
        self.scene.addChild(node)
        self.node = node
        self.hide_job()
        self.legend.show(deviation, band, along)
        if fit:
            if block > 1:
                self._set("cellSize", self.values["cellSize"].text() + f"; shown every {block} cells", r.cell)
            view.fitAll()

    def follow_tolerance(self, value: float) -> None:
        """The colour band keeps the tolerance's value until the user sets another."""
        if abs(self.band.value() - self.band_tolerance) < 1e-9:
            self.band.setValue(max(value, self.band.minimum()))
        self.band_tolerance = value

    def recolour(self) -> None:
        """The shown stock in the band and direction now chosen, without simulating again."""
        if self.report is None or self.node is None:
            return
        self.drop_node()
        try:
            self.show_node(self.report, fit=False)
        except Exception as exc:  # noqa: BLE001 - the numbers stand; say why the view has no coloured stock
            FreeCAD.Console.PrintError(traceback.format_exc())
            self._say(f"not shown in the 3D view: {exc}", error=True)

    # the view as it was
    def hide_job(self) -> None:
        """The Job's model, stock and paths would hide the coloured stock or fight with it (the design is
        where the stock is, within the scallops): hidden while it shows. The model is the Job's clones and what
        they copy: the source mesh or face (through TMM's stand-in box for a mesh), which is what the user sees;
        a 5-axis op's tool axes hide with their op."""
        models = list(getattr(self.job.Model, "Group", []) or [])
        objs = models + [o for m in models for o in m.OutListRecursive] + [self.job.Stock]
        objs += self.job.Operations.OutListRecursive if self.job.Operations else []
        for obj in objs:
            vo = getattr(obj, "ViewObject", None)
            if vo is not None and vo.Visibility:
                vo.Visibility = False
                self.hidden.append(vo)

    def show_job(self) -> None:
        for vo in self.hidden:
            try:
                vo.Visibility = True
            except Exception:  # the object went meanwhile
                pass
        self.hidden = []

    def remove_node(self) -> None:
        self.drop_node()
        self.show_job()

    def drop_node(self) -> None:
        """The coloured stock out of the scene (the Job's objects stay hidden)."""
        if self.node is not None and self.scene is not None:
            try:
                index = self.scene.findChild(self.node)
                if index >= 0:
                    self.scene.removeChild(index)
            except Exception:  # the view (its document) was closed: the node went with it
                pass
        self.node = self.scene = None

    def cleanup(self) -> None:
        self.remove_node()
        shutil.rmtree(self.tmp, ignore_errors=True)
        if self.observer is not None:
            FreeCAD.removeDocumentObserver(self.observer)
            self.observer = None


class _DocumentGone:
    """Closes the panel when its Job's document closes (0.20's Python task dialogs stay open otherwise)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def slotDeletedDocument(self, doc: Any) -> None:
        if doc.Name == self.name:  # after the deletion, not inside it
            QtCore.QTimer.singleShot(0, FreeCADGui.Control.closeDialog)


# --- the command --------------------------------------------------------------------------------------
class CommandSimulate:
    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": resources.icon("TMM_Simulate"),
                "MenuText": QtCore.QT_TRANSLATE_NOOP("TMM_Simulate", "TMM Simulate"),
                "ToolTip": QtCore.QT_TRANSLATE_NOOP(
                    "TMM_Simulate", "Cuts the selected Job's stock with its active operations (or with the "
                    "selected operation) and compares it with the model: material left, gouges, volumes, "
                    "cycle time, rapids through stock; the simulated stock coloured by its deviation")}

    def IsActive(self) -> bool:
        return FreeCAD.ActiveDocument is not None and selected_target() is not None

    def Activated(self) -> None:
        target = selected_target()
        if target is None:
            return
        if FreeCADGui.Control.activeDialog():
            QtGui.QMessageBox.information(FreeCADGui.getMainWindow(), "TMM",
                                          "Close the open task panel first, then simulate.")
            return
        try:
            FreeCADGui.Control.showDialog(SimulatePanel(target))
        except Exception as exc:  # noqa: BLE001 - a box, one report line, the traceback in the log
            from tmm_workbench.gui import messages

            messages.report("TMM Simulate", exc)


FreeCADGui.addCommand(COMMAND_NAME, CommandSimulate())
