"""The 5-axis mesh op's work estimate (core.strategies.mesh5.estimate): the width one pass finishes where the
surface tilts past the machine's tilt limit, and the passes told from it."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.query.height_sample import HeightSample
from tmm_workbench.core.strategies.mesh5.estimate import pass_widths, predict_passes
from tmm_workbench.core.tools.cutter import Cutter


def _ramp(deg: float) -> HeightSample:
    """A plane rising `deg` across the feed (+Y; the feed along +X), 40 x 40 mm, 1 mm nodes."""
    xs = ys = np.arange(0.0, 41.0)
    return HeightSample(xs, ys, np.tile(ys[:, None] * math.tan(math.radians(deg)), (1, len(xs))))


def test_past_the_machines_tilt_the_flat_bottom_finishes_far_less() -> None:
    # on a plane the upright flat D 10 finishes its whole diameter (seen from above: x cos(slope)); at 30 deg the
    # machine (C up to 45 deg) still holds the axis on the normal, at 60 deg it must lean the tool back 15 deg
    # or more from it, and the bottom stands on its rim: a strip a few tenths of a mm to a mm or so wide
    assert math.degrees(TarusMachine().c_limits[1]) == 45.0
    cutter, tol = Cutter.flat(10.0), 0.05
    inner = (slice(3, -3), slice(3, -3))
    w30 = pass_widths(_ramp(30.0), cutter, tol, 0.0, (0.0, 45.0))[inner]
    w60 = pass_widths(_ramp(60.0), cutter, tol, 0.0, (0.0, 45.0))[inner]
    assert np.allclose(w30, 10.0 * math.cos(math.radians(30.0)), rtol=1e-6)
    assert np.all(w60 > 0.0) and np.all(w60 < 0.25 * w30)
    more, fewer = (predict_passes(_ramp(d), cutter, tol, 0.0, (0.0, 45.0)) for d in (60.0, 30.0))
    assert more > 3 * fewer
