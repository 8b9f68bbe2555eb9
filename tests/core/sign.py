"""A sign of our own for the pencil tests and seed 003's experiment (section 4.5): a board 84 x 44 mm with a raised
border 3 mm wide and the raised letters T M M, 2.5 mm high, as a height field (walls one cell wide: 0.2 mm over
2.5 mm, 85 deg). The letters' outlines (closed loops, XY) are what the drawing gives the pencil."""
from __future__ import annotations

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.geometry.mesh import TriMesh

WIDTH, HEIGHT, RELIEF, CELL = 84.0, 44.0, 2.5, 0.2
BORDER = 3.0


def _letters() -> list[np.ndarray]:
    """T, M, M as unions of rectangles (block letters 12 mm wide, 20 mm tall, strokes 3 mm), left to right."""
    r = polygons.rectangle
    t = [r(14, 30, 26, 33), r(18.5, 13, 21.5, 30)]
    m1 = [r(34, 13, 37, 33), r(45, 13, 48, 33), r(37, 27, 45, 30), r(39.5, 20, 42.5, 27)]
    m2 = [r(56, 13, 59, 33), r(67, 13, 70, 33), r(59, 27, 67, 30), r(61.5, 20, 64.5, 27)]
    return [p for group in (t, m1, m2) for p in polygons.union(group)]


def outlines() -> list[np.ndarray]:
    """The drawing: the border's inner edge and the letters' outlines, closed loops (first point repeated). They
    bound the background (the letters are holes in it): the pencil runs inside it."""
    inner = polygons.rectangle(BORDER, BORDER, WIDTH - BORDER, HEIGHT - BORDER)
    return [np.vstack([p, p[:1]]) for p in [inner] + _letters()]


def raised(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether each point lies on a raised part (a letter or the border)."""
    out = (x < BORDER) | (x > WIDTH - BORDER) | (y < BORDER) | (y > HEIGHT - BORDER)
    return out | polygons.points_inside(_letters(), np.column_stack([x.ravel(), y.ravel()])).reshape(x.shape)


def sign_mesh(cell: float = CELL) -> TriMesh:
    """The sign as a height field on `cell` mm (its walls one cell wide)."""
    nx, ny = int(round(WIDTH / cell)) + 1, int(round(HEIGHT / cell)) + 1
    X, Y = np.meshgrid(np.linspace(0, WIDTH, nx), np.linspace(0, HEIGHT, ny))
    Z = np.where(raised(X, Y), RELIEF, 0.0)
    v = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    f = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return TriMesh(v, f, "sign")
