"""A wooden sign as seed 003's customers design one (section 1.4: a base shape, a border, a background, text): a
closed mesh, its top a height field on `cell` mm, for the planner and the web page, and the drawing's outlines
(the border's inner edge, the letters) for the pencil.

The board is the `width` x `height` rectangle, `thickness` below the background (z = 0). The border is a
half-round bead `border` wide following the base shape (a rectangle, a rounded rectangle or an ellipse) a margin
inside the board, as high as the letters (`relief`). The letters (matplotlib's TextPath of a bold sans font, so no
FreeCAD is needed) are fitted in the border's inner area and raised with a rounded shoulder (a quarter round half
the relief high), so that a ball reaches every part of them; the background is plain or waves (a scalloped
background: cos x cos y, a quarter of the relief)."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError, WorkLimitError
from tmm_workbench.core.geometry.mesh import TriMesh

SHAPES = ("rectangle", "rounded", "ellipse")
BACKGROUNDS = ("plain", "waves")
MAX_NODES = 4_000_000          # the top's grid nodes (about 200 MB of mesh and work arrays)
_TEXT = re.compile(r"^[A-Za-z0-9 .,:;!?&'()+\-/#@]{1,32}$")
_WAVE_MM = 8.0                 # the waves' period
_RANGES = {"width": (20.0, 600.0), "height": (10.0, 600.0), "relief": (0.5, 20.0), "thickness": (2.0, 100.0),
           "cell": (0.1, 2.0)}


@dataclass(frozen=True)
class SignSpec:
    """What the customer chooses (mm)."""
    text: str
    width: float = 120.0
    height: float = 60.0
    shape: str = "rectangle"
    border: float = 4.0
    relief: float = 3.0
    background: str = "plain"
    thickness: float = 10.0
    cell: float = 0.25

    def validate(self) -> None:
        """Raises TmmError naming the field, its value and what is allowed; WorkLimitError when the grid is too
        fine for the size (before anything is allocated)."""
        if not isinstance(self.text, str) or not _TEXT.match(self.text) or not self.text.strip():
            raise TmmError(f"sign text must be 1 to 32 letters, digits, spaces or .,:;!?&'()+-/#@, got {self.text!r}")
        for name, (lo, hi) in _RANGES.items():
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and lo <= v <= hi):
                raise TmmError(f"sign {name} must be in [{lo:g}, {hi:g}] mm, got {v!r}")
        top = 0.2 * min(self.width, self.height)
        if not (isinstance(self.border, (int, float)) and 0.0 <= self.border <= top):
            raise TmmError(f"sign border must be in [0, {top:g}] mm (a fifth of the smaller side), got {self.border!r}")
        if self.shape not in SHAPES:
            raise TmmError(f"sign shape must be one of {', '.join(SHAPES)}, got {self.shape!r}")
        if self.background not in BACKGROUNDS:
            raise TmmError(f"sign background must be one of {', '.join(BACKGROUNDS)}, got {self.background!r}")
        nodes = (math.floor(self.width / self.cell) + 1) * (math.floor(self.height / self.cell) + 1)
        if nodes > MAX_NODES:
            raise WorkLimitError(f"sign cell {self.cell:g} mm makes {nodes:,} grid nodes over {self.width:g} x "
                                 f"{self.height:g} mm, more than {MAX_NODES:,}: choose a cell of at least "
                                 f"{math.sqrt(self.width * self.height / MAX_NODES):.2f} mm")


@dataclass
class Sign:
    mesh: TriMesh
    border_inner: np.ndarray                              # the border's inner edge, a closed loop (XY)
    letters: list[np.ndarray] = field(default_factory=list)  # the letters' outlines, closed loops (XY)


def make_sign(spec: SignSpec) -> Sign:
    """The sign's mesh and outlines (see the module)."""
    spec.validate()
    margin = min(3.0, 0.05 * min(spec.width, spec.height))
    outline = _shape(spec.shape, margin, spec.width - margin, margin, spec.height - margin)
    inner = polygons.offset([outline], -spec.border) if spec.border > 0 else [outline]
    if len(inner) != 1:
        raise TmmError(f"sign border {spec.border:g} mm leaves no inner area in a {spec.shape} of "
                       f"{spec.width:g} x {spec.height:g} mm")
    letters = _letters(spec.text, inner[0], spec.border)
    xs = np.linspace(0.0, spec.width, math.floor(spec.width / spec.cell) + 1)
    ys = np.linspace(0.0, spec.height, math.floor(spec.height / spec.cell) + 1)
    top = np.maximum(_background(spec, xs, ys), _bead(outline, spec.border, spec.relief, xs, ys))
    top = np.maximum(top, _raised(letters, min(0.5 * spec.relief, 1.5), spec.relief, xs, ys))
    mesh = _closed_mesh(xs, ys, top, -spec.thickness, f"sign {spec.text!r}")
    return Sign(mesh, np.vstack([inner[0], inner[0][:1]]), [np.vstack([p, p[:1]]) for p in letters])


