"""STL reading and the indexed mesh through the binding and tmm_workbench.core.geometry.mesh: the shared benchmark
files, ASCII/binary detection by content, and clear errors (file and place) for broken files."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SHARED_STL
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl

SHARED_COUNTS = {
    "beet_mm.stl": 4630, "demo.stl": 1894, "ktoolcav.stl": 4090, "mount_rush.stl": 15592,
    "pycam-textbox.stl": 1444, "sphere_on_plate.stl": 7570, "wheel_in_box.stl": 6102,
}

# Three triangles, exactly representable in float32.
TRIS = np.array([
    [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
    [[1, 0, 0], [1, 1, 0], [0, 1, 0]],
    [[-1.5, 2.25, 0.125], [30000, -7.125, 0.5], [1, 2, 3]],
], dtype=np.float64)


def ascii_stl(tris: np.ndarray, eol: str = "\n", normal: str = "0 0 1") -> str:
    lines = ["solid test"]
    for t in tris:
        lines += [f"  facet normal {normal}", "    outer loop"]
        lines += [f"      vertex {x!r} {y!r} {z!r}" for x, y, z in t.tolist()]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid test")
    return eol.join(lines) + eol


def binary_stl(tris: np.ndarray, header: bytes = b"binary test", declared: int | None = None) -> bytes:
    rec = np.zeros(len(tris), dtype=[("normal", "<f4", 3), ("corners", "<f4", 9), ("attr", "<u2")])
    rec["normal"] = np.nan  # ignored
    rec["corners"] = tris.reshape(-1, 9)
    count = len(tris) if declared is None else declared
    return header.ljust(80, b" ") + np.uint32(count).tobytes() + rec.tobytes()


def load_error(path: Path) -> str:
    with pytest.raises(TmmError) as info:
        load_stl(path)
    return str(info.value)


# --- the shared benchmark files -------------------------------------------------------------------

@pytest.mark.parametrize("name,count", sorted(SHARED_COUNTS.items()))
def test_shared_files(name, count):
    soup = native.read_stl(str(SHARED_STL / name))
    assert soup.shape == (count, 9) and soup.dtype == np.float64 and np.isfinite(soup).all()

    mesh = load_stl(SHARED_STL / name)
    assert mesh.name == name
    assert len(mesh) + mesh.degenerate_removed == count
    assert mesh.vertices.dtype == np.float64 and mesh.triangles.dtype == np.int32
    assert len(mesh.vertices) < 3 * len(mesh)                     # corners were shared
    assert len(np.unique(mesh.triangles)) == len(mesh.vertices)   # every vertex is used
    for weighting in ("angle", "area", "meyer"):
        n = mesh.vertex_normals(weighting)
        assert n.shape == mesh.vertices.shape
        np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-9)


def test_read_stl_accepts_path_objects():
    assert native.read_stl(SHARED_STL / "demo.stl").shape == (1894, 9)


# --- formats ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("eol", ["\n", "\r\n", "\r"])
def test_ascii_line_endings(tmp_path, eol):
    p = tmp_path / "a.stl"
    p.write_bytes(ascii_stl(TRIS, eol).encode())
    np.testing.assert_array_equal(native.read_stl(str(p)), TRIS.reshape(-1, 9))


def test_ascii_zero_and_wrong_normals_ignored(tmp_path):
    p = tmp_path / "n.stl"
    p.write_text(ascii_stl(TRIS, normal="0 0 0") + ascii_stl(TRIS, normal="-nan 5 -1"))
    np.testing.assert_array_equal(native.read_stl(str(p)), np.vstack([TRIS, TRIS]).reshape(-1, 9))


@pytest.mark.parametrize("header", [b"binary test", b"solid this header looks like ASCII"])
def test_binary(tmp_path, header):
    p = tmp_path / "b.stl"
    p.write_bytes(binary_stl(TRIS, header))
    np.testing.assert_array_equal(native.read_stl(str(p)), TRIS.reshape(-1, 9))


def test_ascii_and_binary_give_the_same_mesh(tmp_path):
    (tmp_path / "a.stl").write_text(ascii_stl(TRIS))
    (tmp_path / "b.stl").write_bytes(binary_stl(TRIS))
    a, b = load_stl(tmp_path / "a.stl"), load_stl(tmp_path / "b.stl")
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.triangles, b.triangles)
    assert len(a.vertices) == 7  # the first two triangles share an edge


# --- broken files ----------------------------------------------------------------------------------

def test_truncated_binary(tmp_path):
    p = tmp_path / "part.stl"
    p.write_bytes(binary_stl(np.repeat(TRIS[:1], 812, axis=0), declared=1000) + b"\0" * 17)
    assert load_error(p) == f"{p}: binary STL declares 1000 triangles but holds 812 (file truncated?)"


def test_binary_extra_data(tmp_path):
    p = tmp_path / "extra.stl"
    p.write_bytes(binary_stl(TRIS, declared=2))
    assert "binary STL declares 2 triangles (184 bytes) but the file has 234 bytes" in load_error(p)


def test_truncated_ascii(tmp_path):
    p = tmp_path / "cut.stl"
    text = ascii_stl(TRIS)
    p.write_text(text[: text.index("vertex 1.0 1.0 0.0") + 10])
    msg = load_error(p)
    assert msg.startswith(f"{p}: unexpected end of file after line 12") and "truncated" in msg


def test_garbled_keyword_names_line(tmp_path):
    p = tmp_path / "part.stl"
    p.write_bytes(ascii_stl(TRIS, "\r\n").replace("vertex 1.0 1.0 0.0", "vertx 1.0 1.0 0.0").encode())
    assert load_error(p) == f"{p}: line 12: expected 'vertex', got 'vertx'"


def test_garbled_number_names_line(tmp_path):
    p = tmp_path / "num.stl"
    p.write_text(ascii_stl(TRIS).replace("vertex 1.0 1.0 0.0", "vertex 1.0 1,0 0.0"))
    assert load_error(p) == f"{p}: line 12: expected a number (vertex coordinate), got '1,0'"


@pytest.mark.parametrize("bad", ["nan", "-inf", "1e999"])
def test_non_finite_ascii(tmp_path, bad):
    p = tmp_path / "nan.stl"
    p.write_text(ascii_stl(TRIS).replace("vertex 1.0 1.0 0.0", f"vertex 1.0 {bad} 0.0"))
    assert load_error(p) == f"{p}: line 12: non-finite vertex coordinate '{bad}'"


def test_non_finite_binary(tmp_path):
    tris = np.repeat(TRIS[:1], 20, axis=0)
    tris[17, 1, 1] = np.inf
    p = tmp_path / "nan.stl"
    p.write_bytes(binary_stl(tris))
    assert load_error(p) == f"{p}: triangle 17 (byte offset 934) has a non-finite coordinate"


def test_empty_missing_directory_and_no_triangles(tmp_path):
    empty = tmp_path / "empty.stl"
    empty.write_bytes(b"")
    assert load_error(empty) == f"{empty}: file is empty"
    missing = tmp_path / "missing.stl"
    assert load_error(missing) == f"{missing}: file not found"
    assert load_error(tmp_path) == f"{tmp_path}: is a directory, not an STL file"
    none_ascii = tmp_path / "none.stl"
    none_ascii.write_text("solid x\nendsolid x\n")
    assert load_error(none_ascii) == f"{none_ascii}: ASCII STL holds no triangles"
    none_binary = tmp_path / "none_b.stl"
    none_binary.write_bytes(binary_stl(TRIS[:0]))
    assert load_error(none_binary) == f"{none_binary}: binary STL holds no triangles"
    text = tmp_path / "text.stl"
    text.write_text("hello, not an STL\n")
    assert "not an STL file" in load_error(text)


def test_stl_error_is_a_value_error(tmp_path):
    with pytest.raises(ValueError) as info:
        native.read_stl(str(tmp_path / "missing.stl"))
    assert isinstance(info.value, native.StlError)


def test_all_degenerate_file(tmp_path):
    p = tmp_path / "flat.stl"
    p.write_text(ascii_stl(np.array([[[0, 0, 0], [1, 1, 1], [2, 2, 2]], [[5, 5, 5], [5, 5, 5], [6, 5, 5]]],
                                    dtype=np.float64)))
    assert load_error(p).startswith("flat.stl: no non-degenerate triangles")


# --- welding and the mesh --------------------------------------------------------------------------

def test_weld_binding_counts_degenerate():
    soup = np.vstack([TRIS, [[[0, 0, 0], [0, 0, 0], [1, 0, 0]]], [[[0, 0, 1], [1, 1, 2], [2, 2, 3]]]])
    v, f, removed = native.weld(soup.reshape(-1, 9), 1e-6)
    assert v.dtype == np.float64 and v.shape == (7, 3)
    assert f.dtype == np.int32 and f.shape == (3, 3)
    assert removed == 2
    mesh = TriMesh.from_corners(soup, "soup")
    assert mesh.degenerate_removed == 2 and len(mesh) == 3
    assert TriMesh(v, f).degenerate_removed == 0


def test_weld_tolerance():
    moved = TRIS.copy()
    moved[1] += 4e-4  # the second triangle's copies of the shared edge move 0.7e-3 away
    assert len(TriMesh.from_corners(moved, weld_tolerance=1e-3).vertices) == 7
    assert len(TriMesh.from_corners(moved, weld_tolerance=1e-4).vertices) == 9


def test_from_corners_errors():
    bad = TRIS.copy()
    bad[2, 0, 1] = np.nan
    with pytest.raises(TmmError, match=r"^part: triangle 2 has a non-finite coordinate$"):
        TriMesh.from_corners(bad, "part")
    with pytest.raises(TmmError, match="shape"):
        TriMesh.from_corners(TRIS.reshape(-1, 9), "part")
    with pytest.raises(TmmError, match="no triangles"):
        TriMesh.from_corners(np.zeros((0, 3, 3)), "part")
    with pytest.raises(TmmError, match="weld tolerance must be finite and >= 0"):
        TriMesh.from_corners(TRIS, "part", weld_tolerance=-1)


def test_normals_and_adjacency():
    # A closed tetrahedron, outward winding.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int32)
    mesh = TriMesh(v, f, "tet")
    np.testing.assert_array_equal(mesh.adjacency(), [[2, 3, 1], [0, 3, 2], [1, 3, 0], [0, 2, 1]])
    np.testing.assert_allclose(mesh.face_normals()[:3], [[0, 0, -1], [0, -1, 0], [-1, 0, 0]])
    for weighting in ("angle", "area", "meyer"):
        n = mesh.vertex_normals(weighting)
        assert (np.einsum("ij,ij->i", n, v - v.mean(axis=0)) > 0).all()  # outward
    np.testing.assert_allclose(mesh.vertex_normals("angle")[0], -np.ones(3) / np.sqrt(3), atol=1e-15)


def test_plane_vertex_normals_exact():
    xs, ys = np.meshgrid(np.arange(6.0), np.arange(5.0), indexing="ij")
    v = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, 2.5)])
    a = (np.arange(5)[:, None] * 5 + np.arange(4)[None, :]).ravel()
    f = np.vstack([np.column_stack([a, a + 5, a + 6]), np.column_stack([a, a + 6, a + 1])]).astype(np.int32)
    mesh = TriMesh(v, f, "plane")
    for weighting in ("angle", "area", "meyer"):
        np.testing.assert_array_equal(mesh.vertex_normals(weighting), np.tile([0.0, 0.0, 1.0], (len(v), 1)))


def test_bad_weighting_and_indices():
    mesh = TriMesh(TRIS[0], np.array([[0, 1, 2]]), "one")
    with pytest.raises(TmmError, match="allowed: angle, area, meyer"):
        mesh.vertex_normals("cotan")
    with pytest.raises(ValueError, match=r"unknown vertex normal weighting 'cotan' \(allowed: 'angle', 'area', 'meyer'\)"):
        native.vertex_normals(mesh.vertices, mesh.triangles, "cotan")
    with pytest.raises(ValueError, match="triangle 0 references vertex 3, but there are 3 vertices"):
        native.face_normals(mesh.vertices, np.array([[0, 1, 3]], dtype=np.int32))
    with pytest.raises(ValueError, match="negative vertex index"):
        native.triangle_adjacency(np.array([[0, -1, 2]], dtype=np.int32))
