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

The kernel's port (native.adaptive_raster, native/src/algo/adaptive_raster.cpp) does the work when the kernel
has it: the same samples, bracket and search, tens of times faster. This module's numpy code stays as the slow
reference it is tested against (`reference=True`; tests/core/test_adaptive_raster.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.cusp import profile_height, stepover_for_cusp
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import native
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter

Progress = Callable[[float], bool]
_SAFETY = 0.95        # aim a little under the tolerance: cells sample the ridge, they never overshoot it
_ROUNDS = 6           # step evaluations per pass (secant on sqrt(cusp) with a bracket)
_SPACING = 0.05       # mm between samples across a section (the ridge itself is solved exactly)
_RIDGE_HALVINGS = 12  # the ridge within a sample spacing: 0.05 / 4096 mm


@dataclass
class AdaptivePasses:
    offsets: np.ndarray                  # (k,) across-offsets of the passes (along the raster's normal), mm
    cusps: np.ndarray                    # (k - 1,) measured cusp between consecutive passes, mm
    limited: int = 0                     # gaps at the smallest allowed step whose cusp still exceeds it
    unreachable: int = 0                 # gaps with places the tool cannot bring within the cusp (not measured)
    evaluations: int = 0                 # candidate passes dropped and simulated


class _Frame:
    """The raster's frame: x' along the passes, y' across them (the raster_lines offsets), z up."""

    def __init__(self, angle_deg: float) -> None:
        a = math.radians(angle_deg)
        self.d = np.array([math.cos(a), math.sin(a)])
        self.n = np.array([-math.sin(a), math.cos(a)])
        self.rot = np.array([[self.d[0], self.d[1], 0.0], [self.n[0], self.n[1], 0.0], [0.0, 0.0, 1.0]])

    def mesh(self, mesh: TriMesh) -> TriMesh:
        return TriMesh(mesh.vertices @ self.rot.T, mesh.triangles, mesh.name)


def adaptive_pass_offsets(mesh: TriMesh, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float,
                          sample_step: float, floor_z: float, stock_to_leave: float = 0.0,
                          max_slope_deg: float = 75.0, progress: Optional[Progress] = None,
                          reference: bool = False) -> AdaptivePasses:
    """The across-offsets of raster passes over `boundary` (as core.footprint.raster.raster_lines places them:
    the first and last on the boundary's edges) with at most `cusp` mm between neighbours (see the module).
    The kernel's port (native.adaptive_raster) does the work when the kernel has it; `reference` runs this
    module's numpy code instead, the slow reference the kernel is tested against."""
    if not (math.isfinite(max_slope_deg) and 0 < max_slope_deg < 90):
        raise TmmError(f"adaptive slope limit must be in (0, 90) deg, got {max_slope_deg!r}")
    frame = _Frame(angle_deg)
    corners = np.array([[boundary[0], boundary[1]], [boundary[2], boundary[1]], [boundary[2], boundary[3]],
                        [boundary[0], boundary[3]]])
    across = corners @ frame.n
    lo, hi = float(across.min()), float(across.max())
    s_max = min(2 * cutter.native.max_radius * 0.98, stepover_for_cusp(cutter, cusp, 0.0))
    s_min = 0.5 * stepover_for_cusp(cutter, cusp, max_slope_deg)
    length = float(np.ptp(corners @ frame.d))
    passes_most = (hi - lo) / s_min + 2
    check_work("CL points", passes_most * (length / sample_step + 2) * (_ROUNDS + 1), 400,
               f"cusp height {cusp:g} mm (smallest adaptive step {s_min:.3g} mm) and sample step "
               f"{sample_step:g} mm over a {hi - lo:.6g} mm wide boundary")
    turned = frame.mesh(mesh)
    surface = DropSurface(turned)
    if not reference and hasattr(native, "adaptive_raster"):
        return _kernel_offsets(surface, cutter, boundary, angle_deg, cusp, sample_step, floor_z, stock_to_leave,
                               max_slope_deg, s_min, s_max, progress)
    needle = Cutter.flat(2e-4) if stock_to_leave == 0 else Cutter.ball(2 * stock_to_leave)
    tool = cutter.offset(stock_to_leave)

    def line(offset: float) -> Optional[np.ndarray]:
        """The pass at `offset` in the turned frame: (m, 3) CL points, or None outside the boundary."""
        seg = clip_line_to_rect(offset * frame.n, frame.d, boundary)
        if seg is None:
            return None
        xy = sample_segment(seg[0] @ np.vstack([frame.d, frame.n]).T, seg[1] @ np.vstack([frame.d, frame.n]).T,
                            sample_step)
        z = surface.drop(tool, xy, floor_z - stock_to_leave) + stock_to_leave
        return np.column_stack([xy, np.maximum(z, floor_z)])

    r_max = cutter.native.max_radius
    dense = 8              # envelope passes between two passes: their own cusps are about 1/64 of it
    # every instance along a pass that reaches a section shapes it (where the surface slopes along the pass a
    # neighbour's lower surface, a bull-nose's flat bottom above all, reaches lower there than the instance in
    # it); sections every quarter tool radius along the pass keep that affordable
    reach = math.ceil(r_max / sample_step - 1e-9)
    reach_along = np.arange(-reach, reach + 1)
    every = 1

    def drop_at(xs: np.ndarray, y: np.ndarray) -> np.ndarray:
        """CL tip heights at the points (xs[i], y[k]) as (len(y), len(xs))."""
        xy = np.column_stack([np.tile(xs, len(y)), np.repeat(y, len(xs))])
        z = surface.drop(tool, xy, floor_z - stock_to_leave) + stock_to_leave
        return np.maximum(z, floor_z).reshape(len(y), len(xs))

    class Strip:
        """Sections across the passes through pass a's CL points. A candidate next pass b is dropped at the
        same x; the two passes leave H, a dense raster of the same tool from a to b leaves the reachable
        envelope E (material no spacing removes, e.g. a concave corner narrower than the tool, is no cusp;
        beyond the two passes' contacts H = E). In a section a pass's lower surface is that of its instance
        there and of its neighbours along the pass. The cusp is the largest H - E along E's normal; at each
        section's ridge (where a's and b's surfaces cross) it is solved exactly, not sampled."""

        def __init__(self, a: np.ndarray) -> None:
            n = len(a)
            self.x, self.za, self.y0 = a[:, 0], a[:, 2], float(a[0, 1])
            x0, x1 = float(self.x.min()), float(self.x.max())
            keep = np.zeros(n, dtype=bool)
            keep[::every] = True
            if x1 - x0 > 4 * r_max:  # pass ends: the tool's round end leaves material no next pass changes
                keep &= (self.x >= x0 + r_max) & (self.x <= x1 - r_max)
            self.sections = np.flatnonzero(keep)
            self.near = np.clip(self.sections[:, None] + reach_along[None, :], 0, n - 1)   # (S, K)
            self.dx = self.x[self.near] - self.x[self.sections][:, None]
            # the design (the surface offset by the stock to leave): where even the dense raster stays farther
            # from it than the cusp, the tool cannot reach (a concave corner, a crease of the CL surface:
            # pencil work), and no cusp is measured
            self.ys = np.arange(self.y0 - r_max, self.y0 + s_max + r_max + _SPACING, _SPACING)
            xs = self.x[self.sections]
            xy = np.column_stack([np.tile(xs, len(self.ys)), np.repeat(self.ys, len(xs))])
            d = surface.drop(needle, xy, floor_z - 1.0) + stock_to_leave
            self.design = np.where(d > floor_z - 0.5, d, -np.inf).reshape(len(self.ys), len(xs)).T

        def surface_of(self, z: np.ndarray, y_c: float, ys: np.ndarray, per_section: bool = False) -> np.ndarray:
            """(S, len(ys)) or (S,) for ys (S,): the lower surface in the sections of the pass y = y_c whose CL
            tip heights along a's x are z (inf where no instance reaches); per_section: ys holds one y per section."""
            zz = z[self.near]                                                  # (S, K)
            if not per_section:  # a row of y for every section
                rho = np.sqrt(self.dx[:, :, None] ** 2 + (ys - y_c)[None, None, :] ** 2)
                return (zz[:, :, None] + profile_height(cutter, rho)).min(axis=1)
            rho = np.sqrt(self.dx ** 2 + (ys - y_c)[:, None] ** 2)             # one y per section
            return (zz + profile_height(cutter, rho)).min(axis=1)

        def cusp(self, y1: float) -> float:
            if not len(self.sections):
                return 0.0
            ys = self.ys[self.ys <= y1 + r_max + _SPACING]
            fractions = np.arange(1, dense) / dense
            z = drop_at(self.x, np.concatenate([self.y0 + (y1 - self.y0) * fractions, [y1]]))
            pa, pb = self.surface_of(self.za, self.y0, ys), self.surface_of(z[-1], y1, ys)
            both = np.minimum(pa, pb)
            envelope = both
            for k, f in enumerate(fractions):
                envelope = np.minimum(envelope, self.surface_of(z[k], self.y0 + (y1 - self.y0) * f, ys))
            finite = np.isfinite(envelope)
            grad = np.gradient(np.where(finite, envelope, floor_z), _SPACING, axis=1)
            cos = 1.0 / np.sqrt(1.0 + grad * grad)
            ok = finite & (envelope > floor_z + 1e-6) & (cos >= math.cos(math.radians(max_slope_deg)))
            design = self.design[:, :len(ys)]
            reached = (envelope - design) * cos <= cusp
            # out of reach only between the two passes' contacts (where each touches the design: its least
            # height above it): before a's contact the material is the previous pass's, which the strip leaves
            # out (on a slope across the passes a ball touches R sin(slope) uphill of its axis)
            ya = ys[np.argmin(np.where(np.isfinite(pa) & np.isfinite(design), pa - design, np.inf), axis=1)]
            yb = ys[np.argmin(np.where(np.isfinite(pb) & np.isfinite(design), pb - design, np.inf), axis=1)]
            between = (ys[None, :] >= ya[:, None]) & (ys[None, :] <= yb[:, None])
            self.unreachable = bool((ok & ~reached & between).any())
            ok &= reached
            with np.errstate(invalid="ignore"):
                best = float(np.where(ok, (both - envelope) * cos, 0.0).max())
            # each section's ridge, where a's and b's surfaces cross
            # a's surface minus b's only grows across the sections (the profile is convex), so the ridge is
            # bracketed on the samples (the last where a's is the lower; on a slope the ridge lies beyond the
            # passes, where their contacts are), then halved
            below = (pa <= pb) & np.isfinite(pa)
            last = np.where(below.any(axis=1), ys.size - 1 - np.argmax(below[:, ::-1], axis=1), 0)
            lo_y, hi_y = ys[last], ys[np.minimum(last + 1, ys.size - 1)]
            for _ in range(_RIDGE_HALVINGS):
                mid = 0.5 * (lo_y + hi_y)
                up = self.surface_of(self.za, self.y0, mid, True) >= self.surface_of(z[-1], y1, mid, True)
                hi_y = np.where(up, mid, hi_y)
                lo_y = np.where(up, lo_y, mid)
            ridge = 0.5 * (lo_y + hi_y)
            h_ridge = np.minimum(self.surface_of(self.za, self.y0, ridge, True), self.surface_of(z[-1], y1, ridge, True))
            e_ridge = h_ridge.copy()
            for k, f in enumerate(fractions):
                e_ridge = np.minimum(e_ridge, self.surface_of(z[k], self.y0 + (y1 - self.y0) * f, ridge, True))
            col = np.clip(np.round((ridge - ys[0]) / _SPACING).astype(int), 0, len(ys) - 1)
            rows = np.arange(len(self.sections))
            with np.errstate(invalid="ignore"):
                at = ok[rows, col] & np.isfinite(h_ridge) & np.isfinite(e_ridge)
                if at.any():
                    best = max(best, float(((h_ridge - e_ridge) * cos[rows, col])[at].max()))
            return best

    offsets = [lo]
    cusps: list[float] = []
    out = AdaptivePasses(np.zeros(0), np.zeros(0))
    prev = line(lo)
    step = s_max
    while offsets[-1] < hi - 1e-9:
        if progress is not None and progress((offsets[-1] - lo) / (hi - lo)) is False:
            raise Cancelled("tool path computation cancelled")
        base = offsets[-1]
        if prev is None:  # the boundary's corner: nothing to measure against
            nxt = min(hi, base + s_min)
            offsets.append(nxt)
            prev = line(nxt)
            continue
        target = cusp * _SAFETY
        room = hi - base
        strip = Strip(prev)
        good, bad = 0.0, math.inf  # the largest step known within the cusp, the smallest known above it
        good_c = None
        s = min(step * 1.2, s_max, room)
        for _ in range(_ROUNDS):
            out.evaluations += 1
            c = strip.cusp(base + s)
            if c <= target:
                good, good_c = s, c
            else:
                bad = s
            if good >= min(s_max, room) - 1e-12 or bad <= s_min * (1 + 1e-9) or bad - good < 0.02 * bad:
                break
            # the cusp grows about as the step squared: aim at the target, inside the bracket
            guess = s * math.sqrt(target / c) * (0.99 if c > target else 1.0) if c > 1e-12 else 2 * s
            if not good < guess < bad:
                guess = 0.5 * (good + bad) if math.isfinite(bad) else 2 * s
            s = max(s_min, min(guess, s_max, room))
        if good_c is None:  # no step within the cusp yet: from the smallest allowed one, halve the bracket
            good = min(s_min, room)
            good_c = strip.cusp(base + good)
            out.evaluations += 1
            if good_c > cusp:
                out.limited += 1  # even the smallest step leaves more: keep it and say so
            else:
                for _ in range(_ROUNDS):
                    if not math.isfinite(bad) or bad - good < 0.02 * bad:
                        break
                    mid = 0.5 * (good + bad)
                    c = strip.cusp(base + mid)
                    out.evaluations += 1
                    if c <= target:
                        good, good_c = mid, c
                    else:
                        bad = mid
        out.unreachable += int(getattr(strip, "unreachable", False))
        offsets.append(base + good)
        cusps.append(good_c)
        prev, step = line(base + good), good
    out.offsets = np.array(offsets)
    out.cusps = np.array(cusps)
    return out


def _kernel_offsets(surface: DropSurface, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float,
                    sample_step: float, floor_z: float, stock_to_leave: float, max_slope_deg: float, s_min: float,
                    s_max: float, progress: Optional[Progress]) -> AdaptivePasses:
    """The same placement in the kernel (native/src/algo/adaptive_raster.cpp): `surface` holds the turned mesh."""
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
