"""The tool axes a 5-axis op's view draws (core.preview.tool_axes): every n-th position, from the tip up
its axis, coloured by contact status or by tilt."""
from __future__ import annotations

import numpy as np
import pytest

from tmm_workbench.core.preview.tool_axes import CONTACT_RGB, TILTED_RGB, VERTICAL_RGB, axis_lines


def poses(n: int = 10):
    tips = np.column_stack([np.arange(n, dtype=float), np.zeros(n), np.full(n, 5.0)])
    tilt = np.radians(np.linspace(0, 45, n))
    axes = np.column_stack([np.sin(tilt), np.zeros(n), np.cos(tilt)])
    return tips, axes, np.array([0, 1] * (n // 2))


def test_every_nth_line_from_the_tip_up_the_axis():
    tips, axes, status = poses()
    pts, col = axis_lines(tips, axes, 3, 10.0, "Contact", status)
    assert len(pts) == 2 * 4 and len(col) == 4  # positions 0, 3, 6, 9
    np.testing.assert_allclose(pts[0::2], tips[::3])
    np.testing.assert_allclose(pts[1::2], tips[::3] + 10.0 * axes[::3])
    assert [tuple(c) for c in col] == [CONTACT_RGB[int(s)] for s in status[::3]]


def test_tilt_colours_run_from_vertical_to_the_limit():
    tips, axes, _ = poses()
    _, col = axis_lines(tips, axes, 1, 5.0, "Tilt", tilt_limit_deg=45.0)
    np.testing.assert_allclose(col[0], VERTICAL_RGB)
    np.testing.assert_allclose(col[-1], TILTED_RGB)
    # without statuses the contact colouring falls back to the tilt (a reopened document)
    _, col2 = axis_lines(tips, axes, 1, 5.0, "Contact", None, 45.0)
    np.testing.assert_allclose(col, col2)


@pytest.mark.parametrize("every, colouring", [(0, "Tilt"), (1, "Rainbow")])
def test_bad_arguments_are_named(every, colouring):
    tips, axes, _ = poses()
    with pytest.raises(ValueError, match="every" if every == 0 else "colouring"):
        axis_lines(tips, axes, every, 5.0, colouring)
