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


def test_band_colours_follow_the_band_and_mark_the_extremes():
    from tmm_workbench.core.preview.deviation_colours import BAND_INSIDE, band_colours, band_position, beyond_band

    band = 0.01
    t = band_position(np.array([-0.5, -band, -band / 2, 0.0, band / 2, band, 0.011, 9.0]), band)
    lo, hi = BAND_INSIDE
    np.testing.assert_allclose(t, [0.0, lo, 0.5 - (0.5 - lo) / 2, 0.5, 0.5 + (hi - 0.5) / 2, hi, 1.0, 1.0])
    # a 0.005 mm scallop is a clear colour, not the white a +9 mm range would give it
    rgb = band_colours(np.array([0.0, 0.005, 9.0, np.nan]), band)
    assert np.abs(rgb[1] - rgb[0]).max() > 0.2 and tuple(rgb[3]) == pytest.approx(NO_DESIGN_RGB)
    assert not np.allclose(rgb[2], band_colours(np.array([band]), band)[0])  # beyond: darker than the band's end
    assert beyond_band(np.array([0.02, -0.03, 0.001, np.nan]), band) == (1, 1, 0.02, -0.03)
    with pytest.raises(ValueError, match="colour band"):
        band_position(np.zeros(1), 0.0)


def test_normal_deviation_on_a_wall():
    from tmm_workbench.core.sim.compare import has_steep_walls, normal_deviation

    x = np.arange(10) * 0.1
    flat = np.zeros((5, 10))
    wall = np.tile(10.0 * x, (5, 1))  # slope 10: 84.3 deg
    dev = np.full((5, 10), 2.0)
    np.testing.assert_allclose(normal_deviation(dev, flat, 0.1), 2.0)
    np.testing.assert_allclose(normal_deviation(dev, wall, 0.1), 2.0 / np.sqrt(101.0))
    assert has_steep_walls(wall, 0.1) and not has_steep_walls(flat, 0.1)
    half = wall.copy()
    half[:, :5] = np.nan  # no design beside a cell: no slope known, the vertical deviation kept
    assert normal_deviation(dev, half, 0.1)[0, 5] == 2.0
