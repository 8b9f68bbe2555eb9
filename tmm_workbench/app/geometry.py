"""FreeCAD objects -> the core's TriMesh.

Mesh::Feature: `obj.Mesh` already carries the object's Placement (its points are global), so the
topology is taken as is. Part shapes: `shape.tessellate()` works on the located shape, whose
Placement is the object's, so the triangles are global too. STL files: the core reader.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl

DEFAULT_DEFLECTION_MM = 0.01

_stl_cache: dict[tuple[str, int, int], TriMesh] = {}


def mesh_from_stl(path: str | os.PathLike) -> TriMesh:
    """The STL file as a welded mesh; re-read only when the file changes (size or mtime)."""
    p = Path(path).expanduser()
    if not str(path).strip():
        raise TmmError("no STL file given")
    if not p.is_file():
        return load_stl(p)  # the kernel names what is wrong: not found, a directory, ...
    st = p.stat()
    key = (str(p.resolve()), st.st_mtime_ns, st.st_size)
    mesh = _stl_cache.get(key)
    if mesh is None:
        mesh = load_stl(p)
        _stl_cache.clear()  # keep one model in memory, not a growing history
        _stl_cache[key] = mesh
    return mesh


def mesh_from_mesh_feature(obj: Any) -> TriMesh:
    """A Mesh::Feature (or anything with a `.Mesh`) as a TriMesh in global coordinates."""
    points, facets = obj.Mesh.Topology
    if not facets:
        raise TmmError(f"mesh object '{obj.Label}' has no triangles")
    v = np.array([(p.x, p.y, p.z) for p in points], dtype=np.float64)
    f = np.array(facets, dtype=np.int32)
    return TriMesh(v, f, name=obj.Label)


def mesh_from_shape(shape: Any, deflection: float = DEFAULT_DEFLECTION_MM, name: str = "shape") -> TriMesh:
    """A Part shape's faces tessellated within `deflection` mm (global coordinates)."""
    if not (deflection > 0):
        raise TmmError(f"{name}: tessellation tolerance must be positive, got {deflection!r}")
    if shape is None or shape.isNull() or not shape.Faces:
        raise TmmError(f"'{name}' has no faces to machine")
    points, triangles = shape.tessellate(deflection)
    if not triangles:
        raise TmmError(f"'{name}': tessellation gave no triangles")
    v = np.array([(p.x, p.y, p.z) for p in points], dtype=np.float64)
    f = np.array(triangles, dtype=np.int32)
    return TriMesh(v, f, name=name)


def mesh_from_object(obj: Any, deflection: float = DEFAULT_DEFLECTION_MM) -> TriMesh:
    """Mesh features by their triangles, anything with a Part shape by tessellation."""
    if obj is None:
        raise TmmError("no model object given")
    if obj.isDerivedFrom("Mesh::Feature"):
        return mesh_from_mesh_feature(obj)
    if hasattr(obj, "Shape"):
        return mesh_from_shape(obj.Shape, deflection, obj.Label)
    raise TmmError(f"'{obj.Label}' ({obj.TypeId}) is neither a mesh nor a Part shape")


def combine(meshes: list[TriMesh], name: str = "model") -> TriMesh:
    """Several meshes as one (the kernel needs one index)."""
    if len(meshes) == 1:
        return meshes[0]
    verts, tris, offset = [], [], 0
    for m in meshes:
        verts.append(m.vertices)
        tris.append(m.triangles + offset)
        offset += len(m.vertices)
    return TriMesh(np.concatenate(verts), np.concatenate(tris), name=name)


def bezier_face(surface: Any, name: str = "face") -> BezierFace:
    """A Part.BSplineSurface or Part.BezierSurface as the core's face, exactly. Periodic B-splines are made
    non-periodic on a copy first (same geometry); rational ones are refused unless all weights are 1."""
    def weights_of(srf):
        # OCC answers zeros for the weights of a non-rational surface made non-periodic: ask first.
        rational = getattr(srf, "isURational", lambda: True)() or getattr(srf, "isVRational", lambda: True)()
        return np.array(srf.getWeights(), dtype=float) if rational and hasattr(srf, "getWeights") else None

    poles = np.array([[tuple(p) for p in row] for row in surface.getPoles()], dtype=float)
    weights = weights_of(surface)
    if hasattr(surface, "getUKnots"):  # B-spline
        if surface.isUPeriodic() or surface.isVPeriodic():
            surface = surface.copy()
            if surface.isUPeriodic():
                surface.setUNotPeriodic()
            if surface.isVPeriodic():
                surface.setVNotPeriodic()
            poles = np.array([[tuple(p) for p in row] for row in surface.getPoles()], dtype=float)
            weights = weights_of(surface)
        return BezierFace.from_bspline(poles, surface.UDegree, surface.VDegree, surface.getUKnots(),
                                      surface.getUMultiplicities(), surface.getVKnots(), surface.getVMultiplicities(),
                                      weights, name=name)
    if weights is not None and np.max(np.abs(weights - 1.0)) > 1e-12:
        raise TmmError(f"{name}: rational Bézier surface (weights not all 1) is not supported")
    return BezierFace.from_net(poles, name=name)


def stock_box_of(stock: Any) -> tuple[float, float, float, float, float, float]:
    bb = stock.Shape.BoundBox
    return (bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax, bb.ZMax)


def is_box(shape: Any) -> bool:
    """The solid fills its bounding box (FreeCAD's box stocks, a box from the base)."""
    bb = shape.BoundBox
    full = bb.XLength * bb.YLength * bb.ZLength
    return full > 0 and abs(shape.Volume - full) <= 1e-6 * full
