"""The item-7 benchmark's helpers (benchmarks/cusp_item7.py on benchmarks/cusp_spacing.py) keep working: on a
small bump every row is there with finite values, the constant step-over's bisection brackets the adaptive
raster's simulated maximum cusp, and the ratios are the rows' own."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.tools.cutter import Cutter

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from cusp_item7 import BASE, model_rows, ratios, table  # noqa: E402

# the three tests share the module's table (a minute of benchmark): one worker runs them all (--dist loadgroup),
# which builds it once
pytestmark = pytest.mark.xdist_group("cusp_bench")

ROWS = [BASE, "constant cusp mode", "adaptive", "adaptive + verify", "3D offset", "3D offset + verify"]


@pytest.fixture(scope="module")
def bump_table():
    """A bump on a plate (slopes to about 25 deg), ball D6, cusp 0.02 mm, 0.2 mm cells."""
    mesh = grid_mesh(lambda x, y: 2.5 * np.exp(-((x - 8) ** 2 + (y - 6) ** 2) / 14.0), 48, 36, (-4, -3, 20, 15),
                     "bump")
    return model_rows("bump", mesh, Cutter.ball(6.0), 0.02, 0.2, boundary=(0.0, 0.0, 16.0, 12.0), log=print)


def test_every_row_with_finite_values(bump_table):
    assert bump_table.failed == []
    assert [BASE if r.label.startswith(BASE) else r.label for r in bump_table.rows] == ROWS
    for r in bump_table.rows:
        assert r.passes > 0 and r.moves > 0 and r.partial >= 0, r
        assert all(math.isfinite(v) and v > 0 for v in (r.cusp, r.cycle_s, r.compute_s)), r
    lines = table([bump_table])
    assert len(lines) == 2 + len(ROWS) and "nan" not in "".join(lines)


def test_the_bisection_brackets_the_adaptive_max_cusp(bump_table):
    adaptive = next(r for r in bump_table.rows if r.label == "adaptive")
    b = bump_table.bisection
    assert b.cusp_lo is not None and b.cusp_hi is not None
    assert b.cusp_lo <= adaptive.cusp < b.cusp_hi
    assert b.step_lo < b.step_hi and b.step_hi - b.step_lo < 0.1  # 7 rounds of halving
    base = bump_table.base()
    assert base.cusp == b.cusp_lo and f"{b.step_lo:.3f} mm" in base.label


def test_ratios_are_against_the_constant_step_over(bump_table):
    base = bump_table.base()
    assert ratios(base, base) == (1.0, 1.0)
    v = next(r for r in bump_table.rows if r.label == "adaptive + verify")
    p, c = ratios(v, base)
    assert p == pytest.approx(base.passes / (v.passes + v.partial))
    assert c == pytest.approx(base.cycle_s / v.cycle_s)
