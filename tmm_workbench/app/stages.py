"""An op derived from its stages' declarations (core.stage): the property table (Prop rows, FreeCAD property types
from the fields' kinds), the enumerations' choices, the defaults, the ranges of properties that name no params
field, the panel's widgets, and the API's arguments turned into property values (each checked by its own name,
the arguments a chosen mode would ignore refused)."""
from __future__ import annotations

import os

from typing import Any, Optional

from tmm_workbench.app.api_args import numbers, option
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, spec_of
from tmm_workbench.core.stage import NO_DEFAULT, Args, Field, Stage, fields_of, refuse_ignored

PROPERTY_TYPES = {"length": "App::PropertyDistance", "angle": "App::PropertyAngle", "float": "App::PropertyFloat",
                  "percent": "App::PropertyFloat", "int": "App::PropertyInteger", "bool": "App::PropertyBool",
                  "choice": "App::PropertyEnumeration", "vector": "App::PropertyVectorDistance",
                  "file": "App::PropertyFile", "link": "App::PropertyLink",
                  "sublinks": "App::PropertyLinkSubListGlobal", "text": "App::PropertyString"}
_SPIN_KINDS = ("length", "angle", "float", "int")
_UNITS = {"length": "mm", "angle": "deg", "percent": "%"}  # of a number with no range declared: finite


def properties(stages: tuple[Stage, ...]) -> list[Prop]:
    return [Prop(PROPERTY_TYPES[f.kind], f.prop, f.group, f.tip, f.field) for f in fields_of(stages)]


def choices(stages: tuple[Stage, ...]) -> dict[str, dict[str, Any]]:
    return {f.prop: dict(f.choices) for f in fields_of(stages) if f.choices is not None}


def defaults(stages: tuple[Stage, ...]) -> dict[str, Any]:
    """The defaults the stages give (properties whose params field gives theirs are not here)."""
    return {f.prop: f.default for f in fields_of(stages) if f.default is not NO_DEFAULT}


def restored(stages: tuple[Stage, ...]) -> dict[str, Any]:
    """What an older document that lacks a property gets when its default would change what it computed."""
    return {f.prop: f.restored for f in fields_of(stages) if f.restored is not NO_DEFAULT}


def specs(stages: tuple[Stage, ...]) -> dict[str, Spec]:
    """The ranges of the properties that name no params field."""
    return {f.prop: f.spec for f in fields_of(stages) if f.spec is not None}


def widgets(stages: tuple[Stage, ...]) -> tuple[dict[str, str], dict[str, str], dict[str, str]]:
    """The panel's (spin boxes, combo boxes, check boxes): widget name -> property."""
    spins, combos, checks = {}, {}, {}
    for f in fields_of(stages):
        if not f.widget:
            continue
        table = spins if f.kind in _SPIN_KINDS else combos if f.kind == "choice" else checks if f.kind == "bool" \
            else None
        if table is None:
            raise ValueError(f"field {f.prop}: a {f.kind} has no generic widget (its panel handles it)")
        table[f.widget] = f.prop
    return spins, combos, checks


def _value(f: Field, params_class: Optional[type], value: Any) -> Any:
    if f.kind == "choice":
        return option(f.api, value, f.api_choices())
    if f.kind in ("file", "text"):
        if not isinstance(value, (str, os.PathLike)):
            raise TmmError(f"{f.api} must be a path or text, got {value!r}")
        return str(value)
    if f.kind == "link":
        if not hasattr(value, "TypeId"):
            raise TmmError(f"{f.api} must be a FreeCAD object, got {value!r}")
        return value
    if f.kind == "bool":
        if not isinstance(value, bool):
            raise TmmError(f"{f.api} must be True or False, got {value!r}")
        return value
    spec = spec_of(params_class, f.field) if f.field and params_class is not None else f.spec
    numbers(**{f.api: (value, spec or Spec("", _UNITS.get(f.kind, "")))})
    return value


def api_values(stages: tuple[Stage, ...], params_class: Optional[type], args: Args, model: Any) -> dict[str, Any]:
    """The op's property values for an API call's `args` (None: the op's default): arguments a stage's chosen mode
    would ignore refused by name, each value checked by its argument's name, choices in the API's spelling."""
    values: dict[str, Any] = {}
    for f in fields_of(stages):  # each value in its range first: a bad number is named as such
        if f.api and args.get(f.api) is not None:
            values[f.prop] = _value(f, params_class, args[f.api])
    refuse_ignored(stages, args)
    for stage in stages:
        if stage.composite_values is not None:
            values.update(stage.composite_values(args, model))
    return values
