"""Step-over from a cusp height (constant mode), for any APT cutter of revolution.

Parallel passes `s` apart (horizontally) over a plane that rises at `slope` across them leave ridges (cusps)
between neighbouring tool instances. Along a pass the tool moves horizontally and the plane does not change,
so in the section across the passes each instance is its profile h(|u|) standing on the plane: relative to
the plane, instance k leaves
    g(u) = h(|u|) - u tan(slope) - min_v [h(|v|) - v tan(slope)],   u = y - k s, |u| <= max radius,
and the surface left is min_k g(y - k s). Its largest value over a period is the vertical cusp; times
cos(slope) it is the cusp along the plane's normal, the usual scallop height (a ball gives the classic
R - sqrt(R^2 - (s / (2 cos slope))^2), a bull-nose on a level plane 2 (R - r) + 2 sqrt(2 r h - h^2) for s).
This is exact for any convex profile (the kernel's h(rho): ball, flat, bull-nose, cones and tapers); the
cusp on a curved surface differs by the curvature, which is why the adaptive raster measures it on the real
cutter positions instead (seed 000 section 3.5.2.2).

Constant mode keeps the cusp everywhere: the planar step-over for the steepest crossing of the region was its
rule; it undershoots where the surface bends across the passes (seed 000's concave window: 0.0606 mm against
0.0508), so the mode now takes the worst crossing's slope and curvature on sampled CL sections
(core.footprint.cusp_section), with this module's planar step reported beside it.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.raster import Rect
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import FINEST_MM
from tmm_workbench.core.tools.cutter import Cutter

MIN_CUSP = FINEST_MM  # the least cusp height asked for (a cusp of 1e-8 mm is lost in the profile's rounding)
_SAMPLES = 2048          # profile samples across the tool, and cusp samples across one period
_BISECTIONS = 48         # step-over bisection: far below a micrometre of step-over


def _profile(cutter: Cutter) -> tuple[np.ndarray, np.ndarray]:
    """u in [-Rmax, Rmax] and h(|u|), dense (the cusp's accuracy is the sampling's, refined at the ridge)."""
    r_max = cutter.native.max_radius
    u = np.linspace(-r_max, r_max, 2 * _SAMPLES + 1)
    return u, np.asarray(cutter.native.height(np.abs(u)))


def profile_height(cutter: Cutter, u: np.ndarray) -> np.ndarray:
    """h(|u|) of the cutter, inf beyond its widest radius (its side wall)."""
    r_max = cutter.native.max_radius
    out = np.full(u.shape, np.inf)
    inside = np.abs(u) <= r_max
    out[inside] = cutter.native.height(np.abs(u[inside]))
    return out


def _golden_min(f, a: float, b: float, best: float) -> float:
    """The least of `best` and f's minimum on [a, b] by golden section (f unimodal there)."""
    g = (math.sqrt(5) - 1) / 2
    for _ in range(45):  # 0.618^45 ~ 4e-10 of the bracket
        c, d = b - g * (b - a), a + g * (b - a)
        if f(c) <= f(d):
            b = d
        else:
            a = c
    return min(best, f((a + b) / 2))


def plane_cusp(cutter: Cutter, stepover: float, slope_deg: float = 0.0) -> float:
    """The cusp (along the plane's normal, mm) between passes `stepover` apart over a plane rising at
    `slope_deg` across them; inf where the tool instances leave a strip uncut between them."""
    if not (math.isfinite(stepover) and stepover > 0):
        raise TmmError(f"step-over must be a positive length, got {stepover!r}")
    if not (math.isfinite(slope_deg) and 0 <= slope_deg < 90):
        raise TmmError(f"slope must be in [0, 90) deg, got {slope_deg!r}")
    r_max = cutter.native.max_radius
    if stepover >= 2 * r_max:
        return math.inf
    t = math.tan(math.radians(slope_deg))
    u, h = _profile(cutter)
    rel = h - u * t
    j = int(np.argmin(rel))
    base = _golden_min(lambda v: float(profile_height(cutter, np.array([v]))[0] - v * t),
                       u[max(j - 1, 0)], u[min(j + 1, len(u) - 1)], float(rel[j]))

    u_low = float(u[j])

    def left(y: np.ndarray, without: int | None = None) -> np.ndarray:
        """The surface left above the plane at y (vertical): the instances that may be lowest there (but
        `without`). h(|u|) - u tan(slope) is convex in u (a convex profile, its wall infinite), so at any y
        the lowest instance is one of the two whose u brackets its minimum u_low: a window of instances
        around it is exact, and its size does not grow as the step-over shrinks (a tiny cusp would
        otherwise ask for every instance within the tool's reach: 131074 of them at a cusp of 1e-8 mm)."""
        k = np.arange(math.floor((float(y.min()) - u_low) / stepover) - 2,
                      math.ceil((float(y.max()) - u_low) / stepover) + 3)
        if without is not None:
            k = k[k != without]
        du = y[:, None] - k[None, :] * stepover
        return (profile_height(cutter, du) - du * t - base).min(axis=1)

    y = np.linspace(0.0, stepover, _SAMPLES + 1)
    values = left(y)
    i = int(np.argmax(values))
    # the ridge is a crossing of two instances: refine around the best sample (golden section on a
    # unimodal neighbourhood; the samples bound the error of the rest)
    best = -_golden_min(lambda v: -float(left(np.array([v]))[0]), y[max(i - 1, 0)], y[min(i + 1, len(y) - 1)],
                        -float(values[i]))
    # Where an instance's side wall (rho = max radius) stands, the surface left jumps: its supremum there is
    # what the other instances leave (the sawtooth of a flat end mill on a slope). Periodic in y: instance
    # 0's two walls stand for every instance's.
    for edge in (-r_max, r_max):
        best = max(best, float(left(np.array([edge]), without=0)[0]))
    return best * math.cos(math.radians(slope_deg))


