"""The Surface op panel's rows for where the 3D offset's passes start (app.offset_start): the
OffsetStart combo (bound like the page's own) and the OffsetCurve chooser (sketches and objects with edges, open
or closed)."""
from __future__ import annotations

from typing import Any

from tmm_workbench.gui import object_chooser



def curve_candidates(obj: Any) -> list[Any]:
    """Objects whose edges can start the passes: sketches and other 2D objects, and edge-only shapes (the Job's
    model clones and stock are solids: never among them)."""
    return [o for o in object_chooser.edge_objects(obj.Document)
            if o.isDerivedFrom("Part::Part2DObject") or not o.Shape.Faces]


def _has_rows(page: Any) -> bool:
    return hasattr(page.form, "offsetCurve")


def get_fields(page: Any, obj: Any) -> None:
    if _has_rows(page):
        object_chooser.write(page.form.offsetCurve, obj, "OffsetCurve")


def set_fields(page: Any, obj: Any) -> None:
    if _has_rows(page):
        object_chooser.fill(page.form.offsetCurve, curve_candidates(obj), obj.OffsetCurve)


def signals(page: Any) -> list[Any]:
    return [page.form.offsetCurve.currentIndexChanged] if _has_rows(page) else []
