"""The planner's stock (docs/planner.md, `stock`): a box around the placed model (its margins), a cylinder with
its axis along Z through the centre of the model's XY bounds (its diameter and height from the model and the
margins, or given), or a solid (a STEP or STL file of the stock's shape, in the model file's frame). Its bounds
are checked against the machine's travels and the model against the stock: a model not inside it is bad input.
Without FreeCAD: a STEP stock is read through its tessellation (core.plan.launch). The FreeCAD Job gets the
matching stock (app.plan_stock.set_job_stock); its simulation and the roughing take the stock solid's top as
heights, so a cylinder's outside and the air over a solid's top are never cut."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.plan.job_file import UNITS, JobSpec, PlanInputError, is_step

INSIDE_MM = 1e-3   # a model point this close outside the stock's surface still counts as inside


@dataclass(frozen=True)
class PlannedStock:
    type: str                                     # box | cylinder | solid
    box: tuple                                    # its bounds (xmin, ymin, zmin, xmax, ymax, zmax) mm
    centre: Optional[tuple[float, float]] = None  # cylinder: its axis
    radius: Optional[float] = None                # cylinder
    file: Optional[Path] = None                   # solid: the file the Job's stock is made of
    scale: float = 1.0                            # solid: the file's units to mm (an STL in the model's units)
    translate: tuple = (0.0, 0.0, 0.0)            # solid: the model's move, applied to the stock too

    def describe(self) -> str:
        lo, hi = self.box[:3], self.box[3:]
        if self.type == "cylinder":
            return (f"cylinder D{2 * self.radius:g} x {hi[2] - lo[2]:g} mm, axis X{self.centre[0]:g} "
                    f"Y{self.centre[1]:g}")
        size = " x ".join(f"{b - a:g}" for a, b in zip(lo, hi))
        return f"solid {self.file.name}, {size} mm over all" if self.type == "solid" else f"box {size} mm"

    def as_dict(self) -> dict:
        """For the report and the FreeCAD side (app.plan_stock.set_job_stock)."""
        out: dict = {"type": self.type, "box_mm": [round(v, 4) for v in self.box], "describe": self.describe()}
        if self.type == "cylinder":
            out |= {"centre_mm": [round(v, 4) for v in self.centre], "radius_mm": round(self.radius, 4)}
        if self.type == "solid":
            out |= {"file": str(self.file), "scale": self.scale, "translate_mm": list(self.translate)}
        return out


def planned_stock(job: JobSpec, mesh: TriMesh) -> PlannedStock:
    """The stock of `job` around its placed model `mesh`, checked: the model inside it, it inside the travels."""
    s = job.stock
    if s.type == "cylinder":
        stock = _cylinder(job, mesh)
    elif s.type == "solid":
        stock = _solid(job, mesh)
    else:
        lo, hi = mesh.bounds
        stock = PlannedStock("box", _outward((float(lo[0]) - s.margin, float(lo[1]) - s.margin, float(lo[2]) - s.below),
                                             (float(hi[0]) + s.margin, float(hi[1]) + s.margin,
                                              float(hi[2]) + s.above)))
    _within_travels(job, mesh, stock)
    return stock


def stock_of_plan(job: JobSpec, box: tuple) -> PlannedStock:
    """The stock of `job` whose bounds `planned_stock` found as `box` (a plan's stock_box), without the model."""
    kind = job.stock.type
    if kind == "cylinder":
        return PlannedStock(kind, box, ((box[0] + box[3]) / 2, (box[1] + box[4]) / 2), (box[3] - box[0]) / 2)
    if kind == "solid":
        return PlannedStock(kind, box, file=job.stock.file, scale=_scale(job), translate=tuple(job.model.translate))
    return PlannedStock(kind, box)


def _scale(job: JobSpec) -> float:
    """A solid stock file's units to mm: a STEP is read in mm, an STL is in the model's units."""
    return 1.0 if is_step(job.stock.file) else UNITS[job.model.units]


def _outward(low: tuple, high: tuple) -> tuple:
    """Bounds rounded outward to 0.1 um: the stock holds the model (the roughing op refuses a model outside it)."""
    return tuple(math.floor(v * 1e4) / 1e4 for v in low) + tuple(math.ceil(v * 1e4) / 1e4 for v in high)


def _cylinder(job: JobSpec, mesh: TriMesh) -> PlannedStock:
    s = job.stock
    lo, hi = mesh.bounds
    centre = (round(float(lo[0] + hi[0]) / 2, 4), round(float(lo[1] + hi[1]) / 2, 4))
    reach = float(np.hypot(mesh.vertices[:, 0] - centre[0], mesh.vertices[:, 1] - centre[1]).max())
    radius = math.ceil((reach + s.margin) * 1e4) / 1e4 if s.diameter is None else s.diameter / 2
    if reach > radius + INSIDE_MM:
        far = mesh.vertices[int(np.argmax(np.hypot(mesh.vertices[:, 0] - centre[0],
                                                   mesh.vertices[:, 1] - centre[1])))]
        raise PlanInputError(f"stock.diameter: got {s.diameter:g}; at least {2 * reach:.4g} mm: the model is not "
                             f"inside the stock (it reaches {reach:.4g} mm from the stock's axis X{centre[0]:g} "
                             f"Y{centre[1]:g}, at X{far[0]:.4g} Y{far[1]:.4g})")
    bottom = float(lo[2]) - s.below
    top = float(hi[2]) + s.above if s.height is None else bottom + s.height
    if float(hi[2]) > top + INSIDE_MM:
        raise PlanInputError(f"stock.height: got {s.height:g}; at least {float(hi[2]) - bottom:.4g} mm: the model "
                             f"is not inside the stock (its top Z{float(hi[2]):.4g} above the stock's top "
                             f"Z{top:.4g}; the stock starts stock.below = {s.below:g} mm under the model)")
    box = _outward((centre[0] - radius, centre[1] - radius, bottom), (centre[0] + radius, centre[1] + radius, top))
    return PlannedStock("cylinder", box, centre, radius)


def stock_mesh(job: JobSpec) -> TriMesh:
    """A solid stock's mesh as placed (the model's units for an STL, its translate)."""
    s = job.stock
    scale = _scale(job)
    try:
        mesh = load_stl(s.mesh_file or s.file)
    except TmmError as exc:
        raise PlanInputError(f"stock.file: {exc}") from None
    if len(mesh.triangles) == 0:
        raise PlanInputError(f"stock.file: {s.file} has no triangles")
    vertices = mesh.vertices * scale + np.asarray(job.model.translate, dtype=float)
    return TriMesh(vertices, mesh.triangles, name=mesh.name)


def _solid(job: JobSpec, mesh: TriMesh) -> PlannedStock:
    """A solid stock: the model's points must lie under its top and over its lowest point (the planner cuts from
    above: the stock is what its top surface covers), and its surface must not cross the stock's but for the
    underside (boundary_crossings)."""
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.tools.cutter import Cutter

    solid = stock_mesh(job)
    lo, hi = solid.bounds
    floor = float(lo[2]) - 1.0
    v = mesh.vertices
    top = DropSurface(solid).drop(Cutter.flat(2 * INSIDE_MM), v[:, :2], floor)
    outside = (top <= floor + 0.5) | (v[:, 2] > top + INSIDE_MM) | (v[:, 2] < float(lo[2]) - INSIDE_MM)
    if outside.any():
        p = v[int(np.flatnonzero(outside)[0])]
        raise PlanInputError(f"stock.file: the model is not inside the stock {job.stock.file.name}: "
                             f"{int(outside.sum())} of its {len(v)} points lie outside it (the first at "
                             f"X{p[0]:.4g} Y{p[1]:.4g} Z{p[2]:.4g}); a solid stock must hold the whole model")
    crossing = boundary_crossings(mesh, solid)
    if crossing is not None:
        raise PlanInputError(f"stock.file: the model is not inside the stock {job.stock.file.name}: {crossing} (its "
                             "points lie inside it); a solid stock must hold the whole model")
    box = _outward(tuple(float(x) for x in lo), tuple(float(x) for x in hi))
    return stock_of_plan(job, box)


def _edges(mesh: TriMesh, keep: np.ndarray) -> np.ndarray:
    """(m, 2) vertex indices of the edges of the triangles in `keep` (each once)."""
    t = mesh.triangles[keep]
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0)


