"""The Surface op panel's group box for the machining region, the spiral and the slope range: widget -> property
tables the op page binds like its own, the sketch chooser, and "Use selected
faces" (the faces selected in the 3D view become RegionFaces, Region becomes Faces)."""
from __future__ import annotations

from typing import Any

import FreeCADGui

from tmm_workbench.app import region_source
from tmm_workbench.gui import object_chooser

NO_SKETCH = "(none)"


def sketch_candidates(obj: Any) -> list[Any]:
    """Objects whose edges can bound a region: sketches and other 2D objects, and edge-only shapes whose
    wires are all closed (the Job's model clones and stock are solids: never among them)."""
    return [o for o in object_chooser.edge_objects(obj.Document) if o.isDerivedFrom("Part::Part2DObject")
            or (not o.Shape.Faces and all(w.isClosed() for w in o.Shape.Wires))]


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


def reference_candidates(obj: Any) -> list[Any]:
    """The tool controllers of the op's Job but its own: a rest's reference tool."""
    from tmm_workbench.app.simulation import job_of

    job = job_of(obj)
    own = getattr(obj, "ToolController", None)
    tcs = list(getattr(getattr(job, "Tools", None), "Group", []) or []) if job is not None else []
    return [tc for tc in tcs if own is None or tc.Name != own.Name]


def get_fields(page: Any, obj: Any) -> None:
    if not _has_group(page):
        return
    object_chooser.write(page.form.regionSketch, obj, "RegionSketch")
    if hasattr(page.form, "restReference") and hasattr(obj, "RestReference"):
        object_chooser.write(page.form.restReference, obj, "RestReference")
    if hasattr(page.form, "pencilPasses") and hasattr(obj, "PencilPasses"):
        passes = int(page.form.pencilPasses.value())   # a count: a plain spin box, not a quantity
        if obj.PencilPasses != passes:
            obj.PencilPasses = passes


def set_fields(page: Any, obj: Any) -> None:
    if not _has_group(page):
        return
    object_chooser.fill(page.form.regionSketch, sketch_candidates(obj), obj.RegionSketch)
    if hasattr(page.form, "restReference") and hasattr(obj, "RestReference"):
        object_chooser.fill(page.form.restReference, reference_candidates(obj), obj.RestReference)
    if hasattr(page.form, "pencilPasses") and hasattr(obj, "PencilPasses"):
        page.form.pencilPasses.setValue(int(obj.PencilPasses))
    page.form.regionFacesInfo.setText(faces_text(obj))


def signals(page: Any) -> list[Any]:
    if not _has_group(page):
        return []
    return [page.form.regionSketch.currentIndexChanged] + (
        [page.form.restReference.currentIndexChanged, page.form.pencilPasses.valueChanged]
        if hasattr(page.form, "restReference") else [])
