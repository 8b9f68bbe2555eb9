"""The adaptive raster's pass placement in numpy: the slow reference the kernel's placement
(native.adaptive_raster, called by core.footprint.adaptive_raster) is tested against in
tests/core/test_adaptive_raster.py, the same samples, bracket and search step for step (the method: that
module's docstring). Test code, not part of the add-on; benchmarks swap it into the Surface's pattern stage
(core.strategies.surface.pattern.adaptive_pass_offsets) to time the two.
"""
from __future__ import annotations

import math
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import Cancelled
from tmm_workbench.core.footprint.adaptive_raster import ROUNDS as _ROUNDS
from tmm_workbench.core.footprint.adaptive_raster import AdaptivePasses, Progress, placement
from tmm_workbench.core.footprint.cusp import profile_height
from tmm_workbench.core.footprint.raster import Rect, clip_line_to_rect, sample_segment
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.tools.cutter import Cutter

_SAFETY = 0.95        # aim a little under the tolerance: cells sample the ridge, they never overshoot it
_SPACING = 0.05       # mm between samples across a section (the ridge itself is solved exactly)
_RIDGE_HALVINGS = 12  # the ridge within a sample spacing: 0.05 / 4096 mm


def adaptive_pass_offsets(mesh: TriMesh, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float,
                          sample_step: float, floor_z: float, stock_to_leave: float = 0.0,
                          max_slope_deg: float = 75.0, progress: Optional[Progress] = None) -> AdaptivePasses:
    """What core.footprint.adaptive_raster.adaptive_pass_offsets returns (same arguments), computed in numpy."""
    p = placement(mesh, cutter, boundary, angle_deg, cusp, sample_step, max_slope_deg)
    frame, surface, lo, hi, s_min, s_max = p.frame, p.surface, p.lo, p.hi, p.s_min, p.s_max
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
