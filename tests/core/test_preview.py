"""Tool path pictures: a PNG of the requested size that actually shows the model and the path."""
from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tmm_workbench.core.geometry import bezier

from tmm_workbench.core.preview import toolpath_png as preview
from tmm_workbench.core.toolpath import MoveKind, Toolpath

NET = np.array([[[50.0 * i, 40.0 * j, 10.0 * np.sin(i + j)] for j in range(4)] for i in range(4)])


def raster_over(net: np.ndarray, passes: int = 8, per_pass: int = 40) -> Toolpath:
    """A zig-zag of tip positions 3 mm above the patch, with the usual rapids at both ends."""
    tp = Toolpath()
    top = net[:, :, 2].max() + 10
    for p in range(passes):
        u = np.full(per_pass, p / (passes - 1))
        v = np.linspace(0, 1, per_pass)[:: 1 if p % 2 == 0 else -1]
        xyz = bezier.evaluate(net, u, v) + [0, 0, 3]
        if p == 0:
            tp.add(MoveKind.RAPID, xyz[0, 0], xyz[0, 1], top + 5)
            tp.add(MoveKind.RAPID, xyz[0, 0], xyz[0, 1], top)
            tp.add(MoveKind.PLUNGE, *xyz[0])
            xyz = xyz[1:]
        for q in xyz:
            tp.add(MoveKind.FEED, *q)
    last = tp.moves[-1]
    tp.add(MoveKind.RAPID, last.x, last.y, top + 5)
    return tp


def png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def test_importing_preview_does_not_import_matplotlib() -> None:
    # Choosing a backend at import time could fight FreeCAD's GUI: matplotlib loads only when drawing.
    repo = Path(__file__).resolve().parents[2]
    code = ("import sys; sys.path.insert(0, %r); import tmm_workbench.core.preview.toolpath_png; "
            "print('matplotlib' in sys.modules)" % str(repo))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_path_statistics_counts_and_lengths() -> None:
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 10)
    tp.add(MoveKind.RAPID, 0, 0, 5)
    tp.add(MoveKind.PLUNGE, 0, 0, 1)
    tp.add(MoveKind.FEED, 3, 4, 1)
    tp.add(MoveKind.FEED, 3, 4, 2)
    tp.add(MoveKind.RAPID, 3, 4, 10)
    s = preview.path_statistics(tp)
    assert s["rapid_count"] == 2 and s["plunge_count"] == 1 and s["feed_count"] == 2
    assert s["rapid_length"] == pytest.approx(5 + 8)
    assert s["cutting_length"] == pytest.approx(4 + 5 + 1)


def test_segments_split_by_kind_with_shared_end_points() -> None:
    tp = raster_over(NET, passes=3, per_pass=5)
    seg = preview._segments(tp)
    feed = seg["feed"]
    pieces = np.split(feed, np.flatnonzero(np.isnan(feed[:, 0])))
    assert len([p for p in pieces if len(p[~np.isnan(p[:, 0])])]) == 1  # one continuous zig-zag
    assert np.count_nonzero(~np.isnan(seg["rapid"][:, 0])) == 2 + 2  # two runs of rapids, 2 points each
    np.testing.assert_allclose(seg["plunge"][0], [tp.moves[1].x, tp.moves[1].y, tp.moves[1].z])


def test_decimation_caps_triangles_and_keeps_extent() -> None:
    mesh = bezier.tessellate(NET, 150, 150)  # 45 000 triangles
    v, f = preview.decimate_for_drawing(mesh.vertices, mesh.triangles, max_triangles=5000)
    assert 1000 < len(f) <= 5000
    lo, hi = mesh.bounds
    assert np.all(v.min(axis=0) >= lo - 1e-9) and np.all(v.max(axis=0) <= hi + 1e-9)
    assert np.all(v.max(axis=0) - v.min(axis=0) > 0.9 * (hi - lo))
    small_v, small_f = preview.decimate_for_drawing(mesh.vertices, mesh.triangles[:100], max_triangles=5000)
    assert len(small_f) == 100  # small meshes are drawn as they are


