"""Work limits: every strategy estimates its work from its parameters, before allocating anything, and
refuses what this kind of machine (2 cores, 24 GB) cannot do in reasonable time and memory.

The limits are a setting: `set_limits(...)` (the App layer applies the user's FreeCAD preferences and names
them in refusals: `name_settings`), or the environment variables TMM_MAX_POINTS / TMM_MAX_POSITIONS /
TMM_MAX_MEMORY_GB for headless runs. CL points
of a drop-cutter cost microseconds each; multipoint positions (two-contact searches) milliseconds, so they
have a limit of their own.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, replace

from tmm_workbench.core.errors import WorkLimitError

# mm: the finest tolerance (cusp height, chord tolerance) an op takes. A tenth of a micrometre is below any
# machine's resolution; finer values only multiply passes and points
FINEST_MM = 1e-4


def _env(name: str, default: float) -> float:
    try:
        value = float(os.environ.get(name, default))
    except ValueError:
        return default
    return value if value > 0 else default


@dataclass(frozen=True)
class WorkLimits:
    max_points: int = int(_env("TMM_MAX_POINTS", 20_000_000))        # drop-cutter CL points of one op
    max_positions: int = int(_env("TMM_MAX_POSITIONS", 500_000))     # multipoint positions of one op
    max_memory_bytes: float = _env("TMM_MAX_MEMORY_GB", 8.0) * 1e9   # what one computation may allocate


_current = WorkLimits()
# how the user raises each limit, named in a refusal: a headless run's environment variables, or what the App
# layer names instead (name_settings: FreeCAD's preferences)
ENV_SETTINGS: tuple[str, dict] = ("the environment variables", {
    "max_points": "TMM_MAX_POINTS", "max_positions": "TMM_MAX_POSITIONS", "max_memory_bytes": "TMM_MAX_MEMORY_GB"})
_settings = ENV_SETTINGS


def current() -> WorkLimits:
    return _current


def set_limits(max_points: int | None = None, max_memory_gb: float | None = None,
               max_positions: int | None = None) -> WorkLimits:
    """Changes the limits for the following computations; returns the previous ones."""
    global _current
    previous = _current
    changes: dict = {}
    if max_points is not None:
        changes["max_points"] = int(max_points)
    if max_positions is not None:
        changes["max_positions"] = int(max_positions)
    if max_memory_gb is not None:
        changes["max_memory_bytes"] = float(max_memory_gb) * 1e9
    _current = replace(_current, **changes)
    return previous


def name_settings(where: str, names: dict) -> None:
    """How refusals tell the user to raise a limit: `where` ("the TMM preferences ...") and the setting's name
    for each WorkLimits field."""
    global _settings
    _settings = (where, dict(names))


def check_work(what: str, count: float, bytes_each: float, cause: str, limit: str = "max_points") -> None:
    """Refuses `count` items of `what` (bytes_each each) above the limits (`limit`: the WorkLimits field
    that bounds the count); `cause` names the parameters that set the count, with their values ("sample
    step 1e-06 mm, step-over 1 mm")."""
    limits = _current
    most = getattr(limits, limit)
    memory = count * bytes_each
    if count > most or memory > limits.max_memory_bytes:
        raise WorkLimitError(
            f"{cause} gives about {count:.3g} {what} ({memory / 1e9:.3g} GB): more than this machine's limit of "
            f"{most:.3g} {what} and {limits.max_memory_bytes / 1e9:.3g} GB; use coarser values or a smaller "
            f"boundary, or raise the limits: {_settings[0]} {_settings[1][limit]} and "
            f"{_settings[1]['max_memory_bytes']}")
