"""G2/G3 arcs as chords (core.arcs): every chord within the tolerance of the arc (its sagitta), the ends
exact, the sense (G2 clockwise), full circles, helices, and inconsistent centres refused; an arc move's G-code
words (plane, G2/G3, the plane's centre offsets) and its chords from one Arc."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.arcs import PLANE_CODES, Arc, arc_points
from tmm_workbench.core.errors import TmmError


def sagitta(pts: np.ndarray, centre, r: float) -> float:
    mid = (pts[1:, :2] + pts[:-1, :2]) / 2
    return float((r - np.hypot(*(mid - centre).T)).max())


@pytest.mark.parametrize("clockwise", [True, False])
def test_quarter_circle(clockwise):
    start, end = (10.0, 0.0, 0.0), ((0.0, -10.0, 0.0) if clockwise else (0.0, 10.0, 0.0))
    pts = arc_points(start, end, -10.0, 0.0, clockwise, 1e-3)
    assert np.allclose(pts[-1], end)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 10.0)
    allp = np.vstack([start, pts])
    assert 0 < sagitta(allp, (0, 0), 10.0) <= 1e-3 + 1e-12
    ang = np.unwrap(np.arctan2(allp[:, 1], allp[:, 0]))
    assert np.all(np.diff(ang) < 0) if clockwise else np.all(np.diff(ang) > 0)
    assert ang[-1] - ang[0] == pytest.approx(-math.pi / 2 if clockwise else math.pi / 2)


def test_full_circle_and_helix():
    pts = arc_points((5.0, 0.0, 0.0), (5.0, 0.0, -2.0), -5.0, 0.0, False, 1e-3)
    allp = np.vstack([(5.0, 0.0, 0.0), pts])
    assert len(pts) > 50 and np.allclose(pts[-1], (5.0, 0.0, -2.0))
    assert np.all(np.diff(allp[:, 2]) < 0)                      # Z linear in the angle
    assert np.unwrap(np.arctan2(allp[:, 1], allp[:, 0]))[-1] == pytest.approx(2 * math.pi)


def test_inconsistent_centre_is_refused():
    with pytest.raises(TmmError, match="the centre is 10 mm from the start and 12 mm from the end"):
        arc_points((10.0, 0.0, 0.0), (0.0, 12.0, 0.0), -10.0, 0.0, False)
    with pytest.raises(TmmError, match="zero radius"):
        arc_points((1.0, 1.0, 0.0), (1.0, 1.0, 0.0), 0.0, 0.0, True)


@pytest.mark.parametrize("plane,words", [("XY", ("I", "J")), ("XZ", ("I", "K")), ("YZ", ("J", "K"))])
def test_arc_command_words_and_chords(plane, words):
    """The words of the move about a centre (the plane's two offsets from the start, as FreeCAD's I/J/K), its
    sense from Arc.through (a quarter turn about the plane's normal is G3), its chords on the circle, and the
    reversed arc back to the start."""
    axes = {"XY": (0, 1), "XZ": (2, 0), "YZ": (1, 2)}[plane]  # a counter-clockwise quarter from axes[0] to axes[1]
    centre = np.array([1.0, 2.0, 3.0])
    start, end = centre.copy(), centre.copy()
    start[axes[0]] += 4.0
    end[axes[1]] += 4.0
    arc = Arc.through(start, end, centre, plane)
    name, got = arc.command(start, end)
    assert name == "G3" and not arc.clockwise and PLANE_CODES[plane] == {"XY": "G17", "XZ": "G18", "YZ": "G19"}[plane]
    assert list(got) == ["X", "Y", "Z", *words]
    assert [got[w] for w in words] == [(centre - start)["IJK".index(w)] for w in words]
    pts = arc.chords(start, end, 1e-4)
    assert np.allclose(np.linalg.norm(pts - centre, axis=1), 4.0) and np.allclose(pts[-1], end)
    back = arc.reversed()
    assert back.command(end, start)[0] == "G2" and np.allclose(back.chords(end, start, 1e-4)[-1], start)


def test_arc_plane_checked():
    with pytest.raises(TmmError, match="plane"):
        Arc((0.0, 0.0, 0.0), True, "ZX")
