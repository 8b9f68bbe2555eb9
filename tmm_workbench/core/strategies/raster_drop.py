"""3-axis surface finishing: a raster footprint dropped on the mesh, linked into one tool path."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.query.drop import DropSurface, Progress
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.raster import Rect, raster_lines, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.toolpath import MoveKind, Toolpath

ZIGZAG = "zigzag"
ONEWAY = "oneway"
# Where no triangle lies under the cutter ("air": beside an open surface or a relief without a base, in a
# hole): FLOOR runs the tool along the floor there, as a drop-cutter does; SKIP does not cut there: the pass
# is split, the tool lifts to the safe height and plunges again where the model resumes.
OFF_MODEL_FLOOR = "floor"
OFF_MODEL_SKIP = "skip"
_AIR_DEPTH_MM = 1e6  # SKIP drops onto a floor this far below the model: only air points end there
_COLLINEAR_MM = 1e-7  # points this close to the chord of their neighbours add nothing to the path
_LABEL = {"stepover": "step-over", "sample_step": "sample step"}


@dataclass
class SurfaceParams:
    boundary: Rect                   # xmin, ymin, xmax, ymax of the tip positions (mm)
    stepover: float                  # distance between passes (mm)
    sample_step: float               # forward sampling step along a pass (mm)
    safe_height: float               # retract height between passes (mm)
    clearance_height: float          # height at start and end (mm)
    angle_deg: float = 0.0           # raster angle from +X
    pattern: str = ZIGZAG            # ZIGZAG or ONEWAY
    stock_to_leave: float = 0.0      # material left on the surface (mm)
    floor_z: Optional[float] = None  # the tip never goes below; default: the model's lowest point
    off_model: str = OFF_MODEL_FLOOR  # OFF_MODEL_FLOOR or OFF_MODEL_SKIP (see above)

    def validate(self) -> None:
        for name in ("stepover", "sample_step"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise TmmError(f"{_LABEL[name]} must be a positive length, got {v!r}")
        for name in ("safe_height", "clearance_height", "angle_deg", "stock_to_leave"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise TmmError(f"{name.replace('_', ' ')} must be a finite number, got {v!r}")
        if self.pattern not in (ZIGZAG, ONEWAY):
            raise TmmError(f"pattern must be '{ZIGZAG}' or '{ONEWAY}', got {self.pattern!r}")
        if self.off_model not in (OFF_MODEL_FLOOR, OFF_MODEL_SKIP):
            raise TmmError(f"off-model must be '{OFF_MODEL_FLOOR}' or '{OFF_MODEL_SKIP}', got {self.off_model!r}")
        if self.clearance_height < self.safe_height:
            raise TmmError(f"clearance height {self.clearance_height:g} mm is below the safe height "
                           f"{self.safe_height:g} mm")
        if len(self.boundary) != 4 or not all(math.isfinite(b) for b in self.boundary):
            raise TmmError(f"boundary must be four finite numbers xmin, ymin, xmax, ymax, got {self.boundary!r}")


def compute_surface_toolpath(mesh: TriMesh, cutter: Cutter, params: SurfaceParams,
                             progress: Optional[Progress] = None,
                             surface: Optional[DropSurface] = None) -> Toolpath:
    """Gouge-free raster finishing of `mesh` with `cutter` (tip positions; Z up).

    Every cutting move, including the links between zig-zag passes, is made of dropped CL points,
    so straight moves only join positions no more than `sample_step` apart.
    """
    params.validate()
    lo, hi = mesh.bounds
    b = params.boundary
    if b[2] <= lo[0] or b[0] >= hi[0] or b[3] <= lo[1] or b[1] >= hi[1]:
        raise TmmError(f"boundary x {b[0]:g}..{b[2]:g}, y {b[1]:g}..{b[3]:g} lies outside the model "
                       f"(x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g})")
    floor_z = float(lo[2]) if params.floor_z is None else float(params.floor_z)

    lines = raster_lines(b, params.stepover, params.angle_deg)
    if params.pattern == ZIGZAG:
        lines = [ln if i % 2 == 0 else ln[::-1] for i, ln in enumerate(lines)]
    # Runs of XY points: passes, and for zig-zag the links between them, dropped in one batch.
    runs: list[tuple[bool, np.ndarray]] = []  # (is_link, xy)
    for i, ln in enumerate(lines):
        if i > 0 and params.pattern == ZIGZAG:
            link = sample_segment(lines[i - 1][1], ln[0], params.sample_step)[1:-1]
            runs.append((True, link))
        runs.append((False, sample_segment(ln[0], ln[1], params.sample_step)))
    xy = np.concatenate([r for _, r in runs])
    if len(xy) > 50_000_000:
        raise TmmError(f"{len(xy)} CL points: sampling step {params.sample_step:g} mm is too fine")

    s = params.stock_to_leave
    surface = surface or DropSurface(mesh)
    skip = params.off_model == OFF_MODEL_SKIP
    air_floor = float(lo[2]) - _AIR_DEPTH_MM
    z = surface.drop(cutter.offset(s), xy, (air_floor if skip else floor_z) - s, progress) + s
    air = z <= air_floor + 1.0 if skip else np.zeros(len(z), dtype=bool)
    if air.all():
        raise TmmError("the cutter is over no part of the model anywhere in the boundary (off-model: skip)")
    z = np.maximum(z, floor_z)

    top = float(z[~air].max())
    if params.safe_height <= top:
        raise TmmError(f"safe height {params.safe_height:g} mm is not above the highest tool position "
                       f"{top:.4g} mm")
    return _link(_pieces(runs, z, air, params.pattern), params)


def _pieces(runs: list[tuple[bool, np.ndarray]], z: np.ndarray, air: np.ndarray,
            pattern: str) -> list[tuple[bool, bool, np.ndarray]]:
    """(is_link, detached, points) in cutting order. A pass is split where it crosses air; a zig-zag link
    that crosses air is left out. `detached`: the tool gets there by retract, rapid and plunge."""
    out: list[tuple[bool, bool, np.ndarray]] = []
    detach = True
    k = 0
    for is_link, xy in runs:
        pts, gap = np.column_stack([xy, z[k:k + len(xy)]]), air[k:k + len(xy)]
        k += len(xy)
        if is_link:
            if gap.any():
                detach = True
            elif len(pts):
                out.append((True, detach, pts))
                detach = False
            continue
        if pattern == ONEWAY:
            detach = True
        # consecutive on-model points: [start, end) index pairs
        edges = np.flatnonzero(np.diff(np.concatenate([[True], gap, [True]]).astype(np.int8)))
        for start, end in zip(edges[::2], edges[1::2]):
            out.append((False, detach or start > 0, pts[start:end]))
            detach = False
        if len(gap) and gap[-1]:
            detach = True
    return out


def _link(pieces: list[tuple[bool, bool, np.ndarray]], params: SurfaceParams) -> Toolpath:
    tp = Toolpath()
    for is_link, detached, pts in pieces:
        if not is_link:
            pts = _drop_collinear(pts)
        plunged = False
        if not tp.moves or detached:
            x0, y0, z0 = pts[0]
            if tp.moves:  # lift straight up, cross over at the safe height
                last = tp.moves[-1]
                tp.add(MoveKind.RAPID, last.x, last.y, params.safe_height)
            else:
                tp.add(MoveKind.RAPID, x0, y0, params.clearance_height)
            tp.add(MoveKind.RAPID, x0, y0, params.safe_height)
            tp.add(MoveKind.PLUNGE, x0, y0, z0)
            plunged = True
        for p in pts[1:] if plunged else pts:
            tp.add(MoveKind.FEED, *p)
    last = tp.moves[-1]
    tp.add(MoveKind.RAPID, last.x, last.y, params.clearance_height)
    return tp


def _drop_collinear(pts: np.ndarray) -> np.ndarray:
    """Remove interior points lying on the chord of their neighbours (flat stretches)."""
    if len(pts) < 3:
        return pts
    a, p, c = pts[:-2], pts[1:-1], pts[2:]
    ac = c - a
    ap = p - a
    cross = np.linalg.norm(np.cross(ac, ap), axis=1)
    dist = cross / np.maximum(np.linalg.norm(ac, axis=1), 1e-300)
    keep = np.concatenate([[True], dist > _COLLINEAR_MM, [True]])
    return pts[keep]
