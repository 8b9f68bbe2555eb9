"""What the headless API does to its callers' arguments before checking them: numpy scalars become Python
numbers (FreeCAD's properties and the core's checks take float and int, a macro often passes np.float32),
and a progress callback's answer must be a bool (a string such as "stop" is truthy: taken as "go on")."""
from __future__ import annotations

import functools
from typing import Any, Callable

import numpy as np

from tmm_workbench.app import progress as progress_mod
from tmm_workbench.core.errors import TmmError


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
