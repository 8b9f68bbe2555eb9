"""What a 5-axis face op machines, from the API's face source: a Bézier control net (array (m+1, n+1, 3), mm) or a
Part.BezierSurface / BSplineSurface (a Part::Feature made for it in the call's new document), or an (object,
"FaceN") pair of the caller's document; the Job around it, and the face's highest point (for the heights)."""
from __future__ import annotations

from typing import Any

import FreeCAD

from tmm_workbench.app import geometry, op_multipoint
from tmm_workbench.app import job as jobs
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.multipoint import face_top


def owns_document(source: Any) -> bool:
    """A net or a surface is machined in a new document; an (object, face) pair in its object's."""
    return face_pair(source)[0] is None


def face_job(doc: Any, source: Any) -> tuple[Any, dict[str, Any], float]:
    """The Job around the source's face in `doc`, the op's Base (the face of the Job's model clone) and the face's
    highest point (its bounding box's top when the face is not one the op can machine: the op says why)."""
    obj, sub = face_pair(source)
    if obj is None:
        obj, sub = surface_feature(doc, source), "Face1"
    doc.recompute()
    try:
        top = face_top(geometry.bezier_face(op_multipoint.face_surface(obj, sub)))
    except TmmError:  # the op reports it (and keeps its message as its status)
        top = obj.Shape.BoundBox.ZMax
    job = jobs.create_job(doc, obj, name="Job")
    return job, {"Base": [(job.Model.Group[-1], (sub,))]}, top


def face_pair(source: Any) -> tuple[Any, str]:
    """(object, "FaceN") for a pair input, (None, "") for a net or a surface."""
    if isinstance(source, (tuple, list)) and len(source) == 2 and hasattr(source[0], "TypeId"):
        obj, sub = source
        if not isinstance(sub, str) or not sub.startswith("Face"):
            raise TmmError(f"face_source: the element of {obj.Label} must be named 'FaceN', got {sub!r}")
        return obj, sub
    return None, ""


def surface_feature(doc: Any, source: Any) -> Any:
    """A Part::Feature holding the face of a surface or of a Bézier control net."""
    import Part

    kind = type(source).__name__
    if kind in ("BezierSurface", "BSplineSurface"):
        surf = source
    else:
        import numpy as np

        try:
            net = np.asarray(source, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise TmmError(f"face_source must be a control net, a Part surface or (object, 'FaceN'); "
                           f"got {type(source).__name__}") from exc
        if net.ndim != 3 or net.shape[2] != 3 or net.shape[0] < 2 or net.shape[1] < 2:
            raise TmmError(f"a Bézier control net must have shape (m+1, n+1, 3), m, n >= 1; got {net.shape}")
        if not np.isfinite(net).all():
            raise TmmError("the Bézier control net has a non-finite coordinate")
        if max(net.shape[:2]) > 26:
            raise TmmError(f"a Bézier net of shape {net.shape} exceeds FreeCAD's degree limit (25)")
        surf = Part.BezierSurface()
        surf.increase(net.shape[0] - 1, net.shape[1] - 1)
        for i in range(net.shape[0]):
            for j in range(net.shape[1]):
                surf.setPole(i + 1, j + 1, FreeCAD.Vector(*map(float, net[i, j])))
    obj = doc.addObject("Part::Feature", "Surface")
    obj.Shape = surf.toShape()
    obj.Label = "Bezier surface" if type(surf).__name__ == "BezierSurface" else "B-spline surface"
    return obj
