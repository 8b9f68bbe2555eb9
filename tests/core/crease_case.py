"""Seed 000's clean-up case (section 5.6: a surface with a gap) of our own: a floor 60 x 40 mm meeting a wall at 75
deg in a sharp concave crease along x = 40 (the wall rises to a plateau at x = 43.5), and a V groove 3 mm wide and
1.5 mm deep (90 deg) along y = 20 from x = 5 to 30, its ends sloped at 45 deg: narrower than a finishing ball D10,
which bridges it. A height field on a 0.5 mm grid whose lines carry the creases (the floor-wall crease, the wall's
top, the groove's bottom and edges)."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh

WIDTH, HEIGHT, CELL = 60.0, 40.0, 0.5
WALL_X, WALL_DEG, TOP_X = 40.0, 75.0, 43.5
WALL_H = (TOP_X - WALL_X) * math.tan(math.radians(WALL_DEG))
GROOVE_Y, GROOVE_HALF, GROOVE_X = 20.0, 1.5, (5.0, 30.0)


def height(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    wall = np.clip((x - WALL_X) * math.tan(math.radians(WALL_DEG)), 0.0, WALL_H)
    depth = np.clip(np.minimum.reduce([GROOVE_HALF - np.abs(y - GROOVE_Y), x - GROOVE_X[0], GROOVE_X[1] - x]),
                    0.0, None)
    return wall - depth


def crease_mesh(cell: float = CELL) -> TriMesh:
    nx, ny = int(round(WIDTH / cell)) + 1, int(round(HEIGHT / cell)) + 1
    X, Y = np.meshgrid(np.linspace(0, WIDTH, nx), np.linspace(0, HEIGHT, ny))
    v = np.column_stack([X.ravel(), Y.ravel(), height(X, Y).ravel()])
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    f = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return TriMesh(v, f, "crease_groove")


def fold_x(radius: float) -> float:
    """Where a ball of `radius` touches both the floor and the wall: its tip's x."""
    a = math.radians(WALL_DEG)
    return WALL_X - radius * (1 - math.cos(a)) / math.sin(a)
