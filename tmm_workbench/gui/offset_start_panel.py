"""The Surface op panel's rows for where the 3D offset's passes start (issue 14 item 1, app.offset_start): the
OffsetStart combo (bound like the page's own) and the OffsetCurve chooser (sketches and objects with edges, open
or closed)."""
from __future__ import annotations

from typing import Any

COMBOS = {"offsetStart": "OffsetStart"}
NO_CURVE = "(none)"


def curve_candidates(obj: Any) -> list[Any]:
    """Objects whose edges can start the passes: sketches and other 2D objects, and edge-only shapes (the Job's
    model clones and stock are solids: never among them)."""
    out = []
    for o in obj.Document.Objects:
        if not hasattr(o, "Shape") or hasattr(o, "PathResource"):
            continue
        shape = o.Shape
        if shape.isNull() or not shape.Edges:
            continue
        if o.isDerivedFrom("Part::Part2DObject") or not shape.Faces:
            out.append(o)
    return out


def _has_rows(page: Any) -> bool:
    return hasattr(page.form, "offsetCurve")


def get_fields(page: Any, obj: Any) -> None:
    if not _has_rows(page):
        return
    name = page.form.offsetCurve.currentData()
    target = obj.Document.getObject(name) if name else None
    if obj.OffsetCurve != target:
        obj.OffsetCurve = target


def set_fields(page: Any, obj: Any) -> None:
    if not _has_rows(page):
        return
    combo = page.form.offsetCurve
    combo.blockSignals(True)
    combo.clear()
    combo.addItem(NO_CURVE, "")
    for o in curve_candidates(obj):
        combo.addItem(o.Label, o.Name)
    index = combo.findData(obj.OffsetCurve.Name) if obj.OffsetCurve is not None else 0
    combo.setCurrentIndex(max(index, 0))
    combo.blockSignals(False)


def signals(page: Any) -> list[Any]:
    return [page.form.offsetCurve.currentIndexChanged] if _has_rows(page) else []
