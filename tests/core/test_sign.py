"""The sign of seed 003's customers (core.geometry.sign): a closed mesh with the letters, border and background
where the design puts them, its outlines for the pencil, and refusals naming the field."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError, WorkLimitError
from tmm_workbench.core.geometry.mesh import load_stl, save_stl
from tmm_workbench.core.geometry.sign import SignSpec, make_sign


def _edges_paired(triangles: np.ndarray) -> bool:
    """Closed and consistently oriented: every directed edge once, and its reverse present."""
    e = np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    key = e[:, 0].astype(np.int64) * (1 << 32) + e[:, 1]
    rev = e[:, 1].astype(np.int64) * (1 << 32) + e[:, 0]
    return len(np.unique(key)) == len(key) and np.isin(rev, key).all()


def _volume(v: np.ndarray, f: np.ndarray) -> float:
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6.0)


def _top(sign, spec: SignSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    nx, ny = math.floor(spec.width / spec.cell) + 1, math.floor(spec.height / spec.cell) + 1
    v = sign.mesh.vertices[:nx * ny]
    return v[:, 0].reshape(ny, nx)[0], v[:, 1].reshape(ny, nx)[:, 0], v[:, 2].reshape(ny, nx)


@pytest.mark.parametrize("shape,background", [("rectangle", "plain"), ("ellipse", "waves"), ("rounded", "plain")])
def test_closed_solid_with_letters_border_and_background_in_place(shape, background):
    spec = SignSpec("TMM 7", width=80.0, height=40.0, shape=shape, background=background, border=3.0, cell=0.2)
    sign = make_sign(spec)
    v, f = sign.mesh.vertices, sign.mesh.triangles
    assert _edges_paired(f)
    board = spec.width * spec.height * spec.thickness
    assert board < _volume(v, f) < board + spec.width * spec.height * spec.relief   # outward normals, relief on top
    xs, ys, z = _top(sign, spec)
    inside_letters = polygons.grid_inside([p[:-1] for p in sign.letters], xs, ys)
    inner = polygons.grid_inside([sign.border_inner[:-1]], xs, ys)
    assert inside_letters.sum() > 0.05 * inner.sum()             # the text covers part of the inner area
    assert not (inside_letters & ~inner).any()                    # and stays inside the border
    assert (z[inside_letters] > 0).all() and z[inside_letters].max() <= spec.relief + 1e-9
    deep = polygons.offset([p[:-1] for p in sign.letters], -1.6)  # beyond the shoulder (small ellipse text: none)
    assert deep or shape == "ellipse"
    if deep:
        assert np.allclose(z[polygons.grid_inside(deep, xs, ys)], spec.relief)   # letters' tops at the relief
    background_only = inner & ~polygons.grid_inside(polygons.offset([p[:-1] for p in sign.letters], 0.3), xs, ys)
    if background == "plain":
        assert np.allclose(z[background_only], 0.0)
    else:
        assert 0.0 <= z[background_only].min() < 0.05 and 0.2 * spec.relief < z[background_only].max() < 0.3 * spec.relief
    bead = ~inner & polygons.grid_inside([polygons.offset([sign.border_inner[:-1]], 3.0)[0]], xs, ys)
    assert z[bead].max() == pytest.approx(spec.relief, abs=0.02)  # the bead's crest


def test_the_text_changes_the_model_and_the_outlines_close():
    a, b = make_sign(SignSpec("AB", cell=0.5)), make_sign(SignSpec("AC", cell=0.5))
    assert not np.array_equal(a.mesh.vertices, b.mesh.vertices)
    assert all(np.array_equal(p[0], p[-1]) for p in a.letters + [a.border_inner])
    assert len(make_sign(SignSpec("B", cell=0.5)).letters) == 3   # B: its outline and two holes


def test_saved_stl_reads_back_the_same(tmp_path):
    sign = make_sign(SignSpec("Hi", width=40, height=20, cell=0.5))
    path = save_stl(sign.mesh, tmp_path / "hi.stl")
    back = load_stl(path)
    assert len(back) == len(sign.mesh)
    assert np.allclose(sorted(map(tuple, back.vertices.round(4))), sorted(map(tuple, sign.mesh.vertices.round(4))),
                       atol=1e-4)
    assert not (tmp_path / "hi.stl.part").exists()


@pytest.mark.parametrize("kwargs,words", [
    (dict(text=""), "sign text"), (dict(text="a\nb"), "sign text"), (dict(text="x" * 33), "sign text"),
    (dict(text="ok", width=5.0), "sign width must be in [20, 600] mm, got 5.0"),
    (dict(text="ok", relief=float("nan")), "sign relief"),
    (dict(text="ok", border=30.0), "sign border must be in [0, 12] mm"),
    (dict(text="ok", shape="star"), "sign shape must be one of rectangle, rounded, ellipse, got 'star'"),
    (dict(text="ok", background="wood"), "sign background"),
])
def test_bad_values_named(kwargs, words):
    with pytest.raises(TmmError) as err:
        make_sign(SignSpec(**kwargs))
    assert words in str(err.value)


def test_grid_too_fine_refused_before_allocation():
    with pytest.raises(WorkLimitError, match="sign cell 0.1 mm makes"):
        make_sign(SignSpec("big", width=600, height=600, cell=0.1))
