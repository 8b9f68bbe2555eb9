"""FreeCAD's tool library files read into the planner's tool list, without FreeCAD.

A library (`.fctl`, FreeCAD 0.20 to 1.1 alike) is JSON: `{"version": 1, "tools": [{"nr": 1, "path":
"6mm_Ball_End.fctb"}, ...]}` (1.x adds `"label"`). A relative `path` is looked for in the `Bit` folder beside the
library's folder (FreeCAD's layout: `Tools/Library/x.fctl`, `Tools/Bit/y.fctb`), then in the library's own folder;
0.20 may store it absolute. A ToolBit (`.fctb`, `"version": 2`): `name`, `shape` (the shape file, `ballend.fcstd`;
1.x adds `"shape-type": "Ballend"`), `parameter` (quantities as text, `"6.0000 mm"`, or numbers) and `attribute`.

Read: endmill -> flat, ballend -> ball, bullnose -> bull (its `CornerRadius`, or 0.20's `FlatRadius`, the flat
bottom's radius: corner = Diameter / 2 - FlatRadius, as app.tools reads a ToolBit), `Diameter`,
`CuttingEdgeHeight` (the flute length), `ShankDiameter`, `Length`, `Flutes` where the bit has it (else 2). A bit
of another shape (drill, v-bit, chamfer, probe, ...) is skipped and said in the report; a library or bit that
cannot be read is bad input.
"""
from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from tmm_workbench.core.errors import TmmError

SHAPES = {"endmill": "flat", "ballend": "ball", "bullnose": "bull"}   # FreeCAD's shape -> the planner's type
UNITS_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "um": 0.001, "in": 25.4, '"': 25.4, "inch": 25.4}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([a-zA-Z\"]*)\s*$")
SUFFIX = ".fctl"


class LibraryError(TmmError):
    """A tool library or one of its bits cannot be read (bad input)."""


def is_library(name: str) -> bool:
    return name.lower().endswith(SUFFIX)


def read_library(path: Path) -> tuple[list[dict], list[str]]:
    """The planner's tool list (job file tool entries: name, type, diameter, corner_radius for bull, flutes,
    flute_length, shank_diameter, length) of the library at `path`, in its tool numbers' order, and the notes on
    the bits skipped. LibraryError: the library or a bit is missing or unreadable."""
    data = _json(path, "tool library")
    if not isinstance(data, dict) or not isinstance(data.get("tools"), list):
        raise LibraryError(f"tool library {path}: not a FreeCAD tool library (a JSON object with a list 'tools' of "
                           f"{{nr, path}})")
    entries = []
    for i, e in enumerate(data["tools"]):
        if not isinstance(e, dict) or not isinstance(e.get("path"), str) or isinstance(e.get("nr"), bool) \
                or not isinstance(e.get("nr"), int):
            raise LibraryError(f"tool library {path.name}: tools[{i}] is {e!r}; each entry is {{\"nr\": a whole "
                               f"number, \"path\": the ToolBit file}}")
        entries.append((e["nr"], i, e["path"]))
    tools, skipped = [], []
    for nr, _, bit_path in sorted(entries):
        bit_file = find_bit(path, bit_path)
        tool = read_bit(bit_file)
        if isinstance(tool, str):
            skipped.append(f"T{nr} {bit_file.name}: {tool}")
            continue
        tools.append(dict(tool, name=f"T{nr} {tool['name']}"))
    return tools, skipped


def find_bit(library: Path, bit_path: str) -> Path:
    """The ToolBit file a library names: absolute as it is, else in the Bit folder beside the library's folder,
    then in the library's own folder."""
    given = Path(bit_path)
    places = [given] if given.is_absolute() else [library.parent.parent / "Bit" / given, library.parent / given]
    for p in places:
        if p.is_file():
            return p
    raise LibraryError(f"tool library {library.name}: the ToolBit {bit_path!r} is not there (looked in "
                       f"{', '.join(str(p.parent) for p in places)})")


def read_bit(path: Path) -> dict | str:
    """A ToolBit file as a job file tool entry, or the reason the planner cannot use it (its shape)."""
    data = _json(path, "ToolBit")
    if not isinstance(data, dict) or not isinstance(data.get("parameter"), dict):
        raise LibraryError(f"ToolBit {path}: not a FreeCAD ToolBit (a JSON object with 'shape' and 'parameter')")
    shape = Path(str(data.get("shape", ""))).name.lower()
    shape = shape[:-len(".fcstd")] if shape.endswith(".fcstd") else shape
    if shape not in SHAPES:
        return f"shape {shape or '(none)'!r}: the planner takes {', '.join(SHAPES)}"
    p = {**data.get("attribute", {}), **data["parameter"]} if isinstance(data.get("attribute"), dict) \
        else data["parameter"]
    where = f"ToolBit {path.name}"
    diameter = _mm(where, p, "Diameter")
    tool: dict[str, Any] = {"name": str(data.get("name") or path.stem), "type": SHAPES[shape],
                            "diameter": diameter, "flute_length": _mm(where, p, "CuttingEdgeHeight")}
    if shape == "bullnose":
        tool["corner_radius"] = _mm(where, p, "CornerRadius") if "CornerRadius" in p else \
            diameter / 2 - _mm(where, p, "FlatRadius")
    for key, name in (("shank_diameter", "ShankDiameter"), ("length", "Length")):
        if name in p:
            tool[key] = _mm(where, p, name)
    flutes = p.get("Flutes")
    if isinstance(flutes, (int, float)) and not isinstance(flutes, bool) and flutes != 0:   # 1.1's unset: 0
        tool["flutes"] = int(flutes) if flutes == int(flutes) else flutes   # a fraction: the job's check names it
    return tool


def _mm(where: str, params: dict, name: str) -> float:
    """A ToolBit length parameter in mm: a number (mm) or a quantity text ("6.0000 mm", "0.25 in")."""
    if name not in params:
        raise LibraryError(f"{where}: no {name}" + (" (a bull-nose bit needs CornerRadius or FlatRadius)"
                                                     if name == "FlatRadius" else ""))
    value = params[name]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    text = str(value)
    m = _QUANTITY.match(text if "." in text else text.replace(",", "."))   # 1.1 writes the user's UserString
    unit = m.group(2).lower() if m else ""
    if m is None or (unit and unit not in UNITS_MM):
        raise LibraryError(f"{where}: {name} is {value!r}; a length such as '6.0000 mm' (units "
                           f"{', '.join(u for u in UNITS_MM if u != chr(34))})")
    return float(m.group(1)) * UNITS_MM.get(unit, 1.0)


def _json(path: Path, what: str) -> Any:
    if not path.is_file():
        raise LibraryError(f"{what} not found: {path}")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise LibraryError(f"{what} {path}: not readable as JSON: {exc}") from None
