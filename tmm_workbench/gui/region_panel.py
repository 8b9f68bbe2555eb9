"""The Surface op panel's group box for the machining region, the spiral and the slope range (issue 14
item 3): widget -> property tables the op page binds like its own, the sketch chooser, and "Use selected
faces" (the faces selected in the 3D view become RegionFaces, Region becomes Faces)."""
from __future__ import annotations

from typing import Any

import FreeCADGui

from tmm_workbench.app import region_source

SPIN_BOXES = {"regionTolerance": "RegionTolerance", "slopeMin": "SlopeMin", "slopeMax": "SlopeMax"}
COMBOS = {"region": "Region", "spiralDirection": "SpiralDirection"}
NO_SKETCH = "(none)"


def sketch_candidates(obj: Any) -> list[Any]:
    """Objects whose edges can bound a region: sketches and other 2D objects, and edge-only shapes whose
    wires are all closed (the Job's model clones and stock are solids: never among them)."""
    out = []
    for o in obj.Document.Objects:
        if not hasattr(o, "Shape") or hasattr(o, "PathResource"):
            continue
        shape = o.Shape
        if shape.isNull() or not shape.Edges:
            continue
        if o.isDerivedFrom("Part::Part2DObject") or (not shape.Faces and all(w.isClosed() for w in shape.Wires)):
            out.append(o)
    return out


def faces_text(obj: Any) -> str:
    links = list(obj.RegionFaces or [])
    if not links:
        return "No region faces: select faces of the model and press Use selected faces"
    names = [f"{o.Label}.{s}" for o, subs in links for s in subs]
    return f"{len(names)} region face(s): " + ", ".join(names[:6]) + (" ..." if len(names) > 6 else "")


def use_selection(page: Any, obj: Any) -> None:
    """The faces selected in the 3D view as the op's RegionFaces (Region: Faces)."""
    links = []
    for sel in FreeCADGui.Selection.getSelectionEx():
        faces = tuple(n for n in sel.SubElementNames if n.startswith("Face"))
        if faces:
            links.append((sel.Object, faces))
    if not links:
        page.form.regionFacesInfo.setText("No face selected: select faces of the model in the 3D view first")
        return
    obj.RegionFaces = links
    obj.Region = region_source.FACES
    page.form.region.setCurrentText(region_source.FACES)
    page.form.regionFacesInfo.setText(faces_text(obj))


def _has_group(page: Any) -> bool:
    """Pages derived from the Surface page (roughing, waterline) have no region group box."""
    return hasattr(page.form, "regionGroup")


def init_fields(page: Any, obj: Any) -> None:
    if _has_group(page):
        page.form.regionFacesButton.clicked.connect(lambda: use_selection(page, obj))


def get_fields(page: Any, obj: Any) -> None:
    if not _has_group(page):
        return
    name = page.form.regionSketch.currentData()
    target = obj.Document.getObject(name) if name else None
    if obj.RegionSketch != target:
        obj.RegionSketch = target


def set_fields(page: Any, obj: Any) -> None:
    if not _has_group(page):
        return
    combo = page.form.regionSketch
    combo.blockSignals(True)
    combo.clear()
    combo.addItem(NO_SKETCH, "")
    for o in sketch_candidates(obj):
        combo.addItem(o.Label, o.Name)
    index = combo.findData(obj.RegionSketch.Name) if obj.RegionSketch is not None else 0
    combo.setCurrentIndex(max(index, 0))
    combo.blockSignals(False)
    page.form.regionFacesInfo.setText(faces_text(obj))


def signals(page: Any) -> list[Any]:
    return [page.form.regionSketch.currentIndexChanged] if _has_group(page) else []
