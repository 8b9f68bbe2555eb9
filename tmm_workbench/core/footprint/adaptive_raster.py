"""Adaptive raster (seed 000 section 3.5.2.2): each pass placed from the real cutter positions of
the previous one, so that the largest cusp between the two is the tolerance.

The seed intersects the cutter's section with the surface's section at each CC point (eq. 3.54-3.58) and takes
the smallest step along the pass. Here the cusp is measured on the tool positions themselves: the previous pass
and a candidate next pass are dropped exactly at the same x; in sections across the passes through every CL
point, each pass's lower surface is the least over its instances that reach the section (the neighbours along
the pass count: where the surface slopes along it, a bull-nose's flat bottom above all, they reach lower than the
instance in the section). The two passes leave H; a dense raster of the same tool between them leaves the
reachable envelope E. The cusp is the largest H - E along E's normal (vertical x cos(slope across)), solved
exactly at each section's ridge (where the two passes' surfaces cross). So curvature and the real tool count,
and material no spacing could remove (a concave corner narrower than the tool: pencil or a smaller tool's work)
does not drive the step; it is counted as `unreachable`. The step is the largest with that cusp at most the
tolerance (a few evaluations: the cusp grows about as the step squared). The dense raster leaves cusps of its
own, about (1/8)^2 of the measured one: the aim is 5 % under the tolerance. Checked against the stock
simulation in tests/core/test_adaptive_raster.py.

Where the tool cannot keep the cusp, the step does not shrink to nothing: steep places (slope across the passes
above `max_slope_deg`) are not measured (walls are waterline's), and the step never goes below half the
constant-mode step at `max_slope_deg` (core.footprint.cusp); gaps that still exceed the cusp there are counted
as `limited`. Passes run along `angle_deg` from +X; the work is done in a frame turned so that they run along +X'
(the cutter is a solid of revolution: its drop does not change when the mesh turns about Z).

The kernel (native.adaptive_raster, native/src/algo/adaptive_raster.cpp) places the passes. Its slow numpy
reference, the same samples, bracket and search step for step, is test code: tests/core/adaptive_raster_reference.py
(compared in tests/core/test_adaptive_raster.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.raster import Rect
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import FIX, native
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
ROUNDS = 6  # step evaluations per pass (secant on sqrt(cusp) with a bracket): the work estimate counts them


@dataclass
class AdaptivePasses:
    offsets: np.ndarray                  # (k,) across-offsets of the passes (along the raster's normal), mm
    cusps: np.ndarray                    # (k - 1,) measured cusp between consecutive passes, mm
    limited: int = 0                     # gaps at the smallest allowed step whose cusp still exceeds it
    unreachable: int = 0                 # gaps with places the tool cannot bring within the cusp (not measured)
    evaluations: int = 0                 # candidate passes dropped and simulated


class Frame:
    """The raster's frame: x' along the passes, y' across them (the raster_lines offsets), z up."""

    def __init__(self, angle_deg: float) -> None:
        a = math.radians(angle_deg)
        self.d = np.array([math.cos(a), math.sin(a)])
        self.n = np.array([-math.sin(a), math.cos(a)])
        self.rot = np.array([[self.d[0], self.d[1], 0.0], [self.n[0], self.n[1], 0.0], [0.0, 0.0, 1.0]])

    def mesh(self, mesh: TriMesh) -> TriMesh:
        return TriMesh(mesh.vertices @ self.rot.T, mesh.triangles, mesh.name)


@dataclass
class Placement:
    """What a placement starts from (the kernel's, and the test reference's): the raster's frame, the drop
    surface of the mesh turned into it, the boundary's extent across the passes and the step's bounds."""
    frame: Frame
    surface: DropSurface
    lo: float       # mm, the first pass's across-offset
    hi: float       # mm, the last pass's
    s_min: float    # mm, the smallest step: half the constant-mode step at the slope limit
    s_max: float    # mm, the largest: the step on a flat, below the tool's diameter


def placement(mesh: TriMesh, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float, sample_step: float,
              max_slope_deg: float) -> Placement:
    """The checked start of a placement (slope limit, work estimate; TmmError when either is out of bounds)."""
    if not (math.isfinite(max_slope_deg) and 0 < max_slope_deg < 90):
        raise TmmError(f"adaptive slope limit must be in (0, 90) deg, got {max_slope_deg!r}")
    frame = Frame(angle_deg)
    corners = np.array([[boundary[0], boundary[1]], [boundary[2], boundary[1]], [boundary[2], boundary[3]],
                        [boundary[0], boundary[3]]])
    across = corners @ frame.n
    lo, hi = float(across.min()), float(across.max())
    s_max = min(2 * cutter.native.max_radius * 0.98, stepover_for_cusp(cutter, cusp, 0.0))
    s_min = 0.5 * stepover_for_cusp(cutter, cusp, max_slope_deg)
    length = float(np.ptp(corners @ frame.d))
    passes_most = (hi - lo) / s_min + 2
    check_work("CL points", passes_most * (length / sample_step + 2) * (ROUNDS + 1), 400,
               f"cusp height {cusp:g} mm (smallest adaptive step {s_min:.3g} mm) and sample step "
               f"{sample_step:g} mm over a {hi - lo:.6g} mm wide boundary")
    return Placement(frame, DropSurface(frame.mesh(mesh)), lo, hi, s_min, s_max)


def adaptive_pass_offsets(mesh: TriMesh, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float,
                          sample_step: float, floor_z: float, stock_to_leave: float = 0.0,
                          max_slope_deg: float = 75.0, progress: Optional[Progress] = None) -> AdaptivePasses:
    """The across-offsets of raster passes over `boundary` (as core.footprint.raster.raster_lines places them:
    the first and last on the boundary's edges) with at most `cusp` mm between neighbours (see the module),
    placed by the kernel (native.adaptive_raster)."""
    p = placement(mesh, cutter, boundary, angle_deg, cusp, sample_step, max_slope_deg)
    return _kernel_offsets(p.surface, cutter, boundary, angle_deg, cusp, sample_step, floor_z, stock_to_leave,
                           max_slope_deg, p.s_min, p.s_max, progress)


def _kernel_offsets(surface: DropSurface, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float,
                    sample_step: float, floor_z: float, stock_to_leave: float, max_slope_deg: float, s_min: float,
                    s_max: float, progress: Optional[Progress]) -> AdaptivePasses:
    """The same placement in the kernel (native/src/algo/adaptive_raster.cpp): `surface` holds the turned mesh."""
    if not hasattr(native, "adaptive_raster"):  # a kernel built before the placement moved into it
        raise TmmError(f"the kernel has no adaptive_raster: rebuild it (`{FIX}` in the TMM folder)")
    o = native.AdaptiveRasterOptions()
    o.xmin, o.ymin, o.xmax, o.ymax = (float(v) for v in boundary)
    o.angle, o.max_slope = math.radians(angle_deg), math.radians(max_slope_deg)
    o.cusp, o.sample_step, o.floor_z, o.stock_to_leave = cusp, sample_step, floor_z, stock_to_leave
    o.step_min, o.step_max = s_min, s_max
    try:
        offsets, cusps, info = native.adaptive_raster(surface.index, cutter.offset(stock_to_leave).native,
                                                      cutter.native, o, progress=progress)
    except native.Cancelled as exc:
        raise Cancelled("tool path computation cancelled") from exc
    except ValueError as exc:
        raise TmmError(f"adaptive raster: {exc}") from exc
    return AdaptivePasses(offsets, cusps, info["limited"], info["unreachable"], info["evaluations"])
