"""The work of a TMM op estimated from its properties alone (bounding boxes, never a mesh or a tool path), by
the strategies' own `estimate_work` through core.limits: the panel runs it when a value is entered (with the
value not yet written, `overrides`), and `TmmOp.execute` runs it before the op loads or tessellates anything.
A value above the work limits raises the strategies' TmmError (what, how many, which parameters).

Also the ranges of the op's length and angle properties that name no params field (`EXTRA_SPECS`): the
panel's minimum and maximum for them, checked here like the params' own.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping, Optional

import FreeCAD

from tmm_workbench.app import geometry
from tmm_workbench.core import limits, polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, check, spec_of
from tmm_workbench.core.work import Work

# properties that name no params field: their allowed range (a length beyond 10 m is a typing slip)
EXTRA_SPECS: dict[str, Spec] = {
    "LinearDeflection": Spec("tessellation tolerance", "mm", low=0.001, high=10.0),
    "BoundaryMargin": Spec("boundary margin", "mm", low=-100_000.0, high=100_000.0),
    "AxisRetract": Spec("axis retract", "mm", low=0.0, high=1000.0),
    "FinalZ": Spec("final depth", "mm", low=-10_000.0, high=10_000.0),
    "TopZ": Spec("top", "mm", low=-10_000.0, high=10_000.0),
    "BottomZ": Spec("bottom", "mm", low=-10_000.0, high=10_000.0),
    "PlungeAngle": Spec("plunge angle", "deg", low=0.0, high=90.0),
    "SampleStep": Spec("sample step", "mm", low=0.0, high=1000.0, optional=True),  # waterline: 0 derives it
}
# compute seconds per counted unit on this project's reference machine (2 cores, loaded by other work: the upper
# of the runs that benchmarks/compute_estimate.py measured; a machine to itself computes up to ~2x faster)
PACE = {"surface": 2e-5, "adaptive": 7e-5, "surface_flat_cusp": 4e-5, "offset3d": 5e-4, "verify": 4e-6,
        "waterline": 2e-5, "roughing": 1.5e-5, "multipoint": 2.4e-3, "multipoint_scallop": 0.025,
        # a CC point's C-space and its rebuilds (seed 000's convex and concave finishes at 0.004 in: 0.022 and
        # 0.029 s per CC point cut, load 9), and the simulation of what the finish leaves (SimulateLeft: per cell
        # of its grid, and per mm cut over the cells under the tool; docs/mesh5.md "The op's estimate")
        "mesh5": 0.025, "mesh5_left_cells": 2e-6, "mesh5_left_cut": 8e-7}
TELL_COMPUTE_S = 5.0    # the panel's estimate names the compute time from here
LONG_COMPUTE_S = 30.0   # the op says so before it starts (console), with how to cancel
# a side of a range the params leave open, for the panel's minimum / maximum
OPEN_HIGH = {"mm": 10_000.0, "deg": 360.0, "%": 100.0}


PREFERENCES = "User parameter:BaseApp/Preferences/Mod/TMM"
# where a refusal sends the user (FreeCAD's parameter editor: TMM has no preference page)
PREFERENCES_WHERE = "the TMM preferences (Tools > Edit parameters..., BaseApp/Preferences/Mod/TMM)"
PREFERENCE_NAMES = {"max_points": "MaxPoints", "max_positions": "MaxPositions", "max_memory_bytes": "MaxMemoryGB"}


def apply_work_limits() -> None:
    """The user's work limits (FreeCAD preferences MaxPoints, MaxPositions, MaxMemoryGB under
    Preferences/Mod/TMM; 0 or absent: the core's defaults) for the next computation."""
    group = FreeCAD.ParamGet(PREFERENCES)
    points, positions = group.GetInt("MaxPoints", 0), group.GetInt("MaxPositions", 0)
    memory = group.GetFloat("MaxMemoryGB", 0.0)
    defaults = limits.WorkLimits()
    limits.name_settings(PREFERENCES_WHERE, PREFERENCE_NAMES)
    limits.set_limits(points if points > 0 else defaults.max_points,
                      memory if memory > 0 else defaults.max_memory_bytes / 1e9,
                      positions if positions > 0 else defaults.max_positions)


