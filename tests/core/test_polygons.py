"""core.polygons (Clipper 6 through pyclipper) against analytic areas: offsets of a square by round joins
(area a^2 + 4 a d + pi d^2 within the chord tolerance), erosions, booleans of rectangles, orientation of
outer boundaries and holes, open-path clipping and sweeping, regions with their holes, point and segment
containment."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core import polygons as P


def square(x0, y0, a):
    return P.rectangle(x0, y0, x0 + a, y0 + a)


def test_offsets_against_analytic_areas():
    a, d = 10.0, 2.0
    grown = P.offset([square(0, 0, a)], d, arc_tol=1e-4)
    exact = a * a + 4 * a * d + math.pi * d * d
    # round joins are chords inside the arcs: a little less, never more
    assert exact - 0.01 < P.area(grown) <= exact
    assert P.area(P.offset([square(0, 0, a)], -d)) == pytest.approx((a - 2 * d) ** 2, abs=1e-9)
    assert P.offset([square(0, 0, a)], -a / 2 - 1e-3) == []          # eroded away
    disc = P.offset([np.array([[0.0, 0.0], [1e-6, 0.0], [0.0, 1e-6]])], 3.0, arc_tol=1e-4)
    assert P.area(disc) == pytest.approx(math.pi * 9, rel=1e-4)
    mitred = P.offset([square(0, 0, a)], d, miter=True)
    assert P.area(mitred) == pytest.approx((a + 2 * d) ** 2, abs=1e-9)


def test_booleans_of_rectangles():
    A, B = [square(0, 0, 10)], [square(5, 5, 10)]
    assert P.area(P.union(A, B)) == pytest.approx(175.0)
    assert P.area(P.intersection(A, B)) == pytest.approx(25.0)
    assert P.area(P.difference(A, B)) == pytest.approx(75.0)
    assert P.difference(B, [square(-100, -100, 300)]) == []
    assert P.covers([square(-1, -1, 12)], A) and not P.covers(A, B)


def test_orientation_outer_ccw_holes_cw():
    ring = P.difference([square(0, 0, 10)], [square(3, 3, 4)])
    areas = sorted(P.signed_area(p) for p in ring)
    assert areas == pytest.approx([-16.0, 100.0])
    assert P.area(ring) == pytest.approx(84.0)
    cw = square(0, 0, 1)[::-1]
    assert not P.is_ccw(cw) and P.is_ccw(P.oriented(cw, True)) and P.signed_area(P.oriented(cw, True)) == 1.0
    (region,) = P.regions(ring)
    assert P.signed_area(region.outer) > 0 and len(region.holes) == 1 and P.signed_area(region.holes[0]) < 0
    # an island inside the hole is a region of its own
    pieces = P.regions(ring + [square(4, 4, 2)])
    assert sorted(r.area for r in pieces) == pytest.approx([4.0, 84.0])


def test_open_paths_clipped_and_swept():
    ring = P.difference([square(0, 0, 10)], [square(3, 3, 4)])
    pieces = P.clip_open([np.array([[-5.0, 5.0], [15.0, 5.0]])], ring)
    lengths = sorted(float(np.hypot(*np.diff(p, axis=0).T).sum()) for p in pieces)
    assert lengths == pytest.approx([3.0, 3.0])
    band = P.offset_open([np.array([[0.0, 0.0], [10.0, 0.0]])], 1.0, arc_tol=1e-4)
    assert P.area(band) == pytest.approx(20.0 + math.pi, abs=0.01)
    loop_band = P.offset_open([square(0, 0, 10)], 1.0, arc_tol=1e-4, closed=True)
    assert P.area(loop_band) == pytest.approx((12 ** 2 - 4 + math.pi) - 8 ** 2, abs=0.01)


def test_many_open_paths_clipped_as_each_alone():
    # more paths than one Clipper sweep takes: every path's pieces, none lost or doubled at a batch's end
    ring = P.difference([square(0, 0, 10)], [square(3, 3, 4)])
    rng = np.random.default_rng(7)
    paths = [np.cumsum(rng.normal(size=(int(rng.integers(2, 6)), 2)) * 3, axis=0) + 5
             for _ in range(2 * P._OPEN_BATCH + 7)]

    def key(pieces):
        return sorted(tuple(np.round(p if tuple(p[0]) <= tuple(p[-1]) else p[::-1], 6).ravel()) for p in pieces)

    alone = [q for p in paths for q in P.clip_open([p], ring)]
    assert len(alone) > 2 * P._OPEN_BATCH
    assert key(P.clip_open(paths, ring)) == key(alone)


def test_point_and_segment_containment():
    ring = P.difference([square(0, 0, 10)], [square(3, 3, 4)])
    assert P.contains_point(ring, (1, 1)) and not P.contains_point(ring, (5, 5))
    assert P.contains_point(ring, (0, 5))                 # on the boundary
    assert P.segment_inside(np.array([1.0, 1.0]), np.array([9.0, 1.0]), ring)
    assert not P.segment_inside(np.array([1.0, 1.0]), np.array([9.0, 9.0]), ring)   # through the hole


def test_circle_within_its_chord_tolerance():
    c = P.circle((1.0, 2.0), 5.0, chord_tol=0.001)
    r = np.hypot(c[:, 0] - 1.0, c[:, 1] - 2.0)
    assert np.allclose(r, 5.0)
    half = math.pi / len(c)
    assert 5.0 * (1 - math.cos(half)) <= 0.001 and P.is_ccw(c)


def test_without_pyclipper_everything_loads_and_roughing_says_what_is_missing():
    """pyclipper is imported on first use: the workbench's op modules load (and documents restore) on a
    FreeCAD without it; clipping then fails with the package to install."""
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import sys; sys.modules['pyclipper'] = None\n"
        "import tmm_workbench.core.strategies.zlevel_rough, tmm_workbench.core.polygons as P\n"
        "import numpy as np\n"
        "from tmm_workbench.core.errors import TmmError\n"
        "try:\n"
        "    P.union([np.array([[0, 0], [1, 0], [1, 1.0]])])\n"
        "except TmmError as e:\n"
        "    print('REFUSED', e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parents[2], timeout=120)
    assert out.returncode == 0, out.stderr
    assert "REFUSED polygon clipping needs pyclipper" in out.stdout and "python3-pyclipper" in out.stdout
