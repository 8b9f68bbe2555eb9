"""A deep cavity for the whole-tool tests: a plate 100 mm square at z = 0 with a pocket 70 mm square and 40 mm deep,
walls drafted 3 degrees, and a boss 20 mm square at the top, 20 mm high, drafted too."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh

DRAFT = math.tan(math.radians(3.0))


def square_rings(levels: list[tuple[float, float]], name: str) -> TriMesh:
    """Concentric squares (half width, z) from the outside in, each joined to the next by four trapezoids
    (two triangles each), the innermost capped."""
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
    v = np.array([[hw * x, hw * y, z] for hw, z in levels for x, y in corners])
    f = []
    for k in range(len(levels) - 1):
        o, i = 4 * k, 4 * (k + 1)
        for e in range(4):
            a, b, c, d = o + e, o + (e + 1) % 4, i + (e + 1) % 4, i + e
            f += [[a, b, c], [a, c, d]]
    n = 4 * (len(levels) - 1)
    f += [[n, n + 1, n + 2], [n, n + 2, n + 3]]
    return TriMesh(v, np.array(f), name)


def cavity_mesh() -> TriMesh:
    return square_rings([(50, 0), (35, 0), (35 - 40 * DRAFT, -40), (10 + 20 * DRAFT, -40), (10, -20)], "cavity")