@dataclass(frozen=True)
class Estimate:
    count: float   # what the strategy estimates: CL points, tool positions, loop points...
    what: str
    passes: Optional[int] = None
    cut_length: Optional[float] = None   # mm of cutting moves, from the boxes and the spacing (not a path)
    feed: Optional[float] = None         # mm/s, the tool controller's horizontal feed
    note: str = ""                       # what the count leaves out (VerifyCusp's partial passes)
    compute_seconds: Optional[float] = None   # the count at the strategy's measured pace (PACE)
    work: Optional[Work] = None          # what it was told from (its climbs)
    vert_feed: Optional[float] = None    # mm/s, the tool controller's vertical feed
    plunge_deg: float = 45.0             # moves going down steeper than this are cut at vert_feed (the op's)

    @property
    def climbs(self) -> tuple[tuple[float, float], ...]:
        """The cut length by the slope the passes climb (core.work.Work.climbs; () when not told)."""
        return self.work.climbs if self.work is not None else ()

    @property
    def cutting_seconds(self) -> Optional[float]:
        """The cutting time the estimate implies (core.work.Work.cutting_seconds: cut length at the horizontal
        feed, the half of it that goes down slopes steeper than the plunge angle at the vertical feed); None
        without a feed."""
        if self.cut_length is None or not self.feed or self.feed <= 0:
            return None
        work = self.work or Work(self.count, self.what, cut_length=self.cut_length)
        return work.cutting_seconds(self.feed, self.vert_feed, self.plunge_deg)

    def text(self) -> str:
        from tmm_workbench.core.sim.cycle_time import hms

        passes = f", {self.passes} passes" if self.passes else ""
        t = self.cutting_seconds
        time = f", cutting about {hms(t)} at {self.feed * 60:.4g} mm/min" if t is not None else ""
        note = f" {self.note}" if self.note else ""
        c = self.compute_seconds
        compute = f"; computing about {hms(c)}" if c is not None and c >= TELL_COMPUTE_S else ""
        return f"about {self.count:.3g} {self.what}{passes}{time}{note}{compute}"

    @property
    def long(self) -> bool:
        """The computation will take longer than a user waits without being told (LONG_COMPUTE_S)."""
        return (self.compute_seconds or 0.0) > LONG_COMPUTE_S


def _field_spec(proxy: Any, prop: str) -> Optional[Spec]:
    for row in getattr(proxy, "PROPERTIES", ()):
        if row.name == prop and row.field and proxy.PARAMS is not None:
            return spec_of(proxy.PARAMS, row.field)
    return None


def spec_for(proxy: Any, prop: str) -> Optional[Spec]:
    """The allowed range of the op's property `prop`: its params field's Spec, else its stage's, else EXTRA_SPECS."""
    return _field_spec(proxy, prop) or getattr(proxy, "SPECS", {}).get(prop) or EXTRA_SPECS.get(prop)


def check_value(proxy: Any, prop: str, value: float) -> None:
    """TmmError naming the parameter, its value and its range when `value` does not fit (0 on an optional
    field means 'derive it', as the ops read it)."""
    spec = spec_for(proxy, prop)
    if spec is None or (spec.optional and value == 0):
        return
    if spec.integer and isinstance(value, float) and value.is_integer():   # a spin box's count read as a number
        value = int(value)
    check(spec, value)


def check_ranges(obj: Any, overrides: Optional[Mapping[str, float]] = None) -> None:
    """The op's properties that name no params field inside EXTRA_SPECS (a tessellation tolerance of 1e-6 mm
    would tessellate a Part model into more triangles than memory holds)."""
    ov = dict(overrides or {})
    for prop in {**EXTRA_SPECS, **getattr(obj.Proxy, "SPECS", {})}:
        if prop not in ov and hasattr(obj, prop) and _field_spec(obj.Proxy, prop) is None:
            check_value(obj.Proxy, prop, _value(obj, prop, ov))


def _value(obj: Any, prop: str, overrides: Mapping[str, float]) -> Any:
    if prop in overrides:
        return overrides[prop]
    v = getattr(obj, prop)
    return float(v.Value) if hasattr(v, "Value") else v


def _params(proxy: Any, obj: Any, overrides: Mapping[str, float], **extra: Any) -> Any:
    fields = {row.field: overrides[row.name] for row in proxy.PROPERTIES if row.field and row.name in overrides}
    return proxy.params_from(obj, **{**fields, **extra})