def check_cusp(cutter: Cutter, cusp: float) -> None:
    """TmmError naming the cusp height unless it lies in [MIN_CUSP, the tool radius]."""
    if not (isinstance(cusp, (int, float)) and math.isfinite(cusp) and MIN_CUSP <= cusp <= cutter.radius):
        shown = f"{cusp:g}" if isinstance(cusp, (int, float)) else repr(cusp)
        raise TmmError(f"cusp height must be in [{MIN_CUSP:g}, {cutter.radius:g}] mm (a machine's resolution to the "
                       f"tool radius), got {shown}")


def stepover_for_cusp(cutter: Cutter, cusp: float, slope_deg: float = 0.0,
                      max_stepover: float | None = None) -> float:
    """The largest step-over (mm, at most `max_stepover`, default the diameter at the widest) whose cusp
    over a plane rising at `slope_deg` across the passes is at most `cusp` mm (along the normal)."""
    if not (math.isfinite(cusp) and 0 < cusp <= cutter.radius):  # a derived cusp (a rule's margin) may be < MIN_CUSP
        raise TmmError(f"cusp height must be in (0, {cutter.radius:g}] mm (the tool radius), got {cusp!r}")
    return _stepover_for_cusp(cutter, float(cusp), float(slope_deg),
                              None if max_stepover is None else float(max_stepover))


@functools.lru_cache(maxsize=4096)
def _stepover_for_cusp(cutter: Cutter, cusp: float, slope_deg: float, max_stepover: float | None) -> float:
    """stepover_for_cusp, remembered: a pure function of its arguments (Cutter is a frozen value), asked again
    and again with the same ones (the section rule's levels at every search, offset3d's slope table)."""
    r_max = cutter.native.max_radius
    hi = 2 * r_max if max_stepover is None else min(float(max_stepover), 2 * r_max)
    if plane_cusp(cutter, hi * (1 - 1e-12), slope_deg) <= cusp:
        return hi
    lo = 0.0
    for _ in range(_BISECTIONS):
        cancel.poll()
        mid = (lo + hi) / 2
        if plane_cusp(cutter, mid, slope_deg) <= cusp:
            lo = mid
        else:
            hi = mid
    if lo <= 0:
        raise TmmError(f"no step-over keeps the cusp at {cusp:g} mm on a {slope_deg:g} deg slope")
    return lo


def steepest_crossing_deg(mesh: TriMesh, boundary: Rect, angle_deg: float, max_slope_deg: float = 89.0) -> float:
    """The steepest slope (deg) across passes at `angle_deg` from +X of the upward-facing triangles that lie
    (by their centroid) in `boundary`, ignoring those steeper than `max_slope_deg` overall (walls: left to
    waterline; a raster cannot keep a cusp there)."""
    v = mesh.vertices[mesh.triangles]
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    length = np.linalg.norm(n, axis=1)
    ok = length > 0
    n = n[ok] / length[ok, None]
    centre = v[ok].mean(axis=1)
    xmin, ymin, xmax, ymax = boundary
    inside = (centre[:, 0] >= xmin) & (centre[:, 0] <= xmax) & (centre[:, 1] >= ymin) & (centre[:, 1] <= ymax)
    up = n[:, 2] > math.cos(math.radians(max_slope_deg))
    n = n[inside & up]
    if not len(n):
        return 0.0
    a = math.radians(angle_deg)
    across = np.abs(n[:, 0] * -math.sin(a) + n[:, 1] * math.cos(a))
    return float(np.degrees(np.arctan2(across, n[:, 2])).max())
