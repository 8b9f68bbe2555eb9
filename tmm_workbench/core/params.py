"""Strategy parameters: a dataclass whose fields carry their label, unit and allowed range, so every
strategy validates (and every op, panel and API reports) in one way, written once here.

    @dataclass
    class RasterParams(StrategyParams):
        stepover: float = param(1.0, "step-over", "mm", low=0, low_open=True)

`StrategyParams.validate()` checks every field against its `Spec`: numbers must be finite (no NaN or
infinity ever reaches a path), inside the range, choices one of the allowed values. A message names the
parameter, its value and the allowed range, in the user's terms.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, fields
from typing import Any, Optional, Sequence

import numpy as np

from tmm_workbench.core.errors import TmmError


@dataclass(frozen=True)
class Spec:
    label: str                        # the user's name of the parameter ("step-over")
    unit: str = ""                    # "mm", "deg" or "" (a count, a ratio)
    low: Optional[float] = None       # allowed range; None: unbounded on that side
    high: Optional[float] = None
    low_open: bool = False            # low itself excluded
    high_open: bool = False
    choices: Optional[tuple[Any, ...]] = None
    optional: bool = False            # None allowed (means "derive it")
    integer: bool = False
    kind: str = ""                    # "length" (positive length wording), "" otherwise

    def range_text(self) -> str:
        if self.choices is not None:
            return " or ".join(f"'{c}'" for c in self.choices)
        u = f" {self.unit}" if self.unit else ""
        if self.low is not None and self.high is not None:
            lo, hi = "(" if self.low_open else "[", ")" if self.high_open else "]"
            return f"in {lo}{self.low:g}, {self.high:g}{hi}{u}"
        if self.low is not None:
            return f"{'>' if self.low_open else '>='} {self.low:g}{u}"
        if self.high is not None:
            return f"{'<' if self.high_open else '<='} {self.high:g}{u}"
        return "a finite number" + (f" of {self.unit}" if self.unit else "")


def param(default: Any, label: str, unit: str = "", **spec: Any) -> Any:
    """A dataclass field with its Spec (see the module doc)."""
    return field(default=default, metadata={"spec": Spec(label, unit, **spec)})


def spec_of(params_class: type, name: str) -> Optional[Spec]:
    for f in fields(params_class):
        if f.name == name:
            return f.metadata.get("spec")
    raise KeyError(name)


def check(spec: Spec, value: Any) -> None:
    """TmmError naming the parameter, its value and the allowed range if `value` does not fit `spec`."""
    if value is None and spec.optional:
        return
    if spec.choices is not None:
        if value not in spec.choices:
            raise TmmError(f"{spec.label} must be {spec.range_text()}, got {value!r}")
        return
    # numbers.Real and Integral also take numpy's scalars (np.float32(6) is a length as 6.0 is)
    number = isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))
    if spec.integer and not (isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))):
        raise TmmError(f"{spec.label} must be a whole number {spec.range_text()}, got {value!r}")
    ok = number and math.isfinite(value)
    if ok and spec.low is not None:
        ok = value > spec.low if spec.low_open else value >= spec.low
    if ok and spec.high is not None:
        ok = value < spec.high if spec.high_open else value <= spec.high
    if not ok:
        shown = f"{value:g}" if number else repr(value)
        if spec.kind == "length" and spec.low == 0 and spec.high is None:
            what = "a positive length" if spec.low_open else "a length >= 0"
            raise TmmError(f"{spec.label} must be {what}, got {shown} (allowed: {spec.range_text()})")
        whole = "a whole number " if spec.integer else ""
        raise TmmError(f"{spec.label} must be {whole}{spec.range_text()}, got {shown}")


def check_finite(label: str, values: Sequence[Any], unit: str = "mm") -> None:
    """Every entry of `values` a finite number (a box, a point)."""
    if not all(isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)) and math.isfinite(v)
               for v in values):
        raise TmmError(f"{label} must be finite numbers of {unit}, got {tuple(values)!r}")


class StrategyParams:
    """Base of every strategy's parameters dataclass: `validate()` checks each field that has a Spec."""

    def validate(self) -> None:
        for f in fields(self):  # type: ignore[arg-type]
            spec = f.metadata.get("spec")
            if spec is not None:
                check(spec, getattr(self, f.name))
