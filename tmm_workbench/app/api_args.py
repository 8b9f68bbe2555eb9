"""What the headless API does to its callers' arguments before checking them: numpy scalars become Python
numbers (FreeCAD's properties and the core's checks take float and int, a macro often passes np.float32),
and a progress callback's answer must be a bool (a string such as "stop" is truthy: taken as "go on")."""
from __future__ import annotations

import functools
from dataclasses import replace
from typing import Any, Callable, Optional, Sequence

import numpy as np

from tmm_workbench.app import progress as progress_mod
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.params import Spec, check


LENGTH = Spec("", "mm")
POSITIVE = Spec("", "mm", low=0, low_open=True, kind="length")
NON_NEGATIVE = Spec("", "mm", low=0, kind="length")
FEED = Spec("", "mm/min", low=0, low_open=True)
SPEED = Spec("", "rpm", low=0)


def _plain(value: Any) -> Any:
    if isinstance(value, np.generic) and np.ndim(value) == 0:
        return value.item()  # np.float32(6) -> 6.0, np.int64(3) -> 3, np.bool_ -> bool
    return value


def plain_numbers(function: Callable[..., Any]) -> Callable[..., Any]:
    """`function` called with its numpy scalar arguments turned into Python numbers."""
    @functools.wraps(function)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        return function(*(_plain(a) for a in args), **{k: _plain(v) for k, v in kwargs.items()})
    return wrapper


class CallbackProgress(progress_mod.ProgressReporter):
    """The caller's `progress(fraction) -> bool` as a reporter: never shown a fraction below one it was
    already shown (phases that restart their own count are held at the highest seen), and its answer must
    be True or False."""

    def __init__(self, callback: Callable[[float], Any]) -> None:
        self.callback, self.shown = callback, 0.0

    def __call__(self, fraction: float) -> bool:
        self.shown = max(self.shown, min(float(fraction), 1.0))
        answer = self.callback(self.shown)
        if not isinstance(answer, (bool, np.bool_)):
            raise TmmError(f"progress callback must return True (go on) or False (cancel), got {answer!r}")
        return bool(answer)


def option(label: str, value: Any, names: dict[str, str], shown: Optional[Sequence[str]] = None) -> str:
    """The op's property value for an API option (`names`: lower-case API name -> property value); a TmmError
    listing the choices (`shown`, default the API names) for anything else."""
    prop = names.get(str(value).lower())
    if prop is None:
        choices = list(shown or names)
        listed = f"'{choices[0]}' or '{choices[1]}'" if len(choices) == 2 else "one of " + ", ".join(choices)
        raise TmmError(f"{label} must be {listed}, got {value!r}")
    return prop


def numbers(**values: tuple[Any, Spec]) -> None:
    """Each API argument checked against its range by its own name (None: the op's default is used)."""
    for name, (value, spec) in values.items():
        if value is not None:
            check(replace(spec, label=name), value)


def by_core_name(props: dict[str, str]) -> dict[str, str]:
    """An op's enumeration table (property value -> core name) turned round: core name -> property value."""
    return {core: prop for prop, core in props.items()}
