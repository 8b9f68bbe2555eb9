"""Seed 000's convex and concave benchmark surfaces (Appendix A; `shared/benchmarks/seed_surfaces.json`,
`lu2007_bspline_sections`) as triangle meshes in mm, for the cusp-spacing benchmark.

How they are built (the seed gives only the poles, in inches, of two section curves in the planes X = 0 and
X = 10; the JSON's reconstruction note is followed): each section is a cubic, clamped, uniformly knotted
B-spline curve through its poles (all weights 1); the surface is the ruled surface between the two sections
at equal curve parameter, S(t, s) = (1 - s) C0(t) + s C1(t) (what a "through-curve" surface of two sections
is, and what OCC's ruled surface does with two curves of one parameter range). The concave surface's sections
have 11 and 9 poles: equal parameter, not equal pole index, pairs them. Units are converted to mm (x 25.4).
The mesh is a regular (t, s) grid split into triangles, fine enough that its largest deviation from the
surface (measured at every triangle's centroid, printed by `python benchmarks/seed000_surfaces.py`) is far
below the seed's tessellation tolerance of 0.002 in.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import TriMesh  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402

INCH = 25.4
DEGREE = 3


def clamped_uniform_knots(n_poles: int, degree: int = DEGREE) -> np.ndarray:
    inner = np.linspace(0.0, 1.0, n_poles - degree + 1)
    return np.concatenate([np.zeros(degree), inner, np.ones(degree)])


def bspline_curve(poles: np.ndarray, t: np.ndarray, degree: int = DEGREE) -> np.ndarray:
    """Points (len(t), dim) of the clamped uniform B-spline curve with these poles (Cox-de Boor basis)."""
    knots = clamped_uniform_knots(len(poles), degree)
    t = np.clip(np.asarray(t, dtype=float), 0.0, 1.0)
    # degree-0 basis; t = 1 belongs to the last non-empty span
    span = np.clip(np.searchsorted(knots, t, side="right") - 1, degree, len(poles) - 1)
    basis = np.zeros((len(t), len(knots) - 1))
    basis[np.arange(len(t)), span] = 1.0
    for p in range(1, degree + 1):
        nxt = np.zeros((len(t), len(knots) - 1 - p))
        for i in range(len(knots) - 1 - p):
            d0 = knots[i + p] - knots[i]
            d1 = knots[i + p + 1] - knots[i + 1]
            if d0 > 0:
                nxt[:, i] += (t - knots[i]) / d0 * basis[:, i]
            if d1 > 0:
                nxt[:, i] += (knots[i + p + 1] - t) / d1 * basis[:, i + 1]
        basis = nxt
    return basis @ poles


def ruled_points(sections: list[np.ndarray], t: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (n, 3) of the ruled surface between two section curves at the parameter pairs (t[k], s[k])."""
    c0, c1 = (bspline_curve(np.asarray(p, dtype=float), t) for p in sections)
    return (1.0 - s)[:, None] * c0 + s[:, None] * c1


