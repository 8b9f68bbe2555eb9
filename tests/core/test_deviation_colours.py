"""The deviation colours and the drawing decimation (core.preview.deviation_colours): 0 mm at the colour
map's centre, linear on each side, grey without design; a block shows its deepest gouge beyond the
tolerance, else its largest |deviation|, else its lowest height."""
from __future__ import annotations

import numpy as np
import pytest

from tmm_workbench.core.preview.deviation_colours import (NO_DESIGN_RGB, block_centres, colour_range, colours,
                                                          decimate, normalised)


def test_colour_map_centre_and_sides():
    low, high = colour_range(np.array([-0.02, 0.0, 0.3, np.nan]), 0.01)
    assert (low, high) == (-0.02, 0.3)
    assert colour_range(np.array([0.001]), 0.01) == (-0.01, 0.01)
    t = normalised(np.array([low, low / 2, 0.0, high / 2, high, 2 * high]), low, high)
    np.testing.assert_allclose(t, [0.0, 0.25, 0.5, 0.75, 1.0, 1.0])
    rgb = colours(np.array([[np.nan, 0.0]]), low, high)
    assert tuple(rgb[0]) == pytest.approx(NO_DESIGN_RGB) and rgb.shape == (2, 3)


def test_decimate_keeps_what_matters():
    h = np.zeros((4, 4))
    d = np.full((4, 4), 0.001)
    d[0, 1] = -0.05          # a gouge in block (0, 0)
    d[2, 3] = 0.2            # a crest in block (1, 1)
    d[0:2, 2:4] = np.nan     # block (0, 1): no design
    h[0, 3] = -1.0
    H, D, b = decimate(h, d, 0.01, limit=2)
    assert b == 2 and D.shape == (2, 2)
    assert D[0, 0] == -0.05 and D[1, 1] == 0.2 and np.isnan(D[0, 1]) and H[0, 1] == -1.0
    np.testing.assert_allclose(block_centres(0.0, 1.0, 5, 2), [1.0, 3.0, 4.5])
