"""The planner's job description (docs/planner.md): a YAML or JSON file naming the model, the stock, the machine,
the tool library, the material, the finish and what to write. Read and checked here, without FreeCAD: every
field is known, every value in its range, or a PlanInputError names the field, the value and what is allowed.
Paths in the file are relative to the file's folder."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Union

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import MIN_CUSP
from tmm_workbench.core.plan import materials, tool_library

FORMAT = "tmm-plan 1"
UNITS = {"mm": 1.0, "inch": 25.4}
MODEL_SUFFIXES = (".stl", ".step", ".stp")
TOOL_TYPES = ("flat", "ball", "bull")
MACHINE_TYPES = ("3-axis", "tarus5")
TARUS = "tarus5"               # the Tarus head-head 5-axis mill (core.machine.tarus): its post, its C range
TARUS_POSTS = ("tarus",)
TARUS_TILT_MAX = 45.0          # deg: the Tarus's C range (0..45), the 5-axis op's largest tilt from the normal
NO_TRAVELS = (1e4, 1e4, 1e4)   # a tarus5 machine without travels: the post checks its joints
FIVE_AXIS = ("auto", "always", "never")   # planner.five_axis: 5-axis finishing where it pays, always, never
STOCK_TYPES = ("box", "cylinder", "solid")
STOCK_FIELDS = {"box": ("margin", "above", "below"), "cylinder": ("margin", "diameter", "above", "height", "below"),
                "solid": ("file",)}
SHARED = "shared:"   # model.file prefix: a file of the project's shared folder
POSTS = ("linuxcnc", "grbl", "tmm_linuxcnc", "tmm_grbl")


class PlanInputError(TmmError):
    """Bad input to the planner: the command exits with code 2."""


@dataclass(frozen=True)
class ModelSpec:
    file: Path
    units: str = "mm"
    translate: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class StockSpec:
    type: str = "box"        # box | cylinder (axis Z) | solid (a STEP or STL file)
    margin: float = 2.0      # mm beyond the model on each side (a cylinder: beyond its farthest point from the axis)
    above: float = 1.0       # mm above its top
    below: float = 0.0       # mm below its lowest point
    diameter: Optional[float] = None   # cylinder: given in place of the margin
    height: Optional[float] = None     # cylinder: given in place of `above` (from the model's lowest point - below)
    file: Optional[Path] = None        # solid: the stock's shape, in the model file's frame (its units, translate)
    mesh_file: Optional[Path] = None   # solid from a STEP: its tessellation (core.plan.launch), what the core reads


@dataclass(frozen=True)
class MachineSpec:
    type: str = "3-axis"
    post: str = "linuxcnc"
    travels: tuple[float, float, float] = (300.0, 300.0, 100.0)
    spindle_max: float = 24000.0   # rpm
    feed_max: float = 5000.0       # mm/min
    rapid: Optional[tuple[float, float]] = None   # mm/min in X and Y, in Z (None: the cycle estimate's default)
    tilt_limit: float = TARUS_TILT_MAX   # tarus5: the 5-axis op's largest tool tilt from the surface normal, deg

    @property
    def five_axis(self) -> bool:
        return self.type == TARUS


@dataclass(frozen=True)
class ToolSpec:
    name: str
    type: str
    diameter: float
    corner_radius: float
    flutes: int
    flute_length: float
    holder: Optional[str] = None
    stick_out: Optional[float] = None
    shank_diameter: Optional[float] = None   # the ToolBit's (None: the cutting diameter)
    length: Optional[float] = None           # the ToolBit's overall length (None: the planner's proportions)

    def describe(self) -> str:
        shape = {"flat": "flat", "ball": "ball", "bull": f"bull-nose r{self.corner_radius:g}"}[self.type]
        return f"{self.name} ({shape} D{self.diameter:g}, {self.flutes} flutes)"


@dataclass(frozen=True)
class FinishSpec:
    cusp: float = 0.01        # mm, the scallop height the finishing passes aim at
    tolerance: float = 0.01   # mm, the deepest cut below the model the verification accepts


@dataclass(frozen=True)
class OutputSpec:
    dir: Path
    name: str
    gcode: bool = True
    fcstd: bool = True
    heat_map: bool = True
    apt_cl: bool = False     # the whole Job through the APT CL post too (<name>.apt)


@dataclass(frozen=True)
class PlannerSpec:
    """Resolution of the planner's own measurements (coarser: faster, rougher)."""
    analysis_cell: float = 0.5     # mm, the reach tests' and slope map's grid
    sim_cell: float = 0.2          # mm, the verification's simulation grid
    compare_cutters: bool = True   # seed 003's cutter comparison for the finishing tool
    five_axis: str = "auto"        # tarus5: 5-axis finishing where it pays (core.plan.five_axis), always, never


