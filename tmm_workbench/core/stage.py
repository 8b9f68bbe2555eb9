"""What a stage of a strategy declares, in one place: the op properties it reads, each with the params field it
sets, the API argument that gives it, its choices, default, allowed range and panel widget; the API arguments its
chosen mode would ignore; and how arguments that set several properties become their values. The op's property
table, the panel's ranges and widgets, and the API's argument translation are derived from a list of stages
(app.stages), so a new pattern or stage is its module, its tests and a row in its panel's form.

Plain data: no FreeCAD here. A field's `kind` names what it holds (app.stages maps it onto a FreeCAD property
type): length, angle, float, percent, int, bool, choice, vector, file, link, sublinks, text.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping, Optional

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec

KINDS = ("length", "angle", "float", "percent", "int", "bool", "choice", "vector", "file", "link", "sublinks", "text")
NO_DEFAULT = object()  # the property's default comes from its params field (or FreeCAD's own)

Args = Mapping[str, Any]     # an API call's arguments by name (None: not given)


@dataclass(frozen=True)
class Field:
    """One op property of a stage."""
    prop: str                                  # its name in the property editor ("StepOver")
    kind: str                                  # see KINDS
    group: str                                 # the property editor's group
    tip: str                                   # what it does, in the user's words
    field: str = ""                            # the params dataclass field it sets ("" for none)
    api: str = ""                              # the API argument that gives it ("" for none)
    choices: Optional[Mapping[str, Any]] = None  # kind choice: property value -> core value
    api_names: Optional[Mapping[str, str]] = None  # the API's spelling -> property value (default: lower case)
    default: Any = NO_DEFAULT                  # when no params field holds it
    spec: Optional[Spec] = None                # its range when no params field holds it
    widget: str = ""                           # the panel's widget for it ("" for none)
    restored: Any = NO_DEFAULT                 # what an older document without it gets (what it computed then)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"field {self.prop}: kind {self.kind!r} is not one of {', '.join(KINDS)}")
        if (self.kind == "choice") != (self.choices is not None):
            raise ValueError(f"field {self.prop}: choices go with kind 'choice' only")

    def api_choices(self) -> dict[str, str]:
        """The API's spelling (lower case) -> the property value."""
        if self.api_names is not None:
            return dict(self.api_names)
        return {str(p).lower(): p for p in (self.choices or {})}


@dataclass(frozen=True)
class Stage:
    """A stage's declaration (see the module)."""
    name: str
    fields: tuple[Field, ...]
    # the message naming an API argument this stage's chosen mode would ignore, given all of the call's arguments
    ignored: Optional[Callable[[Args], Optional[str]]] = None
    # API arguments that set several properties (a range, a point with its switch): their names, and the property
    # values for them (all of the call's arguments and its model given; each checked by its own name)
    composite: tuple[str, ...] = ()
    composite_values: Optional[Callable[[Args, Any], dict[str, Any]]] = None


def fields_of(stages: tuple[Stage, ...]) -> list[Field]:
    out: list[Field] = []
    seen: set[str] = set()
    for stage in stages:
        for f in stage.fields:
            if f.prop in seen:
                raise ValueError(f"property {f.prop} is declared by two stages")
            seen.add(f.prop)
            out.append(f)
    return out


def api_names(stages: tuple[Stage, ...]) -> set[str]:
    """Every API argument the stages take."""
    return {f.api for f in fields_of(stages) if f.api} | {n for s in stages for n in s.composite}


def refuse_ignored(stages: tuple[Stage, ...], args: Args) -> None:
    """TmmError naming the first argument a stage's chosen mode would ignore."""
    for stage in stages:
        message = stage.ignored(args) if stage.ignored is not None else None
        if message:
            raise TmmError(message)
