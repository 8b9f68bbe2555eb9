"""A light solid standing in for a mesh model in a Path Job.

FreeCAD 0.20's Job only accepts solids as its Model (a Mesh::Feature fails with "length of box too
small"), and turning a big mesh into a solid is slow (one face per triangle). So a mesh input
stays the operation's own input (its `Model` link or `StlFile`), and the Job gets this box of the
mesh's bounds instead: it gives the Job its extents, its Stock and the default heights, and follows
the mesh when the mesh or the file changes. It is never machined itself: the TMM operation reads
the mesh it stands for (see `source_of`).
"""
from __future__ import annotations

import os
from typing import Any, Optional

import FreeCAD
import Part

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.app import geometry, hooks

MIN_THICKNESS_MM = 0.01  # a flat mesh still needs a solid box (grown downwards, the top stays)
TYPE_TAG = "TmmModelBounds"


class ModelBounds:
    """Proxy of a Part::FeaturePython whose shape is the bounding box of a mesh or an STL file."""

    def __init__(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLink", "Source", "TMM", "Mesh object this box stands for")
        obj.addProperty("App::PropertyFile", "StlFile", "TMM", "STL file this box stands for (if no Source)")
        obj.addProperty("App::PropertyString", "TmmType", "TMM", "Marks TMM's stand-in solids")
        obj.setEditorMode("TmmType", 2)
        obj.TmmType = TYPE_TAG
        obj.Proxy = self

    def execute(self, obj: Any) -> None:
        if obj.Source is not None:
            bb = obj.Source.Mesh.BoundBox if hasattr(obj.Source, "Mesh") else obj.Source.Shape.BoundBox
            lo = (bb.XMin, bb.YMin, bb.ZMin)
            hi = (bb.XMax, bb.YMax, bb.ZMax)
        elif obj.StlFile:
            mesh = geometry.mesh_from_stl(obj.StlFile)
            lo, hi = (tuple(float(c) for c in b) for b in mesh.bounds)
        else:
            raise TmmError(f"{obj.Label}: neither a source mesh nor an STL file is set")
        size = [max(h - l, MIN_THICKNESS_MM) for l, h in zip(lo, hi)]
        base = FreeCAD.Vector(lo[0], lo[1], hi[2] - size[2])
        obj.Shape = Part.makeBox(size[0], size[1], size[2], base)

    def onDocumentRestored(self, obj: Any) -> None:
        # a document saved without the GUI (or before the box had its view provider) would show the box
        hooks.attach_view("bounds", obj)

    def __getstate__(self) -> None:
        return None

    def __setstate__(self, state: Any) -> None:
        return None


def create(doc: Any, source: Any = None, stl_file: Optional[str] = None, name: str = "ModelBounds") -> Any:
    obj = doc.addObject("Part::FeaturePython", name)
    ModelBounds(obj)
    if source is not None:
        obj.Source = source
        obj.Label = f"{source.Label}-bounds"
    if stl_file:
        obj.StlFile = str(stl_file)
        obj.Label = f"{os.path.splitext(os.path.basename(str(stl_file)))[0]}-bounds"
    # what the user reads in the tree (Description) and the property view, beside the "-bounds" label
    obj.Label2 = ("TMM stand-in: the mesh's bounding box, the Job's model for its extents and stock; hidden, "
                  "the ops machine the mesh")
    obj.recompute()
    if obj.Shape.isNull():
        message = obj.getStatusString()
        doc.removeObject(obj.Name)
        raise TmmError(f"no stand-in box for the model: {message}")
    vo = obj.ViewObject
    if vo is not None:  # GUI: a see-through box, so the mesh itself stays in view when the user shows it
        vo.Transparency = 85
        vo.ShapeColor = (0.6, 0.7, 0.9)
    hooks.attach_view("bounds", obj)  # hidden, and it stays hidden when the document is reopened
    return obj


def is_bounds(obj: Any) -> bool:
    return getattr(obj, "TmmType", "") == TYPE_TAG


def source_of(obj: Any) -> Optional[Any]:
    """What a Job model object stands for: (mesh object | STL path) for our boxes, through the Job's
    clone (Draft clone: `Objects[0]`), else None."""
    target = obj
    if not is_bounds(target) and getattr(target, "Objects", None):
        target = target.Objects[0]
    if is_bounds(target):
        return target.Source if target.Source is not None else target.StlFile
    return None


def mesh_of_model(obj: Any, deflection: float) -> TriMesh:
    """The mesh to machine for a model object; TMM's stand-in boxes give what they stand for."""
    source = source_of(obj)
    if source is None:
        return geometry.mesh_from_object(obj, deflection)
    if isinstance(source, str):
        return geometry.mesh_from_stl(source)
    return geometry.mesh_from_object(source, deflection)