def _box(o: Any) -> Any:
    mesh = getattr(o, "Mesh", None)
    return mesh.BoundBox if mesh is not None and not hasattr(o, "Shape") else o.Shape.BoundBox


def model_bounds(proxy: Any, obj: Any, load_stl: bool) -> Optional[tuple[float, ...]]:
    """(xmin, ymin, zmin, xmax, ymax, zmax) of what the op machines, from bounding boxes (TMM's stand-in
    boxes have the mesh's); an STL file is read only with `load_stl` (else None)."""
    if getattr(obj, "StlFile", ""):
        return _stl_bounds(obj.StlFile) if load_stl else None
    models = [obj.Model] if getattr(obj, "Model", None) is not None else list(getattr(proxy, "model", None) or [])
    if not models:
        from tmm_workbench.app.compat import PathUtils

        job = PathUtils.findParentJob(obj)
        models = list(job.Model.Group) if job is not None else []
    if not models:
        raise TmmError("nothing to machine: set StlFile or Model, or give the Job a model")
    boxes = [_box(m) for m in models]
    return (min(b.XMin for b in boxes), min(b.YMin for b in boxes), min(b.ZMin for b in boxes),
            max(b.XMax for b in boxes), max(b.YMax for b in boxes), max(b.ZMax for b in boxes))


def _stl_bounds(path: str) -> tuple[float, ...]:
    """An STL file's bounds (min x, y, z, max x, y, z); app.geometry keeps the file's mesh (the panel asks on
    every value entered)."""
    lo, hi = geometry.mesh_from_stl(path).bounds  # a missing or bad file: its TmmError
    return (*map(float, lo), *map(float, hi))


def _stock(obj: Any) -> Any:
    from tmm_workbench.app.compat import PathUtils

    job = PathUtils.findParentJob(obj)
    stock = getattr(job, "Stock", None) if job is not None else None
    if stock is None or stock.Shape.isNull():
        raise TmmError("boundary 'Stock': the Job has no stock")
    return stock.Shape.BoundBox


def _cutter(obj: Any) -> Any:
    from tmm_workbench.app.tools import cutter_from_tool

    return cutter_from_tool(obj.ToolController.Tool)


def _feed(obj: Any, which: str = "HorizFeed") -> Optional[float]:
    """The tool controller's horizontal (or `which`) feed in mm/s (None without one: no time is told)."""
    tc = getattr(obj, "ToolController", None)
    feed = getattr(tc, which, None) if tc is not None else None
    value = float(getattr(feed, "Value", feed)) if feed is not None else 0.0
    return value if value > 0 else None


Inputs = Optional[tuple[Any, Any, tuple[float, ...]]]   # (params, cutter, bounds) of core.work; None: not known


def surface(proxy: Any, obj: Any, ov: Mapping[str, float], load_stl: bool) -> Inputs:
    """The Surface's params over its region (a sketch's or faces' polygons and their box; Rest is known only when
    it computes: the last run's, its region and rest (the loops over its slopes counted), else the box) or its
    boundary box (the stock's or the model's, with the margin), and a coarse sample
    of the model's heights when the model is at hand (core.query.height_sample: the passes and time told)."""
    from tmm_workbench.app import region_source
    from tmm_workbench.app.compat import PathUtils

    if obj.BoundaryShape == "Stock":
        bb = _stock(obj)
        box = (bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax, bb.ZMax)
    else:
        box = model_bounds(proxy, obj, load_stl)
        if box is None:
            return None
    m = _value(obj, "BoundaryMargin", ov)
    region = None
    kind = getattr(obj, "Region", region_source.BOX)
    rest = getattr(proxy, "rest", None) if kind == region_source.REST else None   # the last run's (app.rest_source)
    if rest is not None:   # its region, and its slopes' waterline loops counted
        region = rest.region
    elif kind not in (region_source.BOX, region_source.REST):
        region = region_source.region_of(obj, PathUtils.findParentJob(obj))
    boundary = (box[0] - m, box[1] - m, box[3] + m, box[4] + m) if region is None else polygons.bounds(region)
    params = _params(proxy, obj, ov, boundary=boundary, region=region)
    if rest is not None:
        params.rest = rest.stock
    cutter = _cutter(obj)
    mesh = _mesh_at_hand(proxy, obj, load_stl)
    if mesh is None:
        return params, cutter, box
    floor = float(mesh.bounds[0][2]) if params.floor_z is None else params.floor_z
    return params, cutter, box, _sample(mesh, cutter, params.boundary, floor)