def _shape(kind: str, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
    cx, cy, a, b = 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (x1 - x0), 0.5 * (y1 - y0)
    if kind == "ellipse":
        unit = polygons.circle((0.0, 0.0), 1.0, chord_tol=1e-4)
        return np.column_stack([cx + a * unit[:, 0], cy + b * unit[:, 1]])
    if kind == "rounded":
        r = 0.25 * min(a, b)
        return polygons.offset([polygons.rectangle(x0 + r, y0 + r, x1 - r, y1 - r)], r)[0]
    return polygons.rectangle(x0, y0, x1, y1)


def _letters(text: str, area: np.ndarray, border: float) -> list[np.ndarray]:
    """The text's outlines scaled to the largest size that fits the area's inscribed box (less a gap)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    path = TextPath((0.0, 0.0), text, size=1.0, prop=FontProperties(family="DejaVu Sans", weight="bold"))
    loops = [np.asarray(p, float) for p in path.to_polygons(closed_only=True) if len(p) >= 4]
    if not loops:
        raise TmmError(f"sign text {text!r} has no letters to raise")
    pts = np.vstack(loops)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    x0, y0, x1, y1 = polygons.bounds([area])
    round_area = abs(polygons.signed_area(area)) < 0.9 * (x1 - x0) * (y1 - y0)   # an ellipse: its inscribed box
    shrink = 1.0 / math.sqrt(2.0) if round_area else 1.0
    gap = max(1.0, 0.5 * border)
    w, h = (x1 - x0) * shrink - 2 * gap, (y1 - y0) * shrink - 2 * gap
    scale = min(w / (hi[0] - lo[0]), h / (hi[1] - lo[1]))
    if not (scale > 0):
        raise TmmError(f"sign text {text!r} does not fit in the border's inner area")
    centre = 0.5 * (np.array([x0 + x1, y0 + y1]) - scale * (lo + hi))
    return [centre + scale * p[:-1] for p in loops]   # to_polygons repeats the first point


def _background(spec: SignSpec, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    if spec.background == "plain":
        return np.zeros((len(ys), len(xs)))
    k = 2 * math.pi / _WAVE_MM
    return 0.125 * spec.relief * (1.0 + np.outer(np.cos(k * ys), np.cos(k * xs)))


def _depth(shape: list[np.ndarray], xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """How far inside `shape` each node lies (mm, 0 outside): the distance to the nearest node outside."""
    from scipy.ndimage import distance_transform_edt

    return distance_transform_edt(polygons.grid_inside(shape, xs, ys)) * (xs[1] - xs[0])


def _bead(outline: np.ndarray, width: float, relief: float, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """A half-round bead `width` wide inside `outline`, `relief` high."""
    if width <= 0:
        return np.zeros((len(ys), len(xs)))
    u = _depth([outline], xs, ys) / width
    return np.where((u > 0) & (u < 1), relief * np.sqrt(np.clip(1.0 - (2 * u - 1) ** 2, 0.0, 1.0)), 0.0)


def _raised(letters: list[np.ndarray], shoulder: float, relief: float, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """The letters `relief` high with a quarter-round shoulder `shoulder` wide along their outlines."""
    t = np.clip(_depth(letters, xs, ys) / shoulder, 0.0, 1.0)
    return np.where(t > 0, relief - shoulder + shoulder * np.sqrt(1.0 - (1.0 - t) ** 2), 0.0)


def _closed_mesh(xs: np.ndarray, ys: np.ndarray, top: np.ndarray, bottom_z: float, name: str) -> TriMesh:
    """The top grid, four walls down to `bottom_z` and a bottom fanned from its centre: closed, outward normals."""
    nx, ny = len(xs), len(ys)
    gx, gy = np.meshgrid(xs, ys)
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = [np.column_stack([a, b, c]), np.column_stack([a, c, d])]
    ring = np.concatenate([idx[0, :-1], idx[:-1, -1], idx[-1, :0:-1], idx[:0:-1, 0]])   # counter-clockwise
    n_top, m = nx * ny, len(ring)
    low = n_top + np.arange(m)
    centre = n_top + m
    nxt = np.roll(np.arange(m), -1)
    tris += [np.column_stack([ring, low, low[nxt]]), np.column_stack([ring, low[nxt], ring[nxt]]),
             np.column_stack([np.full(m, centre), low[nxt], low])]
    top_v = np.column_stack([gx.ravel(), gy.ravel(), top.ravel()])
    ring_v = top_v[ring].copy()
    ring_v[:, 2] = bottom_z
    centre_v = [[0.5 * (xs[0] + xs[-1]), 0.5 * (ys[0] + ys[-1]), bottom_z]]
    return TriMesh(np.vstack([top_v, ring_v, centre_v]), np.vstack(tris), name)
