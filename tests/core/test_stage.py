"""Stage declarations (core.stage): fields checked as declared, the Surface's core stages' refusals of an argument
the chosen mode would ignore."""
from __future__ import annotations

import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.stage import Field, Stage, api_names, fields_of, refuse_ignored
from tmm_workbench.core.strategies.surface import forward_step, pattern, positioning

SURFACE_CORE = (pattern.STAGE, positioning.STAGE, forward_step.STAGE)


def test_a_field_of_an_unknown_kind_or_with_misplaced_choices_is_refused() -> None:
    with pytest.raises(ValueError, match="kind 'size'"):
        Field("X", "size", "G", "tip")
    with pytest.raises(ValueError, match="choices go with kind 'choice'"):
        Field("X", "length", "G", "tip", choices={"A": "a"})
    with pytest.raises(ValueError, match="choices go with kind 'choice'"):
        Field("X", "choice", "G", "tip")


def test_a_property_declared_by_two_stages_is_refused() -> None:
    twice = Stage("again", (Field("SampleStep", "length", "G", "tip"),))
    with pytest.raises(ValueError, match="SampleStep is declared by two stages"):
        fields_of(SURFACE_CORE + (twice,))


def test_the_api_spelling_of_choices() -> None:
    by = {f.prop: f for f in fields_of(SURFACE_CORE)}
    assert by["Pattern"].api_choices() == {"zigzag": "ZigZag", "oneway": "OneWay", "spiral": "Spiral", "pencil": "Pencil"}
    assert by["StepOverMode"].api_choices()["offset3d"] == "Offset3D"
    assert by["ForwardStep"].api_choices() == {"tolerance": "Tolerance", "sample": "SampleStep"}
    assert {"stepover", "cusp", "pattern", "sample_step", "arcs", "forward_step"} <= api_names(SURFACE_CORE)


@pytest.mark.parametrize("args, message", [
    ({"stepover_mode": "cusp", "stepover": 0.5}, "stepover is not used with stepover_mode 'cusp'"),
    ({"stepover_mode": "adaptive", "stepover_percent": 10}, "stepover_percent is not used"),
    ({"stepover_mode": "stepover", "stepover": 0.5, "stepover_percent": 10}, "not both"),
    ({"stepover_mode": "stepover", "cusp": 0.01, "verify_cusp": False}, "cusp 0.01 is not used"),
    ({"pattern": "zigzag", "spiral_direction": "inward"}, "spiral_direction is used with pattern 'spiral' only"),
    ({"forward_step": "sample", "arcs": True}, "arcs need forward_step 'tolerance'"),
])
def test_an_argument_the_mode_would_ignore_is_refused_by_name(args: dict, message: str) -> None:
    with pytest.raises(TmmError, match=message):
        refuse_ignored(SURFACE_CORE, args)


@pytest.mark.parametrize("args", [
    {"stepover_mode": "cusp", "cusp": 0.01},
    {"stepover_mode": "stepover", "cusp": 0.01, "verify_cusp": True},
    {"pattern": "Spiral", "spiral_direction": "inward"},
    {"forward_step": "tolerance", "arcs": True},
    {},
])
def test_arguments_the_mode_uses_pass(args: dict) -> None:
    refuse_ignored(SURFACE_CORE, args)
