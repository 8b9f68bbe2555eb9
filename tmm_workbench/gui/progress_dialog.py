"""GUI progress for TMM computations: a window-modal progress dialog with a Cancel button.

Installed as `tmm_workbench.app.progress.progress_factory` by InitGui.py. The kernel calls the
callback from the main thread (its workers compute meanwhile), so Qt may be used directly.
"""
from __future__ import annotations

import time
from typing import Optional

import FreeCADGui
from PySide import QtCore, QtGui

from tmm_workbench.app.progress import ProgressReporter

SHOW_AFTER_S = 0.4  # short computations finish without a dialog flashing up
STEPS = 1000


class DialogProgress(ProgressReporter):
    def __init__(self, label: str) -> None:
        self.label = label
        self.t0 = time.monotonic()
        self.dialog: Optional[QtGui.QProgressDialog] = None

    def __call__(self, fraction: float) -> bool:
        if self.dialog is None:
            if time.monotonic() - self.t0 < SHOW_AFTER_S:
                # no dialog yet: the window repaints and timers run, the user's clicks and keys wait for it
                QtGui.QApplication.processEvents(QtCore.QEventLoop.ExcludeUserInputEvents)
                return True
            self.dialog = self._open()
        # a phase that restarts its own count never moves the bar back
        self.dialog.setValue(max(self.dialog.value(), int(min(max(fraction, 0.0), 1.0) * STEPS)))
        QtGui.QApplication.processEvents()
        return not self.dialog.wasCanceled()

    def _open(self) -> QtGui.QProgressDialog:
        d = QtGui.QProgressDialog(f"Computing {self.label}...", "Cancel", 0, STEPS, FreeCADGui.getMainWindow())
        d.setWindowTitle("TMM")
        d.setWindowModality(QtCore.Qt.WindowModal)  # the document must not change under the computation
        d.setMinimumDuration(0)
        d.setAutoClose(False)
        d.setAutoReset(False)
        d.show()
        return d

    def finish(self) -> None:
        if self.dialog is not None:
            self.dialog.close()
            self.dialog.deleteLater()
            self.dialog = None


def factory(label: str) -> ProgressReporter:
    return DialogProgress(label)
