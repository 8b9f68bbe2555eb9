"""core.post.fixed_text: G-code lines from arrays at once, byte for byte what Python's `%` formatting writes."""
from __future__ import annotations

import numpy as np
import pytest

from tmm_workbench.core.post import fixed_text


def python_lines(fmt: str, values: np.ndarray) -> str:
    return "".join(fmt % tuple(row) for row in values.tolist())


@pytest.mark.parametrize("precision", [0, 1, 3, 4, 6])
def test_random_values_and_ties_as_python_writes_them(precision: int) -> None:
    rng = np.random.default_rng(precision)
    n = 50_000
    values = np.column_stack([
        rng.uniform(-500, 500, n),
        rng.uniform(-1, 1, n) * 10.0 ** rng.integers(-6, 6, n),        # tiny to large
        np.round(rng.uniform(-100, 100, n) * 2 ** 10) / 2 ** 10,       # exact binary fractions: ties
        np.round(rng.uniform(-50, 50, n), precision + 1),              # decimals one place beyond: near ties
    ])
    values[:20, 1] = [0.0, -0.0, 1e-12, -1e-12, 0.5, -0.5, 1.5, 2.5, 0.03125, -0.03125, 0.00005, 0.00015,
                      1e9, -1e9, 999999.99995, 0.1, 0.2, 0.3, 123456.78905, -2.675]
    if precision > 4:   # 1e9 * 10**p beyond the exact range: Python's (checked below)
        values[12:14, 1] = [1e7, -1e7]
    fmt = f"G1 X%.{precision}f Y%.{precision}f Z%.{precision}f F%.{precision}f \n"
    assert fixed_text.lines(fmt, values) == python_lines(fmt, values)


def test_the_grbl_and_linuxcnc_layouts_and_one_column() -> None:
    values = np.array([[1.0, -2.0], [0.00004, 12345.6789]])
    for fmt in ("G1 X%.4f Y%.4f\n", "G0 X%.3f Y%.3f \n", "X%.2fY%.2f\n"):
        assert fixed_text.lines(fmt, values) == python_lines(fmt, values)
    z = np.array([[41.8718], [-0.0]])
    assert fixed_text.lines("G0 Z%.4f \n", z) == "G0 Z41.8718 \nG0 Z-0.0000 \n"


def test_what_it_leaves_to_python() -> None:
    values = np.array([[1.0, 2.0]])
    assert fixed_text.lines("T%d S%.4f\n", values) is None            # not all %.pf
    assert fixed_text.lines("X%.4f\n", values) is None                # a count that differs
    assert fixed_text.lines("X%.4f Y%.4f\n", np.array([[np.nan, 1.0]])) is None
    assert fixed_text.lines("X%.4f Y%.4f\n", np.array([[1e12, 1.0]])) is None   # beyond the exact range