def _mesh_at_hand(proxy: Any, obj: Any, load_stl: bool) -> Any:
    """The op's model as a mesh without tessellating anything: its last computation's, its STL file's (read
    anyway for the bounds when `load_stl`) or the Job's mesh models' (_model_meshes); None for a Part model not
    computed yet."""
    mesh = getattr(proxy, "mesh", None)
    if mesh is not None:
        return mesh
    if getattr(obj, "StlFile", ""):
        return geometry.mesh_from_stl(obj.StlFile) if load_stl else None
    return _model_meshes(obj)


_feature_mesh: dict[tuple, Any] = {}   # the last Mesh object read: (document, name, counts, box) -> its TriMesh


def _model_meshes(obj: Any) -> Any:
    """The op's Model or the Job's models when all are meshes (Mesh objects, or TMM's stand-ins for a Mesh object
    or an STL file), as one mesh; None when one is a Part model (tessellating it is the computation's work)."""
    from tmm_workbench.app import model_proxy
    from tmm_workbench.app.compat import PathUtils

    models = [obj.Model] if getattr(obj, "Model", None) is not None else []
    if not models:
        job = PathUtils.findParentJob(obj)
        models = list(job.Model.Group) if job is not None else []
    sources = [model_proxy.source_of(m) or m for m in models]
    if not sources or not all(isinstance(s, str) or (hasattr(s, "Mesh") and not hasattr(s, "Shape"))
                              for s in sources):
        return None
    meshes = [geometry.mesh_from_stl(s) if isinstance(s, str) else _mesh_feature(s) for s in sources]
    return meshes[0] if len(meshes) == 1 else geometry.combine(meshes)


def _mesh_feature(obj: Any) -> Any:
    """A Mesh object's TriMesh, kept while the object's mesh keeps its counts and box (the panel asks on every
    value entered, and _sample keeps its index for the same TriMesh)."""
    m = obj.Mesh
    bb = m.BoundBox
    key = (obj.Document.Name, obj.Name, m.CountPoints, m.CountFacets, bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax,
           bb.ZMax)
    if key not in _feature_mesh:
        _feature_mesh.clear()
        _feature_mesh[key] = geometry.mesh_from_mesh_feature(obj)
    return _feature_mesh[key]


_surface: list[Any] = []           # [mesh, its DropSurface]: the last model's index
_samples: dict[tuple, Any] = {}   # (cutter, boundary, floor) -> that model's sample


def _sample(mesh: Any, cutter: Any, boundary: tuple[float, ...], floor: float) -> Any:
    """The model's coarse height sample for this cutter over `boundary` (the panel asks on every value entered:
    the last few are kept with the model's index, and dropped with it when the model changes)."""
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.query.height_sample import sample_heights

    if not _surface or _surface[0] is not mesh:
        _surface[:] = [mesh, DropSurface(mesh)]
        _samples.clear()
    key = (cutter, tuple(round(v, 6) for v in boundary), round(floor, 6))   # a Cutter is equal by its values
    if key not in _samples:
        if len(_samples) >= 4:
            _samples.clear()
        _samples[key] = sample_heights(_surface[1], cutter, boundary, floor)
    return _samples[key]


def waterline(proxy: Any, obj: Any, ov: Mapping[str, float], load_stl: bool) -> Inputs:
    """Waterline's params: its boundary (the stock's box, or the model's grown by the tool radius, with the
    margin), the sample step (0: derived) and the Z range when it is used."""
    cutter = _cutter(obj)
    b = model_bounds(proxy, obj, load_stl)
    if b is None:
        return None
    if obj.BoundaryShape == "Stock":
        bb = _stock(obj)
        box = (bb.XMin, bb.YMin, bb.XMax, bb.YMax)
    else:
        r = cutter.radius
        box = (b[0] - r, b[1] - r, b[3] + r, b[4] + r)
    m = _value(obj, "BoundaryMargin", ov)
    sample = _value(obj, "SampleStep", ov)
    extra: dict[str, Any] = {"boundary": (box[0] - m, box[1] - m, box[2] + m, box[3] + m),
                             "sample_step": None if sample == 0 else sample}
    if obj.UseZRange:
        extra.update(top_z=_value(obj, "TopZ", ov), bottom_z=_value(obj, "BottomZ", ov))
    return _params(proxy, obj, ov, **extra), cutter, b


