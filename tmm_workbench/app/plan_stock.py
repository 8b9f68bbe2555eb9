"""The planner's Job and its stock (core.plan.stock: the plan's `stock`), made here before any op: a box is
FreeCAD's stock from the base, its extents set (as the API sets them); a cylinder or a solid FreeCAD's own stocks:
`CreateCylinder` (axis Z, its placement at the centre of its bottom) or,
for a solid, a clone of the file's shape as FreeCAD's Job editor makes an "existing solid" stock
(`createResourceClone`, the same on 0.20, 1.0 and 1.1). The ops are then added to that Job; its roughing and its
simulation take the stock solid's top as heights (app.op_roughing, app.simulation)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

import FreeCAD

MESH_TOLERANCE = 0.05   # mm: sewing an STL stock's triangles into a solid


def new_job(plan: dict, model: Any = None) -> Any:
    """A Job around the plan's model (`model`, a Mesh or Part object: in its document; None: the plan's STL in a
    new document named after the plan) with the plan's stock and no tool controller (each op adds its own)."""
    from tmm_workbench.app import compat
    from tmm_workbench.app import job as jobs

    own = model is None
    doc = FreeCAD.newDocument(plan["name"]) if own else model.Document
    try:
        jm = jobs.prepare_model(doc, plan["model_file"] if own else model)
        doc.recompute()
        job = jobs.create_job(doc, jm.job_base)
        for tc in list(job.Tools.Group):   # FreeCAD's default 5 mm end mill: the ops bring the library's tools
            bit = tc.Tool
            doc.removeObject(tc.Name)
            if bit is not None:
                compat.remove_toolbit(bit)
        set_job_stock(job, plan["stock"])
    except BaseException:
        if own:
            FreeCAD.closeDocument(doc.Name)
        raise
    return job


def set_job_stock(job: Any, stock: dict) -> None:
    """The Job's stock: the plan's box its extents, or replaced by the plan's cylinder or solid (`stock`:
    core.plan.stock.PlannedStock.as_dict)."""
    from tmm_workbench.app import compat
    from tmm_workbench.app.api_run import set_stock

    doc = job.Document
    FreeCAD.setActiveDocument(doc.Name)
    lo, hi = stock["box_mm"][:3], stock["box_mm"][3:]
    if stock["type"] == "box":
        set_stock(job, tuple(stock["box_mm"]), 0.0, 0.0)
        return
    if stock["type"] == "cylinder":
        cx, cy = stock["centre_mm"]
        new = compat.PathStock.CreateCylinder(job, stock["radius_mm"], hi[2] - lo[2],
                                              FreeCAD.Placement(FreeCAD.Vector(cx, cy, lo[2]), FreeCAD.Rotation()))
    elif stock["type"] == "solid":
        source = doc.addObject("Part::Feature", "StockSolid")
        source.Label = Path(stock["file"]).name
        source.Shape = solid_shape(Path(stock["file"]), stock["scale"], stock["translate_mm"])
        if getattr(source, "ViewObject", None) is not None:
            source.ViewObject.Visibility = False
        new = compat.PathJob.createResourceClone(job, source, "Stock", "Stock")
    else:
        raise ValueError(f"stock type {stock['type']!r}: a box, a cylinder or a solid")
    old = job.Stock
    job.Stock = new
    if old is not None:
        doc.removeObject(old.Name)
    doc.recompute()


def solid_shape(path: Path, scale: float, translate: list) -> Any:
    """The solid of a STEP (read in mm) or STL file (its triangles sewn into a solid), scaled to mm and moved as
    the model is. ValueError: no solid in it."""
    import Part

    if path.suffix.lower() in (".step", ".stp"):
        shape = Part.read(str(path))
    else:
        import Mesh

        faces = Part.Shape()
        faces.makeShapeFromMesh(Mesh.Mesh(str(path)).Topology, MESH_TOLERANCE)
        shape = Part.Solid(Part.Shell(faces.Faces))
    if not shape.Solids:
        raise ValueError(f"stock.file {path.name}: no solid in it (a stock is a closed solid)")
    if scale != 1.0:
        m = FreeCAD.Matrix()
        m.scale(FreeCAD.Vector(scale, scale, scale))
        shape = shape.transformGeometry(m)
    shape.translate(FreeCAD.Vector(*translate))
    return shape