def through_points(sections: list[np.ndarray], t: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points (n, 3) of the surface through the section curves at the parameter pairs (t[k], s[k]): ruled
    between two sections; through more, at equal curve parameter t, the polynomial in s through the sections'
    points at s = 0, 1/(m-1), ..., 1 (the complex surface's four sections lie at X = 0, 3, 6, 9 in, evenly
    spaced: a cubic through the four, X linear in s)."""
    if len(sections) == 2:
        return ruled_points(sections, t, s)
    pts = [bspline_curve(np.asarray(p, dtype=float), t) for p in sections]
    nodes = np.linspace(0.0, 1.0, len(pts))
    out = np.zeros_like(pts[0])
    for k, pk in enumerate(pts):
        w = np.ones_like(s)
        for j in range(len(pts)):
            if j != k:
                w = w * (s - nodes[j]) / (nodes[k] - nodes[j])
        out += w[:, None] * pk
    return out


def complex_sections() -> list[np.ndarray]:
    """The complex surface's four section curves' poles (inches), read from seed 000's Appendix A (they are
    not in seed_surfaces.json): the X, Y, Z columns of every pole of Spline 1..4."""
    text = (shared_dir() / "seeds" / "000_644051502d90cb70.txt").read_text()
    text = text[text.index("Complex surface:"):text.index("APPENDIX B")]
    out = []
    for body in re.split(r"Control points of Spline \d:", text)[1:]:
        xyz = [re.findall(rf"\b{c} =\s+(-?\d+\.\d+)", body) for c in "XYZ"]
        out.append(np.array(xyz, dtype=float).T)
    return out


def _grid_triangles(nt: int, ns: int) -> np.ndarray:
    i, j = np.meshgrid(np.arange(nt - 1), np.arange(ns - 1), indexing="ij")
    a = (i * ns + j).ravel()
    b, c, d = a + ns, a + 1, a + ns + 1
    return np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)])


def seed000_mesh(name: str, nt: int = 401, ns: int | None = None, window: tuple | None = None
                 ) -> tuple[TriMesh, float]:
    """The surface `name` ("convex", "concave" or "complex") in mm and the mesh's largest deviation from it (mm);
    `window` (t0, t1, s0, s1): only that part of its parameters (the planner's Tarus test: a 51 x 53 mm piece)."""
    if name == "complex":
        sections = [p * INCH for p in complex_sections()]
        ns = 81 if ns is None else ns                   # it bends along X too: 41 columns left 0.106 mm
    else:
        data = json.loads((shared_dir() / "benchmarks" / "seed_surfaces.json").read_text())
        sections = [np.asarray(p) * INCH for p in data["lu2007_bspline_sections"]["surfaces"][name]]
        ns = 41 if ns is None else ns
    t0, t1, s0, s1 = window or (0.0, 1.0, 0.0, 1.0)
    tt, ss = (g.ravel() for g in np.meshgrid(np.linspace(t0, t1, nt), np.linspace(s0, s1, ns), indexing="ij"))
    pts = through_points(sections, tt, ss)
    tri = _grid_triangles(nt, ns)
    # a height field faces up: wind every triangle so (its normal).z >= 0 (the grid's (t, s) may map onto (x, y)
    # either way round; down-facing triangles made core.footprint.cusp's steepest crossing read 0 deg)
    e1, e2 = pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]]
    down = (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) < 0
    tri[down] = tri[down][:, ::-1]
    # the deviation at each triangle's centroid: the surface at the centroid's parameters against the plane
    uv = np.stack([tt, ss], 1)[tri].mean(axis=1)
    deviation = float(np.linalg.norm(through_points(sections, uv[:, 0], uv[:, 1]) - pts[tri].mean(axis=1),
                                     axis=1).max())
    return TriMesh(pts, tri, f"seed000_{name}"), deviation


# the convex surface's middle, 51 x 53 x 5.5 mm: tests/data/seed000_convex_window.stl
TARUS_WINDOW = (0.4, 0.6, 0.4, 0.6)


def write_window(path: Path) -> Path:
    """The planner's Tarus test model: the convex surface's TARUS_WINDOW, 41 x 21 points (1,600 triangles)."""
    from tmm_workbench.core.geometry.mesh import save_stl

    mesh, _ = seed000_mesh("convex", nt=41, ns=21, window=TARUS_WINDOW)
    return save_stl(mesh, path)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--window"]:
        raise SystemExit(print(write_window(Path(sys.argv[2]))))
    for n in ("convex", "concave", "complex"):
        mesh, dev = seed000_mesh(n)
        lo, hi = mesh.bounds
        print(f"{n}: {len(mesh.triangles)} triangles, box {np.round(lo, 2)} .. {np.round(hi, 2)} mm, "
              f"largest deviation from the surface {dev:.5f} mm (seed tolerance {0.002 * INCH:.4f} mm)")
