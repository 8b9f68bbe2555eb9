"""The 3-axis Surface op's machining region from FreeCAD objects, as the core's polygons
(core.footprint.region): it bounds the tool centre (the CL point's XY), as FreeCAD's 3D Surface boundary.

  Box     no region: the op's BoundaryShape box with its margin (what the op always did);
  Faces   `RegionFaces`: faces of the model (the op's Model, a Job model or the object a Job model clones),
          tessellated within `RegionTolerance` and projected along Z; their union (each face's shadow);
  Sketch  `RegionSketch`: a sketch or any object whose edges form closed loops (a Draft wire, a Part
          circle...), discretised within `RegionTolerance` (global coordinates, its placement applied),
          projected along Z; inner loops are holes.
Faces and Sketch regions are grown or shrunk by `BoundaryMargin` as the box is (minus the tool radius keeps
the whole tool inside).
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.app.api_args import numbers
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import region
from tmm_workbench.core.params import Spec, check, spec_of
from tmm_workbench.core.polygons import Shape
from tmm_workbench.core.stage import Args, Field, Stage

BOX, FACES, SKETCH, REST = "Box", "Faces", "Sketch", "Rest"
REGIONS = (BOX, FACES, SKETCH, REST)   # Rest: where the Job's earlier ops or a reference tool left material
TOLERANCE_SPEC = Spec("region tolerance", "mm", low=0.001, high=10.0)
MAX_TRIANGLES = 500_000          # of the selected faces' tessellation: refused above, before the union (~20 s)


def _label(obj: Any) -> str:
    return f"'{getattr(obj, 'Label', obj)}'"


def model_objects(op: Any, job: Any) -> list[Any]:
    """The objects whose faces may bound the region: the op's Model, the Job's models and what they clone."""
    from tmm_workbench.app import model_proxy

    if getattr(op, "StlFile", ""):
        return []  # the model is the file: no object's faces are the model's
    out = []
    if getattr(op, "Model", None) is not None:
        out.append(op.Model)
    if job is not None and getattr(job, "Model", None) is not None:
        for m in job.Model.Group:
            if model_proxy.is_bounds(m):  # a stand-in box for a mesh: its faces are not the model's
                continue
            out.append(m)
            out.extend(getattr(m, "Objects", None) or [])
            base = getattr(m, "Base", None)  # Path's model clones of older versions
            if base is not None and hasattr(base, "Shape"):
                out.append(base)
    return out


def faces_region(links: list[tuple[Any, tuple[str, ...]]], models: list[Any], tolerance: float) -> Shape:
    """The union of the linked faces' shadows; TmmError for no faces, a sub-element that is no face, or
    faces of an object that is not the model."""
    if not links:
        raise TmmError("Region 'Faces': no faces selected (RegionFaces is empty): select faces of the model")
    names = {m.Name for m in models}
    tris = []
    for obj, subs in links:
        if obj.Name not in names:
            shown = ", ".join(_label(m) for m in models[:3]) or "none: the op machines an STL file"
            raise TmmError(f"Region 'Faces': the faces belong to {_label(obj)}, which is not the model "
                           f"(the model: {shown}); select faces of the model")
        for sub in subs or ():
            if not str(sub).startswith("Face"):
                raise TmmError(f"Region 'Faces': {_label(obj)}.{sub} is not a face")
            count = len(obj.Shape.Faces)
            if not str(sub)[4:].isdigit() or not 1 <= int(str(sub)[4:]) <= count:
                raise TmmError(f"Region 'Faces': {_label(obj)} has no {sub} (its faces: Face1 to Face{count})")
            face = obj.Shape.getElement(str(sub))
            points, triangles = face.tessellate(tolerance)
            if not triangles:
                continue
            p = np.array([(v.x, v.y) for v in points], dtype=float)
            tris.append(p[np.array(triangles, dtype=np.int64)])
            count = sum(len(t) for t in tris)
            if count > MAX_TRIANGLES:
                raise TmmError(f"Region 'Faces': the selected faces give {count} triangles at RegionTolerance "
                               f"{tolerance:g} mm, more than {MAX_TRIANGLES}: make the tolerance larger")
        if not subs:
            raise TmmError(f"Region 'Faces': no face of {_label(obj)} named (select faces, not the object)")
    if not tris:
        raise TmmError("Region 'Faces': the selected faces gave no triangles")
    return region.triangles_region(np.concatenate(tris), "Region 'Faces'")


def sketch_region(obj: Any, tolerance: float) -> Shape:
    """The region bounded by the closed loops of `obj`'s edges; TmmError for an open loop."""
    if obj is None:
        raise TmmError("Region 'Sketch': no sketch chosen (RegionSketch is empty)")
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull() or not shape.Edges:
        raise TmmError(f"Region 'Sketch': {_label(obj)} has no edges")
    loops = []
    for k, wire in enumerate(shape.Wires, 1):
        if not wire.isClosed():
            a, b = wire.OrderedVertexes[0].Point, wire.OrderedVertexes[-1].Point
            raise TmmError(f"Region 'Sketch': {_label(obj)} is not closed: its loop {k} is open, its ends at "
                           f"({a.x:.6g}, {a.y:.6g}) and ({b.x:.6g}, {b.y:.6g}); close it")
        pts = wire.discretize(Deflection=tolerance)
        loops.append(np.array([(v.x, v.y) for v in pts], dtype=float))
    in_wires = sum(len(w.Edges) for w in shape.Wires)
    if in_wires < len(shape.Edges):
        raise TmmError(f"Region 'Sketch': {_label(obj)} is not closed: {len(shape.Edges) - in_wires} of its "
                       f"edges belong to no loop")
    return region.loops_region(loops, f"Region 'Sketch' {_label(obj)}")