@dataclass(frozen=True)
class JobSpec:
    source: Path
    model: ModelSpec
    stock: StockSpec
    machine: MachineSpec
    tools: tuple[ToolSpec, ...]
    material: str
    finish: FinishSpec
    outputs: OutputSpec
    planner: PlannerSpec = field(default_factory=PlannerSpec)
    notes: tuple[str, ...] = ()   # what reading the job left out (a library's bits of shapes the planner cannot use)


# --- field checks -------------------------------------------------------------------------------------------

def _fail(where: str, value: Any, allowed: str) -> PlanInputError:
    return PlanInputError(f"{where}: got {value!r}; {allowed}")


def _mapping(where: str, value: Any, required: tuple[str, ...], optional: tuple[str, ...]) -> dict:
    if not isinstance(value, dict):
        raise _fail(where, value, f"a mapping with {', '.join(required + optional)}")
    unknown = sorted(str(k) for k in value if k not in required + optional)
    if unknown:
        raise PlanInputError(f"{where}: unknown field(s) {', '.join(unknown)}; allowed: "
                             f"{', '.join(required + optional)}")
    missing = [k for k in required if k not in value]
    if missing:
        raise PlanInputError(f"{where}: missing field(s) {', '.join(missing)}")
    return value


def _number(where: str, value: Any, low: float, high: float, low_open: bool = False) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) \
        and (value > low if low_open else value >= low) and value <= high
    if not ok:
        raise _fail(where, value, f"a number in {'(' if low_open else '['}{low:g}, {high:g}]")
    return float(value)