def test_render_writes_a_non_blank_png_of_the_requested_size(tmp_path: Path) -> None:
    import matplotlib.image

    mesh = bezier.tessellate(NET, 20, 20)
    out = tmp_path / "path.png"
    got = preview.render_toolpath_png(mesh, raster_over(NET), str(out), title="test patch",
                                      size_px=(1200, 600))
    assert got == str(out)
    assert png_size(out) == (1200, 600)
    img = matplotlib.image.imread(str(out))[:, :, :3]
    assert img.std() > 0.05  # not a blank canvas
    # The cutting colour shows (the path is drawn, not hidden behind the model).
    reddish = (img[:, :, 0] > 0.6) & (img[:, :, 1] < 0.45) & (img[:, :, 2] < 0.45)
    assert reddish.sum() > 500


def test_render_of_a_large_mesh_stays_quick(tmp_path: Path) -> None:
    import time

    mesh = bezier.tessellate(NET, 300, 300)  # 180 000 triangles
    t0 = time.perf_counter()
    preview.render_toolpath_png(mesh, raster_over(NET, 30, 200), str(tmp_path / "big.png"))
    assert time.perf_counter() - t0 < 30
    assert png_size(tmp_path / "big.png") == (1800, 850)


def test_dense_rasters_draw_every_kth_pass() -> None:
    seg = preview._segments(raster_over(NET, passes=200, per_pass=30))
    cut = preview._join(preview._pieces(seg["feed"]) + preview._pieces(seg["plunge"]))
    thinned, k, n = preview.thin_passes(cut, 60)
    assert n == 200 and k == 4
    drawn = preview._pieces(thinned)
    assert len(drawn) == 51  # passes 0, 4, ..., 196 and the last one, 199
    same, k1, n1 = preview.thin_passes(cut, 500)
    assert k1 == 1 and n1 == 200 and same is cut


def test_subdivision_bounds_edges_and_keeps_area() -> None:
    v = np.array([[0, 0, 0], [100, 0, 0], [100, 100, 0], [0, 100, 0]], dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    vs, fs = preview.subdivide_for_drawing(v, f, 10.0, budget=100_000)
    c = vs[fs]
    assert np.linalg.norm(c - np.roll(c, -1, axis=1), axis=2).max() <= 10.0
    area = 0.5 * np.linalg.norm(np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]), axis=1).sum()
    assert area == pytest.approx(100 * 100)
    _, few = preview.subdivide_for_drawing(v, f, 1.0, budget=50)
    assert len(few) <= 50


def test_points_behind_the_model_are_hidden() -> None:
    # A 20 x 20 plate at z = 0 seen from above, and a wall at x = 0 seen from +X.
    plate = np.array([[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]], dtype=float)
    f = np.array([[0, 1, 2], [0, 2, 3]])
    pts = np.array([[0, 0, 1], [0, 0, -1], [20, 0, -1], [np.nan] * 3, [5, 5, 0.5]], dtype=float)
    out = preview.hide_occluded(pts, plate, f, np.array([0.0, 0.0, 1.0]))
    assert np.isnan(out[1]).all() and np.isnan(out[3]).all()
    np.testing.assert_array_equal(out[[0, 2, 4]], pts[[0, 2, 4]])
    wall = plate[:, [2, 0, 1]]  # the plate turned into the plane x = 0
    seen = preview.hide_occluded(np.array([[5, 0, 0], [-5, 0, 0], [-5, 0, 15]], dtype=float), wall, f,
                                 np.array([1.0, 0.2, 0.3]))
    assert not np.isnan(seen[0]).any() and np.isnan(seen[1]).all() and not np.isnan(seen[2]).any()


def test_back_faces_of_closed_meshes_are_culled() -> None:
    # A closed tetrahedron, outward and inside-out; an open surface keeps every triangle.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    up = np.array([0.0, 0.0, 1.0])
    kept = preview.cull_back_faces(v, f, up)
    assert [0, 2, 1] not in kept.tolist() and [1, 2, 3] in kept.tolist()  # the bottom faces down
    flipped = preview.cull_back_faces(v, f[:, ::-1], up)
    assert len(flipped) == len(kept)  # inside-out files are judged by their signed volume
    assert len(preview.cull_back_faces(v, f[1:], up)) == 3
