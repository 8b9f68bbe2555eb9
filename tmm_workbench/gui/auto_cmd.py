"""Command 'TMM Auto': the automatic planner (docs/planner.md) on the selected mesh or Part object, with a recipe
chosen in a task panel (material, finish, machine, tool library, stock margins, where the report goes). OK plans
it as `tmm plan` does (app.plan_run.plan_object: the core's decisions, the ops through the API with their
progress dialogs and Cancel, the simulation's verification) and leaves the Job in the open document for review;
the G-code, heat map, tool path picture, report.json and report.html go to the output folder. A refused recipe
keeps the panel open with the reason; a cancelled or failed run leaves the document as it was."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Optional

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.gui import resources

COMMAND_NAME = "TMM_Auto"
PANEL_NAME = "TmmAutoPanel"
BOX_NAME = "TmmAutoResult"
TITLE = "TMM Auto"
DEFAULT_MATERIAL = "mdf"
DEFAULT_FINISH = "standard"
RED = "color: #c00000"


def selected_model() -> Optional[Any]:
    """The one selected Mesh or Part object (not a Job's own: its stand-in box or stock)."""
    sel = FreeCADGui.Selection.getSelection()
    if len(sel) != 1:
        return None
    obj = sel[0]
    if obj.isDerivedFrom("Mesh::Feature") or (obj.isDerivedFrom("Part::Feature") and not hasattr(obj, "Path")):
        return obj
    return None


def file_name(label: str) -> str:
    """The object's label as a file name (letters, digits, '-', '_')."""
    return re.sub(r"[^A-Za-z0-9_-]+", "_", label).strip("_") or "part"


def default_out_dir(model: Any) -> Path:
    """Beside the saved document, else in the home folder: <folder>/<label>_plan."""
    saved = model.Document.FileName
    base = Path(saved).parent if saved else Path.home() / "tmm_plan"
    return base / f"{file_name(model.Label)}_plan"


def _combo(name: str, items: list[tuple[str, str]], current: str) -> QtGui.QComboBox:
    """A combo box of (shown text, value) items, `current` chosen."""
    box = QtGui.QComboBox()
    box.setObjectName(name)
    for text, value in items:
        box.addItem(text, value)
    box.setCurrentIndex(max(0, box.findData(current)))
    return box


def _spin(name: str, value: float, tip: str) -> QtGui.QDoubleSpinBox:
    spin = QtGui.QDoubleSpinBox()
    spin.setObjectName(name)
    spin.setRange(0.0, 1000.0)
    spin.setDecimals(2)
    spin.setSuffix(" mm")
    spin.setValue(value)
    spin.setToolTip(tip)
    return spin


def _path_row(name: str, text: str, placeholder: str, browse: Any) -> tuple[QtGui.QWidget, QtGui.QLineEdit]:
    row, edit, button = QtGui.QWidget(), QtGui.QLineEdit(text), QtGui.QPushButton("...")
    edit.setObjectName(name)
    edit.setPlaceholderText(placeholder)
    button.setObjectName(name + "Browse")
    button.clicked.connect(lambda: browse(edit))
    lay = QtGui.QHBoxLayout(row)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.addWidget(edit)
    lay.addWidget(button)
    return row, edit


class AutoPanel:
    """The recipe's fields; OK plans the model."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self.job: Any = None
        self.report: Optional[dict] = None
        self.out: Optional[Path] = None
        self.form = self._build_form()

    def _build_form(self) -> QtGui.QWidget:
        from tmm_workbench.core.plan import materials, recipes

        form = QtGui.QWidget()
        form.setObjectName(PANEL_NAME)
        form.setWindowTitle(TITLE)
        lay = QtGui.QFormLayout(form)
        lay.addRow("Model", QtGui.QLabel(self.model.Label))
        self.material = _combo("material", [(m.replace("_", " "), m) for m in materials.names()], DEFAULT_MATERIAL)
        self.material.setToolTip("The stock's material: the speeds and feeds table of the planner")
        self.finish = _combo("finish", [(f"{name}: cusp {p['finish']['cusp']:g} mm, tolerance "
                                         f"{p['finish']['tolerance']:g} mm", name)
                                        for name, p in recipes.FINISHES.items()], DEFAULT_FINISH)
        self.finish.setToolTip("The scallop height the finishing passes keep and the deepest cut below the model "
                               "the verification accepts")
        self.machine = _combo("machine", [(m, m) for m in recipes.MACHINES], next(iter(recipes.MACHINES)))
        self.machine.setToolTip("The machine: its post processor and travels")
        shop = ", ".join(t["name"] for t in recipes.TOOLS)
        library, self.library = _path_row("library", "", f"the shop library: {shop}", self._browse_library)
        self.library.setToolTip("A tool library file (YAML or JSON, {tools: [...]}, or FreeCAD's .fctl; "
                                f"docs/planner.md); empty: the shop library ({shop})")
        self.margin = _spin("stockMargin", recipes.STOCK["margin"], "Stock beyond the model on each side")
        self.above = _spin("stockAbove", recipes.STOCK["above"], "Stock above the model's top")
        out, self.out_dir = _path_row("outputDir", str(default_out_dir(self.model)), "", self._browse_folder)
        self.out_dir.setToolTip("Where the G-code, the pictures, report.json and report.html go")
        for text, widget in (("Material", self.material), ("Finish", self.finish), ("Machine", self.machine),
                             ("Tool library", library), ("Stock margin", self.margin),
                             ("Stock above", self.above), ("Output folder", out)):
            lay.addRow(text, widget)
        self.status = QtGui.QLabel("OK plans the model: roughing, finishing and rest ops chosen by the planner, "
                                   "verified by a simulation")
        self.status.setObjectName("status")
        self.status.setWordWrap(True)
        lay.addRow(self.status)
        return form

    def _browse_library(self, edit: QtGui.QLineEdit) -> None:
        name, _ = QtGui.QFileDialog.getOpenFileName(self.form, "Tool library", edit.text(),
                                                    "Tool library (*.yaml *.yml *.json *.fctl);;All files (*)")
        if name:
            edit.setText(name)

    def _browse_folder(self, edit: QtGui.QLineEdit) -> None:
        name = QtGui.QFileDialog.getExistingDirectory(self.form, "Output folder", edit.text())
        if name:
            edit.setText(name)

    def job_data(self) -> dict:
        """The job file's data for the chosen recipe (the model's file is plan_object's)."""
        from tmm_workbench.core.plan import recipes

        library = self.library.text().strip()
        out = Path(self.out_dir.text().strip() or str(default_out_dir(self.model))).expanduser().resolve()
        return recipes.job_data(self.material.currentData(), self.finish.currentData(), self.machine.currentData(),
                                "", str(out), file_name(self.model.Label),
                                tools=str(Path(library).expanduser().resolve()) if library else None,
                                stock=dict(recipes.STOCK, margin=self.margin.value(), above=self.above.value()))

    # FreeCAD's task dialog protocol
    def getStandardButtons(self) -> int:
        flags = QtGui.QDialogButtonBox.Ok | QtGui.QDialogButtonBox.Cancel
        return int(getattr(flags, "value", flags))

    def reject(self) -> bool:
        return True

    def accept(self) -> bool:
        """Plans; the panel closes (True) when the Job is made, the outcome then shown."""
        if not self.run():
            return False
        job, report, out = self.job, self.report, self.out
        QtCore.QTimer.singleShot(0, lambda: show_result(job, report, out))
        return True

    def run(self) -> bool:
        """Plans the model; False (the panel stays open, the reason on its status line) when it did not."""
        from tmm_workbench.app.plan_run import plan_object
        from tmm_workbench.core.errors import Cancelled, TmmError
        from tmm_workbench.core.plan.job_file import PlanInputError

        self.status.setStyleSheet("")
        self.status.setText("planning...")
        QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
        try:
            data = self.job_data()
            self.out = Path(data["outputs"]["dir"])
            self.job, self.report = plan_object(self.model, data, progress=True)
            return True
        except PlanInputError as exc:
            self._refused(f"Not planned: {exc}")
        except (Cancelled, TmmError) as exc:
            cancelled = isinstance(exc, Cancelled) or "cancelled" in str(exc)
            self._refused("Cancelled: the document is as it was" if cancelled else f"Not planned: {exc}")
        except Exception as exc:  # noqa: BLE001 - a box, one report line, the traceback in the log
            from tmm_workbench.gui import messages

            messages.report(TITLE, exc)
            self._refused(f"Not planned: {type(exc).__name__}: {exc}")
        finally:
            QtGui.QApplication.restoreOverrideCursor()
        return False

    def _refused(self, text: str) -> None:
        FreeCAD.Console.PrintWarning(f"{TITLE}: {text}\n")
        self.status.setStyleSheet(RED)
        self.status.setText(text)


def result_text(report: dict, out: Path) -> str:
    """The box's words: the run's outcome as `tmm plan` says it (core.plan.launch.outcome_lines: what the run
    changed in the plan, the verdict, the numbers, each op's time), where the report is."""
    from tmm_workbench.core.plan.launch import outcome_lines

    return "\n".join(outcome_lines(report["verification"], ops=True) + [f"Report: {out / 'report.html'}"])


def show_result(job: Any, report: dict, out: Path) -> None:
    """The Job selected and fitted in the view; the outcome in the report view and a non-modal box."""
    FreeCADGui.Selection.clearSelection()
    FreeCADGui.Selection.addSelection(job)
    text = result_text(report, out)
    FreeCAD.Console.PrintMessage(f"{TITLE}, {job.Label}:\n{text}\n")
    icon = QtGui.QMessageBox.Information if report["passed"] else QtGui.QMessageBox.Warning
    box = QtGui.QMessageBox(icon, TITLE, f"{job.Label}\n\n{text}", QtGui.QMessageBox.Ok, FreeCADGui.getMainWindow())
    box.setObjectName(BOX_NAME)
    box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    box.setWindowModality(QtCore.Qt.NonModal)
    box.show()


class CommandAuto:
    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": resources.icon(COMMAND_NAME),
                "MenuText": QtCore.QT_TRANSLATE_NOOP(COMMAND_NAME, "TMM Auto"),
                "ToolTip": QtCore.QT_TRANSLATE_NOOP(
                    COMMAND_NAME, "Plans the selected mesh or Part object by itself: choose the material, finish, "
                    "machine and tool library; the planner picks the tools, roughing, finishing and rest ops, "
                    "verifies the Job by a simulation and leaves it in the document, with the G-code and a report")}

    def IsActive(self) -> bool:
        return FreeCAD.ActiveDocument is not None and selected_model() is not None \
            and not FreeCADGui.Control.activeDialog()

    def Activated(self) -> None:
        model = selected_model()
        if model is not None:
            FreeCADGui.Control.showDialog(AutoPanel(model))


FreeCADGui.addCommand(COMMAND_NAME, CommandAuto())
