"""The Surface op panel's rows for the pencil's given curves (app.pencil_source): the PencilCurve chooser (sketches
and objects with edges, as the 3D offset's curve) and the PencilFile field with its file dialog; each enabled with
the PencilSource that reads it."""
from __future__ import annotations

from typing import Any

from PySide import QtGui

from tmm_workbench.app import pencil_source
from tmm_workbench.gui import object_chooser, offset_start_panel


def _has_rows(page: Any) -> bool:
    return hasattr(page.form, "pencilCurve")


def init_fields(page: Any, obj: Any) -> None:
    if _has_rows(page):
        page.form.pencilFileBrowse.clicked.connect(lambda: browse(page))


def browse(page: Any) -> None:
    name, _ = QtGui.QFileDialog.getOpenFileName(page.form, "Pencil footprint file", page.form.pencilFile.text(),
                                                "Footprint (*.txt *.csv *.fp *.xyl);;All files (*)")
    if name:
        page.form.pencilFile.setText(name)
        page.pageGetFields()


def get_fields(page: Any, obj: Any) -> None:
    if not _has_rows(page):
        return
    object_chooser.write(page.form.pencilCurve, obj, "PencilCurve")
    path = page.form.pencilFile.text().strip()
    if str(obj.PencilFile or "") != path:
        obj.PencilFile = path


def set_fields(page: Any, obj: Any) -> None:
    if not _has_rows(page):
        return
    object_chooser.fill(page.form.pencilCurve, offset_start_panel.curve_candidates(obj), obj.PencilCurve)
    page.form.pencilFile.setText(str(obj.PencilFile or ""))
    enable(page, obj)


def enable(page: Any, obj: Any) -> None:
    """Each row enabled with the source that reads it."""
    if not _has_rows(page):
        return
    source = getattr(obj, "PencilSource", pencil_source.CREASES)
    page.form.pencilCurve.setEnabled(source == pencil_source.OUTLINE)
    for w in (page.form.pencilFile, page.form.pencilFileBrowse):
        w.setEnabled(source == pencil_source.FILE)


def signals(page: Any) -> list[Any]:
    if not _has_rows(page):
        return []
    return [page.form.pencilCurve.currentIndexChanged, page.form.pencilFile.editingFinished]