def region_of(op: Any, job: Any) -> Optional[Shape]:
    """The op's region (None: Box) from its Region, RegionFaces, RegionSketch and RegionTolerance."""
    kind = getattr(op, "Region", BOX)
    if kind == BOX:
        return None
    if kind == REST:
        raise TmmError("Region 'Rest' is computed from the model and the tool (app.rest_source.rest_of)")
    tolerance = float(op.RegionTolerance.Value)
    check(TOLERANCE_SPEC, tolerance)  # finer would tessellate without bound
    if kind == FACES:
        shape = faces_region(list(op.RegionFaces or []), model_objects(op, job), tolerance)
    else:
        shape = sketch_region(op.RegionSketch, tolerance)
    margin = float(op.BoundaryMargin.Value)
    if margin:  # as for the box: grown or shrunk on every side (-tool radius: the whole tool inside)
        shape = polygons.offset(shape, margin, arc_tol=min(tolerance, polygons.ARC_TOL))
        if not shape:
            raise TmmError(f"Region '{kind}' shrunk by BoundaryMargin {margin:g} mm leaves nothing")
    return shape


def api_values(args: Args, model: Any) -> dict[str, Any]:
    """The Surface op's region and slope properties for run_surface's arguments `region`: None (the box), an
    object with closed edges (a sketch), or faces: names of the model's faces ("Face3", ["Face3", "Face5"]) or
    (object, names) pairs; and `slope_range`: (min, max) deg or None."""
    from tmm_workbench.core.strategies.surface.params import SurfaceParams

    region, slope_range = args.get("region"), args.get("slope_range")
    values: dict[str, Any] = {}
    if slope_range is not None:
        try:
            low, high = (float(v) for v in slope_range)
        except (TypeError, ValueError):
            raise TmmError(f"slope_range must be (min, max) in deg, got {slope_range!r}") from None
        numbers(slope_min=(low, spec_of(SurfaceParams, "slope_min_deg")),
                 slope_max=(high, spec_of(SurfaceParams, "slope_max_deg")))
        values.update(SlopeMin=low, SlopeMax=high)
    if region is None:
        return values
    if isinstance(region, str) and region.lower() == "rest":
        values.update(Region=REST)
        return values
    doc = getattr(model, "Document", None)  # an STL path gets a new document: no object of the caller's is in it
    for obj in ([region] if hasattr(region, "TypeId") else
                [i[0] for i in (region if isinstance(region, list) else [region]) if isinstance(i, tuple) and i]):
        if getattr(obj, "Document", None) is not doc:
            raise TmmError(f"region {_label(obj)} must be in the model's document (an STL path makes a new "
                           f"one: pass a Mesh or Part object of the region's document as the model)")
    if hasattr(region, "TypeId"):
        values.update(Region=SKETCH, RegionSketch=region)
        return values
    items = [region] if isinstance(region, (str, tuple)) else list(region)
    links: list[tuple[Any, tuple[str, ...]]] = []
    for item in items:
        if isinstance(item, str):
            if not hasattr(model, "Shape") or model.isDerivedFrom("Mesh::Feature"):
                raise TmmError(f"region face {item!r}: face names need a Part model, the model is "
                               f"{_label(model) if hasattr(model, 'Label') else repr(str(model))}")
            links.append((model, (item,)))
        elif isinstance(item, tuple) and len(item) == 2 and hasattr(item[0], "TypeId"):
            subs = (item[1],) if isinstance(item[1], str) else tuple(item[1])
            links.append((item[0], subs))
        else:
            raise TmmError(f"region must be None (the box), 'rest', a sketch, face names of the model or (object, "
                           f"face names) pairs, got {item!r}")
    values.update(Region=FACES, RegionFaces=links)
    return values


STAGE = Stage("region", (
    Field("Region", "choice", "Region",
          "Where the tool centre may go: Box (BoundaryShape with BoundaryMargin), Faces (RegionFaces seen from "
          "above), Sketch (the closed loops of RegionSketch seen from above, inner loops are holes), Rest (where "
          "the Job's earlier ops or a reference tool left more than RestTolerance that this tool reaches)",
          choices={r: r for r in REGIONS}, default=BOX, widget="region"),
    Field("RegionFaces", "sublinks", "Region", "Faces of the model bounding the region"),
    Field("RegionSketch", "link", "Region", "Sketch (or closed edges) bounding the region"),
    Field("RegionTolerance", "length", "Region",
          "How far the region's polygon may depart from the faces' or the sketch's exact outline",
          api="region_tolerance", default=0.01, spec=TOLERANCE_SPEC, widget="regionTolerance"),
    Field("SlopeMin", "angle", "Surface",
          "Cut only where the surface slope is at least this (shallower areas left to another op)", "slope_min_deg",
          widget="slopeMin"),
    Field("SlopeMax", "angle", "Surface",
          "Cut only where the surface slope is at most this (steeper walls left to waterline)", "slope_max_deg",
          widget="slopeMax"),
), composite=("region", "slope_range"), composite_values=api_values)