def roughing(proxy: Any, obj: Any, ov: Mapping[str, float], load_stl: bool) -> Inputs:
    """Roughing's params over the Job's stock solid (its box)."""
    from tmm_workbench.app.compat import PathUtils

    job = PathUtils.findParentJob(obj)
    stock = getattr(job, "Stock", None) if job is not None else None
    if stock is None or stock.Shape.isNull() or not stock.Shape.Solids:
        raise TmmError("the Job has no stock solid to rough from")
    final_z = _value(obj, "FinalZ", ov) if obj.UseFinalZ else None
    box = geometry.stock_box_of(stock)
    return _params(proxy, obj, ov, final_z=final_z, stock_box=box), _cutter(obj), box


def multipoint(proxy: Any, obj: Any, ov: Mapping[str, float], load_stl: bool) -> Inputs:
    """Multipoint's params over its face's box (None before a face is chosen: the op says so when it computes)."""
    if not obj.Base or not obj.Base[0][1]:
        return None
    base, subs = obj.Base[0]
    bb = base.Shape.getElement(subs[0]).BoundBox
    return _params(proxy, obj, ov), None, (bb.XMin, bb.YMin, bb.ZMin, bb.XMax, bb.YMax, bb.ZMax)


def mesh5(proxy: Any, obj: Any, ov: Mapping[str, float], load_stl: bool) -> Inputs:
    """5-axis mesh finishing's params over the model's box, with the op's tool assembly (its holder makes every
    C-space dearer), the model's needle sample when the model is at hand (its passes told from the tilted
    cutter's width over its slopes; else at most a quarter diameter apart), and the cells of the simulation of
    what the finish leaves (SimulateLeft)."""
    from tmm_workbench.app import tool_assembly
    from tmm_workbench.core.strategies.mesh5 import cleanup, estimate

    b = model_bounds(proxy, obj, load_stl)
    if b is None:
        return None
    mesh = _mesh_at_hand(proxy, obj, load_stl)
    sample = None
    if mesh is not None:   # kept on the op with its mesh: the panel asks on every value entered
        kept = getattr(proxy, "needle_sample", None)
        if kept is None or kept[0] is not mesh:
            kept = proxy.needle_sample = (mesh, estimate.surface_sample(mesh))
        sample = kept[1]
    left = cleanup.MAX_CELL if getattr(obj, "SimulateLeft", False) else None
    return _params(proxy, obj, ov, assembly=tool_assembly.assembly_of(obj)), _cutter(obj), b, sample, left


def of_work(work: Work, feed: Optional[float], vert_feed: Optional[float] = None, plunge_deg: float = 45.0) -> Estimate:
    """The panel's estimate of a strategy's work: its compute at the measured paces, its cutting time at `feed`
    (and `vert_feed` down slopes steeper than `plunge_deg`)."""
    seconds = sum(units * PACE[pace] for pace, units in work.paces)
    return Estimate(work.count, work.what, work.passes, work.cut_length, feed, work.note, compute_seconds=seconds,
                    work=work, vert_feed=vert_feed, plunge_deg=plunge_deg)


def estimate(obj: Any, overrides: Optional[Mapping[str, float]] = None, load_stl: bool = True) -> Optional[Estimate]:
    """The op's work with its properties (and `overrides`: property -> value in mm / deg / %), refused by a
    TmmError above the work limits (the user's preferences) or for a value out of its range; None when it
    cannot be told without reading the model (an STL file and not `load_stl`, no face yet)."""
    proxy = obj.Proxy
    ov = dict(overrides or {})
    for prop, value in ov.items():
        check_value(proxy, prop, value)
    check_ranges(obj, ov)
    inputs_of = getattr(type(proxy), "ESTIMATE", None)  # each op names how its strategy's inputs are told
    if inputs_of is None:
        return None
    apply_work_limits()
    inputs = inputs_of(proxy, obj, ov, load_stl)
    if inputs is None:
        return None
    plunge = _value(obj, "PlungeAngle", ov) if hasattr(obj, "PlungeAngle") else 45.0
    return of_work(type(proxy).STRATEGY.estimate_work(*inputs), _feed(obj), _feed(obj, "VertFeed"), plunge)