def _crossing(p0: np.ndarray, p1: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Which segments p0-p1 pass through which triangles abc (arrays broadcast, (m, 3)): from more than INSIDE_MM
    on one side of its plane to more than INSIDE_MM on the other, through its inside (a segment touching a face,
    lying in it or ending on it does not cross)."""
    n = np.cross(b - a, c - a)
    size = np.linalg.norm(n, axis=-1, keepdims=True)
    n = n / np.where(size > 1e-12, size, np.inf)
    d0, d1 = np.sum((p0 - a) * n, axis=-1), np.sum((p1 - a) * n, axis=-1)
    through = ((d0 < -INSIDE_MM) & (d1 > INSIDE_MM)) | ((d0 > INSIDE_MM) & (d1 < -INSIDE_MM))
    x = p0 + (d0 / np.where(through, d0 - d1, 1.0))[..., None] * (p1 - p0)
    inside = np.ones(through.shape, bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.sum(np.cross(v - u, x - u) * n, axis=-1) >= -1e-9
    return through & inside


def boundary_crossings(model: TriMesh, solid: TriMesh) -> Optional[str]:
    """Where the model's surface crosses the solid stock's (a model edge through a stock face, or a stock edge
    through a model face: a groove or pit in the stock's top between the model's points), None when nowhere. The
    stock's underside (faces facing down) is not checked: the planner cuts from above. Loops over the stock's
    faces and edges (a stock has few), each against all of the model's (culled by their boxes)."""
    up = solid.face_normals()[:, 2] > -1e-9
    mv, sv = model.vertices, solid.vertices
    me = _edges(model, np.ones(len(model.triangles), bool))
    e0, e1 = mv[me[:, 0]], mv[me[:, 1]]
    elo, ehi = np.minimum(e0, e1), np.maximum(e0, e1)
    for tri in solid.triangles[up]:
        a, b, c = sv[tri]
        near = np.all((elo <= np.maximum(np.maximum(a, b), c) + INSIDE_MM) &
                      (ehi >= np.minimum(np.minimum(a, b), c) - INSIDE_MM), axis=1)
        hit = np.flatnonzero(near)[_crossing(e0[near], e1[near], a, b, c)]
        if len(hit):
            p, q = e0[hit[0]], e1[hit[0]]
            return (f"{len(hit)} of its edges pass through the stock's surface (the first from X{p[0]:.4g} "
                    f"Y{p[1]:.4g} Z{p[2]:.4g} to X{q[0]:.4g} Y{q[1]:.4g} Z{q[2]:.4g})")
    corners = mv[model.triangles]
    tlo, thi = corners.min(axis=1), corners.max(axis=1)
    for i, j in _edges(solid, up):
        p, q = sv[i], sv[j]
        near = np.all((tlo <= np.maximum(p, q) + INSIDE_MM) & (thi >= np.minimum(p, q) - INSIDE_MM), axis=1)
        c = corners[near]
        if _crossing(p, q, c[:, 0], c[:, 1], c[:, 2]).any():
            return (f"the stock's edge from X{p[0]:.4g} Y{p[1]:.4g} Z{p[2]:.4g} to X{q[0]:.4g} Y{q[1]:.4g} "
                    f"Z{q[2]:.4g} passes through its faces")
    return None


def _within_travels(job: JobSpec, mesh: TriMesh, stock: PlannedStock) -> None:
    lo, hi = mesh.bounds
    for axis, a, b, travel, m in zip("xyz", stock.box[:3], stock.box[3:], job.machine.travels, hi - lo):
        if b - a > travel:
            raise PlanInputError(f"machine.travels: the stock ({stock.type}) is {b - a:.1f} mm in {axis} (the model "
                                 f"{float(m):.1f} mm), larger than the machine's {travel:g} mm travel")
