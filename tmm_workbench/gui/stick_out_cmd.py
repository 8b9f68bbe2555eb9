"""Command 'TMM Shortest stick-out': for the selected Job (its active 3-axis ops) or op, the shortest stick-out
with which each op's shank and holder never lift the tool or leave a place out (app.stick_out), shown in a
non-modal box and the report view. The holder is each op's own (or its tool controller's)."""
from __future__ import annotations

from typing import Any, Optional

import FreeCAD
import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.gui import resources

COMMAND_NAME = "TMM_StickOut"
BOX_NAME = "TmmStickOutBox"
TITLE = "TMM Shortest stick-out"


def report_text(target: Any) -> str:
    """The box's text: one line per op (app.stick_out.table)."""
    from tmm_workbench.app import stick_out

    return stick_out.table(stick_out.per_op(target))


class CommandStickOut:
    box: Optional[QtGui.QMessageBox] = None

    def GetResources(self) -> dict[str, str]:
        return {"Pixmap": resources.icon(COMMAND_NAME),
                "MenuText": QtCore.QT_TRANSLATE_NOOP(COMMAND_NAME, "TMM Shortest stick-out"),
                "ToolTip": QtCore.QT_TRANSLATE_NOOP(
                    COMMAND_NAME, "For the selected Job (or operation): the shortest stick-out of each 3-axis "
                    "operation's tool with which its shank and holder (the op's Holder, or its tool controller's) "
                    "never keep the tool off the model")}

    def IsActive(self) -> bool:
        from tmm_workbench.gui.simulate_cmd import selected_target

        return FreeCAD.ActiveDocument is not None and selected_target() is not None

    def Activated(self) -> None:
        from tmm_workbench.gui import messages
        from tmm_workbench.gui.simulate_cmd import selected_target

        target = selected_target()
        if target is None:
            return
        QtGui.QApplication.setOverrideCursor(QtCore.Qt.WaitCursor)
        try:
            text = report_text(target)
        except Exception as exc:  # noqa: BLE001 - a box, one report line, the traceback in the log
            messages.report(TITLE, exc)
            return
        finally:
            QtGui.QApplication.restoreOverrideCursor()
        FreeCAD.Console.PrintMessage(f"{TITLE}, {target.Label}:\n{text}\n")
        box = QtGui.QMessageBox(QtGui.QMessageBox.Information, TITLE, f"{target.Label}\n\n{text}",
                                QtGui.QMessageBox.Ok, FreeCADGui.getMainWindow())
        box.setObjectName(BOX_NAME)
        box.setAttribute(QtCore.Qt.WA_DeleteOnClose)
        box.setWindowModality(QtCore.Qt.NonModal)
        box.show()


FreeCADGui.addCommand(COMMAND_NAME, CommandStickOut())
