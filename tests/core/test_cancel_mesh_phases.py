"""The mesh phases (reading an STL, welding, normals, adjacency, the drop-cutter index) and the multipoint
positioner's samples report progress and honour cancel: through the binding a callback's False raises
native.Cancelled at its first report, the fractions never go backwards and end at 1, and a callback that goes on
changes no result; through the core the strategy's watched callback (core.cancel) stops them without a progress
of their own, as core Cancelled. Nothing here is timed (the latencies are in benchmarks/cancel_mesh_phases.py)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.kernel import native
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.strategies.multipoint import MultipointParams, make_positioner, position_points

MESH = grid_mesh(lambda x, y: 2.0 * np.sin(x / 3) * np.cos(y / 4), 40, 40, (0, 0, 40, 40), "wavy")  # 3200 tri
SOUP = MESH.vertices[MESH.triangles].reshape(-1, 9)
CONVEX_Z = [80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80]
NET = np.array([[(50.0 * i, 50.0 * j, CONVEX_Z[4 * i + j]) for j in range(4)] for i in range(4)])
FINE = MultipointParams(sample_spacing=1.0)  # 151 x 151 samples


class Recorder:
    """A progress callback that says stop from its `stop_at`-th question on, and keeps what it was asked."""

    def __init__(self, stop_at: int = 10**9) -> None:
        self.asked: list[float] = []
        self.stop_at = stop_at

    def __call__(self, fraction: float) -> bool:
        self.asked.append(fraction)
        return len(self.asked) < self.stop_at


def write_stls(folder: Path) -> tuple[str, str]:
    """MESH as an ASCII and a binary STL (float32 corners, as the file holds them)."""
    corners = SOUP.astype(np.float32)
    ascii_path, binary_path = folder / "wavy_ascii.stl", folder / "wavy_binary.stl"
    facet = "facet normal 0 0 1\n outer loop\n" + "  vertex %.9g %.9g %.9g\n" * 3 + " endloop\nendfacet\n"
    ascii_path.write_text("solid wavy\n" + "".join(facet % tuple(c) for c in corners) + "endsolid wavy\n")
    records = np.zeros(len(corners), dtype=[("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")])
    records["v"] = corners
    binary_path.write_bytes(bytes(80) + np.uint32(len(corners)).tobytes() + records.tobytes())
    return str(ascii_path), str(binary_path)


def kernel_phases(folder: Path) -> dict[str, Callable[[Any], Any]]:
    """Each phase as phase(progress) through the binding."""
    ascii_path, binary_path = write_stls(folder)
    v, f = MESH.vertices, MESH.triangles
    surface = native.PatchSurface.from_net(NET)
    options = {extend: native.MultipointOptions(Ro=6.7, Ri=6.0, sample_spacing=1.0, extend=extend)
               for extend in (0.0, 2.0)}
    return {
        "read_stl ascii": lambda p: native.read_stl(ascii_path, progress=p),
        "read_stl binary": lambda p: native.read_stl(binary_path, progress=p),
        "weld": lambda p: native.weld(SOUP, 1e-6, progress=p),
        "face_normals": lambda p: native.face_normals(v, f, progress=p),
        "vertex_normals angle": lambda p: native.vertex_normals(v, f, "angle", progress=p),
        "vertex_normals meyer": lambda p: native.vertex_normals(v, f, "meyer", progress=p),
        "triangle_adjacency": lambda p: native.triangle_adjacency(f, progress=p),
        "MeshIndex": lambda p: native.MeshIndex(v, f, progress=p),
        "MultipointPositioner": lambda p: native.MultipointPositioner(surface, options[0.0], progress=p),
        "MultipointPositioner extended": lambda p: native.MultipointPositioner(surface, options[2.0], progress=p),
    }


PHASES = ["read_stl ascii", "read_stl binary", "weld", "face_normals", "vertex_normals angle",
          "vertex_normals meyer", "triangle_adjacency", "MeshIndex", "MultipointPositioner",
          "MultipointPositioner extended"]


def outcome(result: Any) -> list:
    """What a phase made, comparable: arrays, or an index's or positioner's observable parts."""
    if isinstance(result, native.MeshIndex):
        return [result.triangle_count, result.node_count, result.zmin, result.zmax]
    if isinstance(result, native.MultipointPositioner):
        return [result.sample_spacing, result.position_batch(np.array([[75.0, 75.0], [20.0, 130.0]]), 1)["tip"]]
    return list(result) if isinstance(result, tuple) else [result]


@pytest.mark.parametrize("name", PHASES)
def test_kernel_phase_reports_cancels_and_keeps_its_result(tmp_path, name):
    phase = kernel_phases(tmp_path)[name]
    going = Recorder()
    with_callback = outcome(phase(going))
    assert len(going.asked) > 1
    assert going.asked == sorted(going.asked) and 0.0 <= going.asked[0] and going.asked[-1] == 1.0
    for a, b in zip(with_callback, outcome(phase(None))):
        np.testing.assert_array_equal(a, b)
    stop = Recorder(stop_at=1)
    with pytest.raises(native.Cancelled):
        phase(stop)
    assert len(stop.asked) == 1


def test_the_old_signatures_still_work():
    v, f = MESH.vertices, MESH.triangles
    assert native.weld(SOUP, 1e-6)[1].shape == f.shape
    assert native.vertex_normals(v, f, "area").shape == v.shape
    assert native.MeshIndex(v, f, threads=1).triangle_count == len(f)
    assert native.MultipointPositioner(native.PatchSurface.from_net(NET), native.MultipointOptions(Ro=6.7, Ri=6.0))


def core_phases(folder: Path) -> dict[str, Callable[..., Any]]:
    """Each core call that runs a kernel phase, taking progress= (None: the watched callback is asked)."""
    ascii_path, _ = write_stls(folder)
    face = BezierFace.from_net(NET)
    return {
        "load_stl": lambda progress=None: load_stl(ascii_path, progress=progress),
        "from_corners": lambda progress=None: TriMesh.from_corners(SOUP.reshape(-1, 3, 3), progress=progress),
        "face_normals": lambda progress=None: MESH.face_normals(progress=progress),
        "vertex_normals": lambda progress=None: MESH.vertex_normals("meyer", progress=progress),
        "adjacency": lambda progress=None: MESH.adjacency(progress=progress),
        "DropSurface": lambda progress=None: DropSurface(MESH, progress=progress),
        "make_positioner": lambda progress=None: make_positioner(face, 6.7, 6.0, FINE, progress=progress),
    }


CORE = ["load_stl", "from_corners", "face_normals", "vertex_normals", "adjacency", "DropSurface",
        "make_positioner"]


@pytest.mark.parametrize("name", CORE)
def test_core_phase_asks_the_watched_callback(tmp_path, name):
    phase = core_phases(tmp_path)[name]
    phase()  # nothing watched, no progress: runs as before
    stop = Recorder(stop_at=1)
    with cancel.watching(stop), pytest.raises(Cancelled):
        phase()
    assert stop.asked == [0.0]  # asked with the fraction the strategy reported so far


@pytest.mark.parametrize("name", CORE)
def test_core_phase_reports_to_its_own_progress(tmp_path, name):
    phase = core_phases(tmp_path)[name]
    going = Recorder()
    phase(progress=going)
    assert len(going.asked) > 1 and going.asked == sorted(going.asked) and going.asked[-1] == 1.0
    with pytest.raises(Cancelled):
        phase(progress=Recorder(stop_at=1))


def test_load_stl_reports_reading_then_welding(tmp_path):
    going = Recorder()
    load_stl(write_stls(tmp_path)[0], progress=going)
    assert 0.5 in going.asked  # the reading's end
    assert any(f < 0.5 for f in going.asked) and any(0.5 < f < 1.0 for f in going.asked)


def test_position_points_builds_its_samples_within_the_callers_progress():
    """The samples are built before any position: their cancel is the caller's callback too."""
    stop = Recorder(stop_at=1)
    with pytest.raises(Cancelled):
        position_points(BezierFace.from_net(NET), 6.7, 6.0, np.array([[75.0, 75.0]]), FINE, progress=stop)
    assert stop.asked == [0.0]