def _choice(where: str, value: Any, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise _fail(where, value, f"one of {', '.join(allowed)}")
    return str(value)


def _flag(where: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise _fail(where, value, "true or false")
    return value


def _vector(where: str, value: Any, low: float, high: float, low_open: bool = False) -> tuple[float, float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise _fail(where, value, "a list of three numbers [x, y, z]")
    return tuple(_number(f"{where}[{i}]", v, low, high, low_open) for i, v in enumerate(value))  # type: ignore


def _text(where: str, value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise _fail(where, value, "a non-empty text")
    return value


# --- the sections -------------------------------------------------------------------------------------------

def _model(d: Any, base: Path) -> ModelSpec:
    d = _mapping("model", d, ("file",), ("units", "translate"))
    path = _model_path(_text("model.file", d["file"]), base)
    if path.suffix.lower() not in MODEL_SUFFIXES:
        raise _fail("model.file", d["file"], "an STL (.stl) or STEP (.step, .stp) file; FreeCAD objects: TMM Auto")
    if not path.is_file():
        raise _fail("model.file", d["file"], f"an existing model file (looked for {path})")
    units = _choice("model.units", d.get("units", "mm"), tuple(UNITS))
    if is_step(path) and units != "mm":
        raise _fail("model.units", units, "mm for a STEP file (it carries its own units: FreeCAD reads it in mm)")
    return ModelSpec(path, units, _vector("model.translate", d.get("translate", [0, 0, 0]), -1e4, 1e4))


def is_step(path: Path) -> bool:
    """A STEP model: FreeCAD tessellates it before the core sees it (core.plan.launch)."""
    return path.suffix.lower() in (".step", ".stp")


def _model_path(text: str, base: Path, where: str = "model.file") -> Path:
    """`shared:<path>`: under the project's shared folder (core.shared_data); otherwise relative to the job file."""
    if text.startswith(SHARED):
        from tmm_workbench.core.shared_data import shared_dir

        try:
            return (shared_dir() / text[len(SHARED):]).resolve()
        except TmmError as exc:
            raise _fail(where, text, str(exc)) from None
    return (base / text).resolve()


def _stock(d: Any, base: Path) -> StockSpec:
    if not isinstance(d, dict):
        raise _fail("stock", d, "a mapping: type (box, cylinder, solid) and its fields")
    kind = _choice("stock.type", d.get("type", "box"), STOCK_TYPES)
    d = _mapping(f"stock (type {kind})", d, (), ("type",) + STOCK_FIELDS[kind])
    if kind == "solid":
        if "file" not in d:
            raise PlanInputError("stock.file: missing; a solid stock is a STEP (.step, .stp) or STL (.stl) file")
        path = _model_path(_text("stock.file", d["file"]), base, "stock.file")
        if path.suffix.lower() not in MODEL_SUFFIXES or not path.is_file():
            raise _fail("stock.file", d["file"], f"an existing STEP (.step, .stp) or STL (.stl) file (looked for "
                        f"{path})")
        return StockSpec(kind, file=path)
    for given, instead in (("diameter", "margin"), ("height", "above")):
        if given in d and instead in d:
            raise _fail(f"stock.{given}", d[given], f"either stock.{given} or stock.{instead}, not both")
    sizes = {k: _number(f"stock.{k}", d[k], 0.0, 1e4, low_open=True) for k in ("diameter", "height") if k in d}
    return StockSpec(kind, *(_number(f"stock.{k}", d.get(k, v), 0.0, 1000.0)
                             for k, v in (("margin", 2.0), ("above", 1.0), ("below", 0.0))), **sizes)


def _machine(d: Any) -> MachineSpec:
    if d == "tarus":   # the shorthand: the Tarus with its post, C range and no travels given
        d = {"type": TARUS}
    if not isinstance(d, dict):
        raise _fail("machine", d, "a mapping (type, post, travels, ...) or 'tarus' (the Tarus 5-axis mill)")
    kind = _choice("machine.type", d.get("type", "3-axis"), MACHINE_TYPES)
    five = kind == TARUS
    d = _mapping(f"machine (type {kind})", d, () if five else ("post", "travels"),
                 ("type", "post", "travels", "spindle_max", "feed_max", "rapid") + (("tilt_limit",) if five else ()))
    rapid = d.get("rapid")
    if rapid is not None:
        if not isinstance(rapid, (list, tuple)) or len(rapid) != 2:
            raise _fail("machine.rapid", rapid, "a list of two rates [xy, z] in mm/min")
        rapid = tuple(_number(f"machine.rapid[{i}]", v, 1.0, 1e6) for i, v in enumerate(rapid))
    if five:
        post = _choice("machine.post", d.get("post", TARUS_POSTS[0]), TARUS_POSTS)
    elif d["post"] in TARUS_POSTS:
        raise _fail("machine.post", d["post"], f"one of {', '.join(POSTS)} for a 3-axis machine (the tarus post "
                    f"is the Tarus's: machine.type {TARUS})")
    else:
        post = _choice("machine.post", d["post"], POSTS)
    travels = _vector("machine.travels", d["travels"], 0.0, 1e4, low_open=True) if "travels" in d else NO_TRAVELS
    return MachineSpec(kind, post, travels,
                       _number("machine.spindle_max", d.get("spindle_max", 24000.0), materials.MIN_RPM, 1e5),
                       _number("machine.feed_max", d.get("feed_max", 5000.0), 1.0, 1e5), rapid,
                       _number("machine.tilt_limit", d.get("tilt_limit", TARUS_TILT_MAX), 0.0, TARUS_TILT_MAX,
                               low_open=True))


def _tool(i: int, d: Any) -> ToolSpec:
    where = f"tools[{i}]"
    d = _mapping(where, d, ("type", "diameter", "flute_length"),
                 ("name", "corner_radius", "flutes", "holder", "stick_out", "shank_diameter", "length"))
    kind = _choice(f"{where}.type", d["type"], TOOL_TYPES)
    dia = _number(f"{where}.diameter", d["diameter"], 0.0, 100.0, low_open=True)
    if kind == "bull":
        if "corner_radius" not in d:
            raise PlanInputError(f"{where}.corner_radius: missing; a bull-nose tool needs its corner radius")
        corner = _number(f"{where}.corner_radius", d["corner_radius"], 0.0, dia / 2, low_open=True)
    elif "corner_radius" in d:  # a flat or ball tool's corner is its shape's: a value here would be ignored
        raise _fail(f"{where}.corner_radius", d["corner_radius"], f"only for type bull (a {kind} tool's corner "
                    f"is {'0' if kind == 'flat' else 'its radius'})")
    else:
        corner = 0.0 if kind == "flat" else dia / 2
    flutes = d.get("flutes", 2)
    if isinstance(flutes, bool) or not isinstance(flutes, int) or not 1 <= flutes <= 12:
        raise _fail(f"{where}.flutes", flutes, "a whole number in [1, 12]")
    length = _number(f"{where}.flute_length", d["flute_length"], 0.0, 500.0, low_open=True)
    holder, stick_out = d.get("holder"), d.get("stick_out")
    if holder is not None:
        holder = _holder(f"{where}.holder", holder, dia)
    if stick_out is not None:
        if holder is None:
            raise _fail(f"{where}.stick_out", stick_out, "given with a holder only (it is measured from the "
                        "holder's face)")
        stick_out = _number(f"{where}.stick_out", stick_out, length, 1000.0)
    name = _text(f"{where}.name", d.get("name", f"T{i + 1}"))
    shank = None if d.get("shank_diameter") is None else \
        _number(f"{where}.shank_diameter", d["shank_diameter"], 0.0, 100.0, low_open=True)
    overall = None if d.get("length") is None else \
        _number(f"{where}.length", d["length"], max(length, stick_out or 0.0), 1000.0, low_open=stick_out is not None)
    return ToolSpec(name, kind, dia, corner, flutes, length, holder, stick_out, shank, overall)


def _library_tool(i: int, d: Any, given: Any) -> ToolSpec:
    """tools[i] of the job file, or of the library file `given` names (its bad values named with the file)."""
    if not isinstance(given, str):
        return _tool(i, d)
    try:
        return _tool(i, d)
    except PlanInputError as exc:
        raise PlanInputError(f"tools: {given}, {d.get('name', '')}: {exc}") from None


def _holder(where: str, name: Any, shank: float) -> str:
    from tmm_workbench.core.tools import holders

    known = holders.names()
    if name not in known:
        raise _fail(where, name, f"a holder of TMM's library: {', '.join(known)}")
    h = holders.holder(name)
    if not h.shank_min <= shank <= h.shank_max:
        raise _fail(where, name, f"a holder clamping a {shank:g} mm shank ({name} takes {h.shank_min:g}-"
                    f"{h.shank_max:g} mm)")
    return name


def _finish(d: Any) -> FinishSpec:
    d = _mapping("finish", d, ("cusp",), ("tolerance",))
    return FinishSpec(_number("finish.cusp", d["cusp"], MIN_CUSP, 5.0),
                      _number("finish.tolerance", d.get("tolerance", 0.01), MIN_CUSP, 5.0))


def _outputs(d: Any, base: Path, default_name: str) -> OutputSpec:
    d = _mapping("outputs", d, ("dir",), ("name", "gcode", "fcstd", "heat_map", "apt_cl"))
    name = _text("outputs.name", d.get("name", default_name))
    if any(c in name for c in "/\\") or name.startswith("."):
        raise _fail("outputs.name", name, "a file name without folders (the files are <dir>/<name>.*)")
    return OutputSpec((base / _text("outputs.dir", d["dir"])).resolve(), name,
                      *(_flag(f"outputs.{k}", d.get(k, True)) for k in ("gcode", "fcstd", "heat_map")),
                      _flag("outputs.apt_cl", d.get("apt_cl", False)))


def _planner(d: Any, machine: MachineSpec) -> PlannerSpec:
    d = _mapping("planner", d, (), ("analysis_cell", "sim_cell", "compare_cutters", "five_axis"))
    five = _choice("planner.five_axis", d.get("five_axis", "auto"), FIVE_AXIS)
    if five == "always" and not machine.five_axis:
        raise _fail("planner.five_axis", five, f"auto or never on a 3-axis machine (5-axis finishing needs "
                    f"machine.type {TARUS})")
    return PlannerSpec(_number("planner.analysis_cell", d.get("analysis_cell", 0.5), 0.05, 5.0),
                       _number("planner.sim_cell", d.get("sim_cell", 0.2), 0.02, 5.0),
                       _flag("planner.compare_cutters", d.get("compare_cutters", True)), five)


TOP_FIELDS = ("format", "model", "stock", "machine", "tools", "holders", "material", "finish", "outputs", "planner")


def job_from_dict(data: Any, source: Union[str, Path]) -> JobSpec:
    """The checked job of a parsed file `source` (its folder resolves relative paths)."""
    source = Path(source).resolve()
    base = source.parent
    data = _mapping("job file", data, ("format", "model", "machine", "tools", "material", "finish", "outputs"),
                    ("stock", "holders", "planner"))
    if data["format"] != FORMAT:
        raise _fail("format", data["format"], f"'{FORMAT}'")
    tools, notes = data["tools"], ()
    if isinstance(tools, str):   # a library file shared by several jobs: TMM's or FreeCAD's
        tools, notes = _library_file(base / tools)
    if not isinstance(tools, list) or not tools:
        raise _fail("tools", tools, "a non-empty list of tools (type, diameter, flute_length, ...) or the name "
                    "of a YAML / JSON file holding one")
    tools = _held(tools, data.get("holders", {}))
    library = tuple(_library_tool(i, t, data["tools"]) for i, t in enumerate(tools))
    names = [t.name for t in library]
    for i, n in enumerate(names):
        if names.index(n) != i:
            raise _fail(f"tools[{i}].name", n, "a name no other tool has")
    material = _choice("material", data["material"], tuple(materials.names()))
    model = _model(data["model"], base)
    machine = _machine(data["machine"])
    return JobSpec(source, model, _stock(data.get("stock", {}), base), machine, library,
                   material, _finish(data["finish"]), _outputs(data["outputs"], base, model.file.stem),
                   _planner(data.get("planner", {}), machine), notes)


def _held(tools: list, holders: Any) -> list:
    """The tools with the job's `holders` (tool name, or its number T<nr>, -> {holder, stick_out}) given to them:
    a FreeCAD library's bits have no holder (a .fctb holds none); checked with the tool as its own fields."""
    if not isinstance(holders, dict):
        raise _fail("holders", holders, "a mapping of tool names (or numbers, T3) to {holder, stick_out}")
    out = [dict(t) if isinstance(t, dict) else t for t in tools]
    for key, given in holders.items():
        where = f"holders[{key!r}]"
        given = _mapping(where, given, ("holder",), ("stick_out",))
        names = [str(t.get("name", f"T{i + 1}")) if isinstance(t, dict) else "" for i, t in enumerate(out)]
        hits = [i for i, n in enumerate(names) if n == key] or \
            [i for i, n in enumerate(names) if isinstance(key, str) and n.split(" ")[0] == key]
        if len(hits) != 1:
            raise _fail("holders", key, f"the name (or number) of one library tool: {', '.join(names)}")
        tool = out[hits[0]]
        if "holder" in tool:
            raise _fail(where, given, f"no second holder: the tool {names[hits[0]]} has its own ({tool['holder']})")
        tool.update(given)
    return out


def _parsed(p: Path, what: str) -> Any:
    """The YAML or JSON data of file `p` (by its suffix); PlanInputError naming `what` when it cannot be read."""
    if not p.is_file():
        raise PlanInputError(f"{what} not found: {p}")
    text = p.read_text(encoding="utf-8")
    suffix = p.suffix.lower()
    if suffix not in (".json", ".yaml", ".yml"):
        raise PlanInputError(f"{what} {p.name}: the name must end in .yaml, .yml or .json" +
                             (" (or .fctl: a FreeCAD tool library)" if what == "tools file" else ""))
    try:
        if suffix == ".json":
            return json.loads(text)
        import yaml

        return yaml.safe_load(text)
    except Exception as exc:  # noqa: BLE001 - json's ValueError, yaml.YAMLError (no common base)
        raise PlanInputError(f"{what} {p}: not readable as {'JSON' if suffix == '.json' else 'YAML'}: "
                             f"{exc}") from None


def _library_file(p: Path) -> tuple[Any, tuple[str, ...]]:
    """The tools of a TMM tools file (YAML / JSON) or a FreeCAD tool library (.fctl: core.plan.tool_library), and
    the notes on the library's bits left out."""
    if tool_library.is_library(p.name):
        try:
            tools, skipped = tool_library.read_library(p)
        except tool_library.LibraryError as exc:
            raise PlanInputError(f"tools: {exc}") from None
        if not tools:
            raise _fail("tools", p.name, "a library holding an end mill, ball or bull-nose bit (the planner "
                        "takes those): " + "; ".join(skipped))
        return tools, tuple(f"tool library {p.name}: left out {s}" for s in skipped)
    data = _parsed(p, "tools file")
    if isinstance(data, dict) and set(data) == {"tools"}:
        return data["tools"], ()
    raise _fail(f"tools file {p.name}", data if not isinstance(data, dict) else sorted(data),
                "a mapping with one field, tools: the list of tools")


def read_data(path: Union[str, Path]) -> Any:
    """The data of the job file at `path` (.yaml / .yml / .json), not checked yet."""
    return _parsed(Path(path), "job file")


def read_job(path: Union[str, Path]) -> JobSpec:
    """The job file at `path` (.yaml / .yml / .json), checked."""
    return job_from_dict(read_data(path), Path(path))
