"""CC paths of drive planes on a mesh (core.strategies.mesh5.cc_paths) against analytic surfaces."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import closest_distances, grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths, plane_normal, plane_offsets

RS = 40.0          # sphere radius (mm)
CHORD = 0.01
STEP = 1.5


def sphere_cap(n: int = 80) -> TriMesh:
    return grid_mesh(lambda x, y: np.sqrt(RS * RS - x * x - y * y), n, n, (-25, -25, 25, 25), "sphere cap")


@pytest.fixture(scope="module")
def cap_paths():
    mesh = sphere_cap()
    direction = (1.0, 0.4)
    offsets = plane_offsets(mesh, direction, 4.0)
    return mesh, direction, offsets, cc_paths(mesh, direction, offsets, forward_step=STEP, chord_tolerance=CHORD)


def test_cc_points_lie_on_the_mesh_and_the_sphere(cap_paths):
    mesh, _, _, paths = cap_paths
    pts = np.concatenate([p.points for p in paths])
    assert len(pts) > 200
    assert closest_distances(pts[::7], mesh).max() < 1e-9
    # the mesh is inscribed: its facets are within the sagitta of the sphere
    r = np.linalg.norm(pts, axis=1)
    assert np.all(r <= RS + 1e-9) and np.all(r >= RS - 0.02)


def test_chords_within_tolerance_and_forward_step(cap_paths):
    mesh, _, _, paths = cap_paths
    for p in paths[::5]:
        gaps = np.linalg.norm(np.diff(p.points, axis=0), axis=1)
        assert gaps.max() <= STEP + 1e-9
        # the chord's midpoint and quarter points stay within the chord tolerance of the mesh (the polyline)
        for u in (0.25, 0.5, 0.75):
            q = p.points[:-1] * (1 - u) + p.points[1:] * u
            assert closest_distances(q, mesh).max() <= CHORD + 1e-9
        # and the tolerance is used: the chords are not all far shorter than needed (not the raw cut)
        assert gaps.mean() > 0.5 * STEP


def test_normals_and_frames(cap_paths):
    _, direction, _, paths = cap_paths
    m = plane_normal(direction)
    for p in paths:
        exact = p.points / np.linalg.norm(p.points, axis=1, keepdims=True)
        inner = np.all(np.abs(p.points[:, :2]) < 24.0, axis=1)     # the grid's border has one-sided normals
        err = np.degrees(np.arccos(np.clip(np.sum(p.normals * exact, axis=1), -1, 1)))
        assert err[inner].max() < 0.2
        F = p.frames
        assert np.allclose(np.einsum("nij,nkj->nik", F, F), np.eye(3), atol=1e-12)
        assert np.allclose(np.linalg.det(F), 1.0)
        assert np.allclose(F[:, 2], p.normals)
        assert np.abs(F[:, 0] @ m).max() < 1e-12                       # LX lies in the drive plane
        fwd = np.diff(p.points, axis=0)
        assert np.all(np.einsum("ij,ij->i", F[:-1, 0], fwd) > 0)       # LX along the path


def test_passes_in_plane_order_and_points_in_feed_order(cap_paths):
    _, direction, offsets, paths = cap_paths
    m = plane_normal(direction)
    d = np.array([direction[0], direction[1], 0.0]) / math.hypot(*direction)
    planes = [p.plane for p in paths]
    assert planes == sorted(planes) and len(set(planes)) == len(offsets)
    for p in paths:
        assert np.abs(p.points @ m - offsets[p.plane]).max() < 1e-9
        assert np.all(np.diff(p.points @ d) > 0)


def test_a_plane_leaving_the_mesh_splits_the_path():
    mesh = grid_mesh(lambda x, y: 0.1 * x * x / 10, 40, 40, (-20, -20, 20, 20), "holed")
    c = mesh.vertices[mesh.triangles].mean(axis=1)
    keep = ~((np.abs(c[:, 0]) < 5) & (np.abs(c[:, 1]) < 5))           # a square hole in the middle
    holed = TriMesh(mesh.vertices, mesh.triangles[keep], "holed")
    paths = cc_paths(holed, (1, 0), np.array([0.1, 12.0]), 2.0, 0.01)
    by_plane = [[p for p in paths if p.plane == k] for k in (0, 1)]
    assert [len(b) for b in by_plane] == [2, 1]
    left, right = by_plane[0]
    assert left.points[-1, 0] < -4.9 and right.points[0, 0] > 4.9 and left.points[0, 0] < right.points[0, 0]


def test_bad_input_names_the_value():
    mesh = sphere_cap(10)
    with pytest.raises(TmmError, match="forward step"):
        cc_paths(mesh, (1, 0), np.array([0.0]), 0.0, 0.01)
    with pytest.raises(TmmError, match="horizontal"):
        cc_paths(mesh, (0, 0, 1), np.array([0.0]), 1.0, 0.01)
    with pytest.raises(TmmError, match="step"):
        plane_offsets(mesh, (1, 0), -2.0)
