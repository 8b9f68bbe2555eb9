"""Tool holders: the library shipped with the add-on (resources/holders/holders.json, see docs/holders.md) and
a user's extension file of the same format.

A holder is a stack of coaxial cylinders and cones from its face (the end the tool sticks out of) upward, each
(height, diameter at its bottom, diameter at its top), and the range of shank diameters it clamps. The core
reads no FreeCAD setting: the app layer passes the user's file (by default holders.json in TMM's folder of
the FreeCAD user data folder). A user entry of a shipped name replaces the shipped entry.
"""
from __future__ import annotations

import difflib
import json
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Iterable, Optional, Union

from tmm_workbench.core.errors import TmmError

SHIPPED_FILE = Path(__file__).resolve().parents[3] / "resources" / "holders" / "holders.json"
USER_FILE_NAME = "holders.json"  # in <FreeCAD user data>/TMM/ (the app layer passes the path)
FORMAT = "tmm-holders 1"
KINDS = ("collet", "nut", "shrink-fit", "hydraulic", "side-lock", "milling-chuck")
_KEYS = {"name", "kind", "interface", "shank", "stack", "source", "note"}

Segment = tuple[float, float, float]  # (height, bottom diameter, top diameter) in mm


def length(what: str, v: object, positive: bool = True) -> float:
    """A finite length in mm: > 0 (or >= 0); TmmError naming `what` and the allowed range."""
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
            or (v <= 0 if positive else v < 0):
        raise TmmError(f"{what} must be a finite length {'> 0' if positive else '>= 0'} mm, got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Holder:
    name: str
    kind: str
    shank_min: float                 # the smallest shank diameter it clamps (mm)
    shank_max: float                 # the largest (its bore)
    stack: tuple[Segment, ...]       # from the face upward
    interface: str = ""              # the machine side (SK40, HSK63A, ...), "" for a spindle nut
    source: str = ""

    def __post_init__(self) -> None:
        who = f"holder '{self.name}'"
        if not isinstance(self.name, str) or not self.name.strip():
            raise TmmError(f"holder name must be a non-empty text, got {self.name!r}")
        if self.kind not in KINDS:
            raise TmmError(f"{who}: kind {self.kind!r} is not one of {', '.join(KINDS)}")
        lo = length(f"{who}: smallest shank diameter", self.shank_min)
        hi = length(f"{who}: largest shank diameter", self.shank_max)
        if lo > hi:
            raise TmmError(f"{who}: shank range {lo:g}-{hi:g} mm is empty (smallest above largest)")
        if not self.stack:
            raise TmmError(f"{who}: the stack needs at least one segment (height, bottom and top diameter)")
        stack = tuple(_segment(who, i, s) for i, s in enumerate(self.stack, 1))
        object.__setattr__(self, "stack", stack)
        if stack[0][1] <= hi:
            raise TmmError(f"{who}: its nose (diameter {stack[0][1]:g} mm at the face) must be wider than the "
                           f"largest shank it clamps ({hi:g} mm)")

    @property
    def length(self) -> float:
        """From the face to the top of the stack."""
        return sum(s[0] for s in self.stack)

    @property
    def nose_diameter(self) -> float:
        return self.stack[0][1]

    @property
    def max_diameter(self) -> float:
        return max(max(s[1], s[2]) for s in self.stack)

    def clamps(self, shank_diameter: float) -> bool:
        return self.shank_min - 1e-9 <= shank_diameter <= self.shank_max + 1e-9

    def bodies(self, z_face: float, clearance: float) -> list[tuple[float, float, float, float, float]]:
        """The stack as (z0, z1, r0, r1, clearance) frusta from `z_face` (the stick-out) upward."""
        out, z = [], z_face
        for h, d0, d1 in self.stack:
            out.append((z, z + h, d0 / 2, d1 / 2, clearance))
            z += h
        return out

    def describe(self) -> str:
        on = f" on {self.interface}" if self.interface else ""
        shank = f"{self.shank_min:g}" if self.shank_min == self.shank_max else \
            f"{self.shank_min:g}-{self.shank_max:g}"
        return f"{self.name} ({self.kind}{on}, shank {shank} mm, nose D{self.nose_diameter:g}, {self.length:g} mm long)"


def _segment(who: str, i: int, s: object) -> Segment:
    if not isinstance(s, (list, tuple)) or len(s) != 3:
        raise TmmError(f"{who}: stack segment {i} must be [height, bottom diameter, top diameter] in mm, got {s!r}")
    return (length(f"{who}: stack segment {i} height", s[0]),
            length(f"{who}: stack segment {i} bottom diameter", s[1]),
            length(f"{who}: stack segment {i} top diameter", s[2]))


def holder_from_entry(entry: Any) -> Holder:
    """A Holder from one entry of a holders file (a JSON object); TmmError naming the entry and the fault."""
    if not isinstance(entry, dict):
        raise TmmError(f"a holder entry must be an object with {', '.join(sorted(_KEYS))}, got {entry!r}")
    name = entry.get("name")
    who = f"holder '{name}'" if isinstance(name, str) else "a holder entry"
    unknown = sorted(set(entry) - _KEYS)
    if unknown:
        raise TmmError(f"{who}: unknown field(s) {', '.join(unknown)}; the fields are {', '.join(sorted(_KEYS))}")
    for key in ("name", "kind", "shank", "stack"):
        if key not in entry:
            raise TmmError(f"{who} has no '{key}'")
    shank = entry["shank"]
    if not isinstance(shank, list) or len(shank) != 2:
        raise TmmError(f"{who}: shank must be [smallest, largest] diameter in mm, got {shank!r}")
    stack = entry["stack"]
    if not isinstance(stack, list):
        raise TmmError(f"{who}: stack must be a list of [height, bottom diameter, top diameter], got {stack!r}")
    for key in ("interface", "source", "note"):
        if not isinstance(entry.get(key, ""), str):
            raise TmmError(f"{who}: {key} must be a text, got {entry[key]!r}")
    return Holder(name, entry["kind"], shank[0], shank[1], tuple(stack), entry.get("interface", ""),
                  entry.get("source", ""))


def read_holders(path: Union[str, Path]) -> list[Holder]:
    """Every holder of a holders file, validated; TmmError naming the file and the first fault."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise TmmError(f"holders file {path}: cannot be read ({exc.strerror or exc})") from exc
    except json.JSONDecodeError as exc:
        raise TmmError(f"holders file {path}: not valid JSON (line {exc.lineno}: {exc.msg})") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT or not isinstance(data.get("holders"), list):
        raise TmmError(f"holders file {path}: expected an object with \"format\": \"{FORMAT}\" and a "
                       "\"holders\" list (see docs/holders.md)")
    holders: list[Holder] = []
    seen: set[str] = set()
    for i, entry in enumerate(data["holders"], 1):
        try:
            h = holder_from_entry(entry)
        except TmmError as exc:
            raise TmmError(f"holders file {path}, entry {i}: {exc}") from exc
        if h.name.casefold() in seen:
            raise TmmError(f"holders file {path}, entry {i}: the name '{h.name}' is used twice")
        seen.add(h.name.casefold())
        holders.append(h)
    return holders


class HolderLibrary:
    """Holders by name: later sources replace earlier ones of the same name (case-insensitive)."""

    def __init__(self, holders: Iterable[Holder]) -> None:
        self._by_key: dict[str, Holder] = {}
        for h in holders:
            self._by_key[h.name.casefold()] = h

    def names(self) -> list[str]:
        return sorted((h.name for h in self._by_key.values()), key=str.casefold)

    def holder(self, name: str) -> Holder:
        """The holder named `name` (case-insensitive); TmmError with the close names otherwise."""
        found = self._by_key.get(str(name).strip().casefold())
        if found is not None:
            return found
        names = self.names()
        close = difflib.get_close_matches(str(name), names, n=4, cutoff=0.5) or difflib.get_close_matches(
            str(name).casefold(), [n.casefold() for n in names], n=4, cutoff=0.5)
        hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else \
            f"; the library holds {len(names)} holders (holders.names())"
        raise TmmError(f"unknown holder '{name}'{hint}")

    def __len__(self) -> int:
        return len(self._by_key)


@lru_cache(maxsize=1)
def shipped() -> tuple[Holder, ...]:
    return tuple(read_holders(SHIPPED_FILE))


def user_file_in(data_dir: Union[str, Path]) -> Path:
    """The user's extension file in a FreeCAD user data folder (the app layer passes that folder)."""
    return Path(data_dir) / "TMM" / USER_FILE_NAME


def library(user_file: Optional[Union[str, Path]] = None) -> HolderLibrary:
    """The shipped holders, extended (and overridden by name) by `user_file` when that file exists."""
    extra: list[Holder] = []
    if user_file is not None and Path(user_file).is_file():
        extra = read_holders(user_file)
    return HolderLibrary([*shipped(), *extra])


def holder(name: str, user_file: Optional[Union[str, Path]] = None) -> Holder:
    return library(user_file).holder(name)


def names(user_file: Optional[Union[str, Path]] = None) -> list[str]:
    return library(user_file).names()
