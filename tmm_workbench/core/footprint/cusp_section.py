"""Constant cusp mode that holds the tolerance on curved surfaces.

The planar rule (core.footprint.cusp) keeps the cusp on a plane at the region's steepest crossing; on a surface
that bends across the passes it does not: a concave section of radius rho lifts a ball's cusp by about
rho / (rho - R) (seed 000's concave window: 0.0606 mm against 0.0508). Seed 000 (section 3.5.2.2, eq. 3.54-3.58)
intersects the cutter's section with the surface's section at each CC point; the same exact 2D rule is taken
here on the CL surface itself, which carries the slope AND the curvature across the passes for any cutter:

- a coarse drop grid: sections across the passes (x' fixed, y' every `spacing`), the CL tip heights c(y') of
  the real cutter, and the design (a needle's drop);
- E(y) = min_t c(t) + h(|y - t|) over the section's samples: what a dense raster leaves, the reachable envelope
  (the benchmark's and core.sim.cusp_field's reference, in 2D);
- for a step s, every pair of instances a, b = a + s along the section (every sample a phase: the passes may
  fall anywhere) leaves H = the least of a, b and their outer neighbours a - s, b + s; its cusp is
  (H - E) cos(E's slope) at the ridge (where a's and b's lower surfaces cross, solved exactly: their
  difference only grows across the section for a convex profile) and beyond each side wall (a flat bottom's
  sawtooth, as plane_cusp does);
- ridges steeper than the slope limit (walls: waterline's), off the model, or where E stays farther than the
  cusp from the design (out of the tool's reach: a corner narrower than the tool, pencil work) are not counted,
  as the simulated measure leaves them out;
- the step is the largest with the worst pair's cusp at most the tolerance (bisection), at least half the
  planar step at the slope limit (as the adaptive raster's smallest step); `limited` when even that leaves more;
- every pair is taken both ways, anchored at a sample by its a and by its b (the other end's phase then sweeps
  smoothly with the step), and the step is checked on all pairs, searched again on a growing subset until it
  holds (a free border of the model moves the worst pair with the step);
- a pair above the aim is checked against every pass of its phase within the tool's reach (not only four);
- a second look: sections placed densely between the neighbours of the worst sections (the first ones lie up to
  the region's length / 160 apart), the samples across only near their worst pairs.

The 2D section leaves out the neighbours along a pass (a slope along the pass lowers the swept tool by the same
amount in H and in E, to first order: the planar ball's cusp along the normal is the same). Not at a free border
of the model just above the raster's floor (the passes beyond it roll onto the floor, and the border runs at an
angle to them): there the simulated cusp exceeded the rule's by up to 1.6x on a 30 deg sheet. So the sections
that cross such a border get the swept tool: drops at 0.05, 0.2 and 0.5 R either side along the passes too (H
and E from every offset's instance at its 3D distance), and E there also from instances between the samples,
dropped where the CL section turns (the foot of the roll onto the floor, a corner the samples cut off)
(docs/history/results-log.md, "Constant cusp mode by the section rule", 2026-12-02 cusp4 and cusp5).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core import cancel, polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint.cusp import check_cusp, profile_height, stepover_for_cusp
from tmm_workbench.core.footprint.raster import Rect
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.tools.cutter import Cutter

_SAFETY = 0.97            # aim under the tolerance: E's own cusp (samples `spacing` apart) and cells on the ridge
_SAMPLES_PER_STEP = 8     # samples across per planar step on a level plane
_MIN_SPACING, _MAX_SPACING = 0.02, 0.25   # mm between samples across a section
_SECTIONS_MOST = 160      # sections along the passes (the worst crossing is looked for in as many)
_POINTS_MOST = 400_000    # CL points of the drop grid at most (sections x samples): the section spacing grows
_CREASE_RAD = 0.1         # slope turn (rad) between neighbouring samples beyond which the CL surface has a crease
_RIDGE_HALVINGS = 26      # the ridge within 2 R / 2^26
_STEP_HALVINGS = 18       # the step within (s_max - s_min) / 2^18
_HEAD_PAIRS = 256         # pairs checked first, alone, at each step of the search (the worst at the last)
_SEARCH_ROUNDS = 8        # step searches on growing subsets of the pairs before one on all of them
_AROUND_MOST = 64         # failing pairs whose section neighbours (within a step) join the subset, the worst first
_BYTES_PER_POINT = 200    # the grid's heights, design, envelope and pair arrays per sample
_REFINE_SPOTS = 3         # the worst sections around which sections are placed densely (a second look)
_REFINE_SECTIONS = 24     # sections between a worst section's two neighbours
# the swept tool along a pass at a low free border: drops at these offsets (x R) either side of the section too
_SWEEP = (0.05, 0.2, 0.5)
_SUBSAMPLES = (0.25, 0.5, 0.75)   # E's instances between the samples there (fractions of the spacing)


@dataclass
class SectionStep:
    stepover: float       # mm, the largest step whose worst pair cusp is within the aim
    cusp: float           # mm, that worst cusp (along E's normal)
    planar: float         # mm, the planar rule's step at the steepest crossing (for comparison)
    sections: int         # sections across the passes sampled
    spacing: float        # mm between samples across a section
    limited: bool         # even the smallest allowed step leaves more than the tolerance somewhere
    unreachable: int      # samples on the model where E stays farther than the cusp from the design
    creases: int          # samples on a crease of the CL surface (pairs across one are not measured)


def _section_frame(angle_deg: float) -> tuple[np.ndarray, np.ndarray]:
    a = math.radians(angle_deg)
    return np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])


def section_stepover(mesh: TriMesh, cutter: Cutter, boundary: Rect, angle_deg: float, cusp: float, floor_z: float,
                     stock_to_leave: float = 0.0, max_slope_deg: float = 75.0, planar: Optional[float] = None,
                     surface: Optional[DropSurface] = None, region: Optional[list] = None) -> SectionStep:
    """The constant step-over over `boundary` (passes at `angle_deg` from +X) that keeps the cusp at most `cusp`
    mm at every sampled crossing (see the module). `planar`: the planar rule's step at the steepest crossing,
    reported beside it. `region`: the polygons the passes are clipped to (`boundary` their box): crossings
    counted inside them only, clear of their edge by the tool radius (as the box's edges)."""
    check_cusp(cutter, cusp)
    if not (math.isfinite(max_slope_deg) and 0 < max_slope_deg < 90):
        raise TmmError(f"cusp slope limit must be in (0, 90) deg, got {max_slope_deg!r}")
    d, n = _section_frame(angle_deg)
    corners = np.array([[boundary[0], boundary[1]], [boundary[2], boundary[1]], [boundary[2], boundary[3]],
                        [boundary[0], boundary[3]]])
    along, across = corners @ d, corners @ n
    r_max = cutter.native.max_radius
    s_level = stepover_for_cusp(cutter, cusp, 0.0, 2 * r_max * 0.98)
    s_min = 0.5 * stepover_for_cusp(cutter, cusp, max_slope_deg)
    s_max = min(2 * r_max * 0.98, s_level)   # as the adaptive raster's: no wider than on a level plane (what
    # the samples do not measure, creases and places out of reach, gets no wider step than a plane would)
    spacing = float(np.clip(s_level / _SAMPLES_PER_STEP, _MIN_SPACING, _MAX_SPACING))
    surface = surface or DropSurface(mesh)
    while True:  # samples half a step apart at most: coarser ones misplace b between them (a bull's flat)
        step, spots = _section_step(mesh, cutter, boundary, cusp, floor_z, stock_to_leave, max_slope_deg, planar,
                                    surface, d, n, along, across, s_min, s_max, spacing, region=region)
        if step.stepover >= 2 * spacing or spacing <= _MIN_SPACING:
            break
        spacing = max(_MIN_SPACING, step.stepover / _SAMPLES_PER_STEP)
    # A second look where the first found the worst crossings: the sections lie up to the region's length / 160
    # apart (36 on seed 000's whole surfaces, 7 mm apart: its concave surface's steep end bends along the passes,
    # and the worst crossing fell between two sections: 0.0546 mm simulated at the rule's 0.502 mm, 0.4315 mm with
    # sections 0.4 mm apart there). Around each of the worst sections, sections between its two neighbours, the
    # samples across only near its worst pair (the pair, its outer neighbours and the tool's reach on each side).
    half = 2 * s_max + 2 * r_max
    for x_lo, x_hi, y_at in spots:
        fine, _ = _section_step(mesh, cutter, boundary, cusp, floor_z, stock_to_leave, max_slope_deg, planar,
                                surface, d, n, along, across, s_min, min(s_max, step.stepover), spacing,
                                np.linspace(x_lo, x_hi, _REFINE_SECTIONS), (y_at - half, y_at + half), region)
        if fine.stepover < step.stepover:
            step = SectionStep(fine.stepover, fine.cusp, step.planar, step.sections + fine.sections, spacing,
                               fine.limited, step.unreachable, step.creases)
        else:
            step.sections += fine.sections
    return step


def _section_step(mesh: TriMesh, cutter: Cutter, boundary: Rect, cusp: float, floor_z: float, stock_to_leave: float,
                  max_slope_deg: float, planar: Optional[float], surface: Optional[DropSurface], d: np.ndarray,
                  n: np.ndarray, along: np.ndarray, across: np.ndarray, s_min: float, s_max: float,
                  spacing: float, at_xs: Optional[np.ndarray] = None,
                  window: Optional[tuple[float, float]] = None,
                  region: Optional[list] = None) -> tuple[SectionStep, list[tuple[float, float, float]]]:
    """section_stepover with samples `spacing` apart across the sections (at `at_xs` along the passes if given,
    else spread over the region; only pairs whose a lies in `window` across if given), and the places to look
    at again: (x_lo, x_hi, y) around each of the worst sections (its neighbours' x, its worst pair's a)."""
    r_max = cutter.native.max_radius
    y_lo, y_hi = float(across.min()), float(across.max())
    # the pairs' a: the region, or the window in it; samples: the ridges' reach (R) and E's (R) beyond them
    a_lo, a_hi = (y_lo, y_hi) if window is None else (max(y_lo, window[0]), min(y_hi, window[1]))
    reach_y = r_max if window is None else 2 * r_max
    # samples across, E needs the tool's reach beyond the region: counted before any is made
    samples = (a_hi - a_lo + 2 * reach_y + 3 * spacing) / spacing + 1
    # sections inside the region, clear of the passes' ends by the tool radius (the measured cells' rule)
    x0, x1 = float(along.min()) + cutter.radius, float(along.max()) - cutter.radius
    if x1 <= x0:
        x0 = x1 = 0.5 * float(along.min() + along.max())
    count = max(1, min(_SECTIONS_MOST, int(_POINTS_MOST // samples), int((x1 - x0) / spacing) + 1))
    if at_xs is not None:
        count = len(at_xs)
    check_work("CL points", float(count) * samples, _BYTES_PER_POINT,
               f"cusp height {cusp:g} mm (samples {spacing:.3g} mm apart across the passes) over a "
               f"{y_hi - y_lo:.6g} mm wide boundary")
    ys = np.arange(a_lo - reach_y - spacing, a_hi + reach_y + 2 * spacing, spacing)
    xs = np.asarray(at_xs, dtype=float) if at_xs is not None else (np.linspace(x0, x1, count) if count > 1
                                                                    else np.array([x0]))
    X, Y = np.meshgrid(xs, ys, indexing="ij")                       # (sections, samples)
    world = X[..., None] * d + Y[..., None] * n
    # points of a section outside the boundary (a turned raster over a rectangle) are no part of it
    inside = ((world[..., 0] >= boundary[0] - 1e-9) & (world[..., 0] <= boundary[2] + 1e-9)
              & (world[..., 1] >= boundary[1] - 1e-9) & (world[..., 1] <= boundary[3] + 1e-9))
    surface = surface or DropSurface(mesh)
    xy = world.reshape(-1, 2)
    tool = cutter.offset(stock_to_leave)
    c = np.maximum(surface.drop(tool, xy, floor_z - stock_to_leave) + stock_to_leave, floor_z).reshape(X.shape)
    needle = Cutter.flat(2e-4) if stock_to_leave == 0 else Cutter.ball(2 * stock_to_leave)
    design = surface.drop(needle, xy, floor_z - 1.0) + stock_to_leave
    design = np.where(design > floor_z - 0.5, design, -np.inf).reshape(X.shape)
    # the tool swept along the pass: layers of tips at offsets `shifts` along it (the section's own first); only
    # sections with a low free border get drops of their own (elsewhere a layer repeats the section's tips, which
    # an instance off the section never undercuts)
    shifts, layers, swept = _swept_layers(surface, tool, cutter, world, d, c, design, inside, floor_z, stock_to_leave,
                                   ys, y_lo, y_hi, cusp, spacing)

    # E: every sample an instance of the dense raster (of every layer on the swept sections: the swept tool)
    m = int(math.floor(r_max / spacing))
    envelope = np.full(c.shape, np.inf)
    _envelope_add(envelope, c, cutter, spacing, 0.0, m)
    if len(swept):
        sub = envelope[swept]
        for delta, layer in zip(shifts[1:], layers[1:]):
            _envelope_add(sub, layer[swept], cutter, spacing, delta, m)
        # and from instances between the samples where the CL section turns: the lowest instance on the 30 deg
        # sheet is at the foot of the roll onto the floor, a corner the samples (0.06 mm apart) cut off: E 0.003 mm
        # too high there put its worst cells out of reach
        k_all = np.arange(-m, m + 2)
        for f in _SUBSAMPLES:
            for delta, layer in zip(shifts, layers):
                r_i, j_i, v = _corners(surface, tool, floor_z, stock_to_leave, layer[swept], world[swept],
                                       delta * d + f * spacing * n, spacing)     # at ys[j] + f spacing
                if not len(v):
                    continue
                hk = profile_height(cutter, np.hypot((k_all - f) * spacing, delta))
                k = k_all[np.isfinite(hk)]
                hk = hk[np.isfinite(hk)]
                col = j_i[:, None] + k[None, :]
                ok = (col >= 0) & (col < c.shape[1])
                np.minimum.at(sub, (np.broadcast_to(r_i[:, None], col.shape)[ok], col[ok]),
                              (v[:, None] + hk[None, :])[ok])
        envelope[swept] = sub
    grad = np.gradient(envelope, spacing, axis=1)
    cos = 1.0 / np.sqrt(1.0 + grad * grad)
    on_model = np.isfinite(design)
    # steep as the measured cells are: the full slope, along the passes too (between sections); the cusp itself
    # stays along the across-normal (a ball on a plane sloped along the passes: the section's vertical cusp)
    steep_along = np.gradient(envelope, xs[1] - xs[0], axis=0) if count > 1 else np.zeros(c.shape)
    # out of reach where E stays above the design by more than the cusp, less what a slope along the passes lifts a
    # section's E by (the tool touches ahead of or behind its section there): without it a sphere's flank read as
    # out of reach at a small cusp, its worst crossing was left out and the step widened (ball D6, cusp 0.04 mm on
    # sphere_on_plate: 0.96 mm, 0.064 mm measured; 0.79 mm at a cusp of 0.05)
    # (the design's slope: at the foot of a wall the CL surface climbs along the passes over a flat floor the tool
    # does not reach)
    with np.errstate(invalid="ignore"):
        design_along = np.gradient(design, xs[1] - xs[0], axis=0) if count > 1 else np.zeros(c.shape)
    lift = _along_lift(cutter, np.nan_to_num(design_along, nan=0.0, posinf=0.0, neginf=0.0))
    reach = (envelope - design - lift) * cos <= cusp + stock_to_leave
    full_cos = 1.0 / np.sqrt(1.0 + grad * grad + steep_along * steep_along)
    counted = (inside & on_model & reach & (full_cos >= math.cos(math.radians(max_slope_deg)))
               & (envelope > floor_z + 1e-6))
    unreachable = int((inside & on_model & ~reach).sum())
    # a ridge counts where the measured cells would lie: inside the boundary, clear of its edges by the radius
    core = inside & (Y >= y_lo + cutter.radius) & (Y <= y_hi - cutter.radius)
    counted &= core if core.any() else inside
    if region is not None:
        inner = polygons.offset(region, -cutter.radius)
        counted &= polygons.points_inside(inner, world.reshape(-1, 2)).reshape(c.shape) if inner else False

    def between(y: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where y falls in the raveled fields (sections, samples) of the rows' sections: the sample before it
        and the weight of the one after."""
        f = np.clip((y - ys[0]) / spacing, 0.0, len(ys) - 1.000001)
        i = f.astype(int)
        return rows * len(ys) + i, f - i

    def at(field: np.ndarray, y: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """`field` (sections, samples) linearly between samples at y (the rows' sections)."""
        k, w = between(y, rows)
        flat = field.ravel()
        return flat[k] * (1 - w) + flat[k + 1] * w

    def tips(y: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """(layers, n): the tips of the passes at y (the rows' sections) at each offset along them."""
        k, w = between(y, rows)
        out = np.empty((len(layers), len(k)))
        for layer, row in zip(layers, out):
            flat = layer.ravel()
            np.add(flat[k] * (1 - w), flat[k + 1] * w, out=row)
        return out

    # creases of the CL surface (a concave edge of the model the tool rides across, the foot of a wall): its
    # slope turns by more than _CREASE_RAD from one sample to the next, which the samples cannot resolve (their
    # linear interpolation and E misplace the V by up to a spacing); pairs that span one are not measured here
    # but counted (`creases`)
    turn = np.zeros(c.shape, dtype=bool)
    angle = np.arctan(np.diff(c, axis=1) / spacing)
    turn[:, 1:-1] = np.abs(np.diff(angle, axis=1)) > _CREASE_RAD
    turn &= on_model
    crease_before = np.concatenate([np.zeros((c.shape[0], 1)), np.cumsum(turn, axis=1)], axis=1)  # creases < j

    def creases_between(rows: np.ndarray, y0: np.ndarray, y1: np.ndarray) -> np.ndarray:
        j0 = np.clip(np.floor((y0 - ys[0]) / spacing).astype(int), 0, len(ys))
        j1 = np.clip(np.ceil((y1 - ys[0]) / spacing).astype(int) + 1, 0, len(ys))
        return crease_before[rows, j1] - crease_before[rows, j0]

    a_rows, a_cols = np.nonzero(inside & (Y >= a_lo - 1e-9) & (Y <= a_hi + 1e-9))
    a_y = ys[a_cols]
    c_a = np.stack([layer[a_rows, a_cols] for layer in layers])
    rises = [_least_rise(cutter, delta) for delta in shifts]

    def lower(tip: np.ndarray, axis: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The pass at `axis` (its tips `tip`, one row a layer) at y: the swept tool's lower surface."""
        cancel.poll()
        u = np.broadcast_to(y - axis, tip[0].shape)
        out = tip[0] + profile_height(cutter, u)
        for delta, t, rise in zip(shifts[1:], tip[1:], rises[1:]):
            # an instance delta off the section undercuts the section's only where its tip is lower by more than
            # the least of h(hypot(u, delta)) - h(u) (h(delta) for a ball): most of them are not (the pairs' cost)
            i = np.nonzero(t < tip[0] - rise)[0]
            if len(i):
                out[i] = np.minimum(out[i], t[i] + profile_height(cutter, np.hypot(u[i], delta)))
        return out

    # A side wall makes the surface left jump (the sawtooth of a flat bottom on a slope) only where the profile
    # meets it at a finite slope (flat, cone); a ball's or a torus's wall is vertical: the next instance is
    # always lower there, and the instances that are (many, for a small step) are not in the pair.
    edge = r_max * 1e-3
    rise = profile_height(cutter, np.array([r_max - edge, r_max]))
    walls = float(rise[1] - rise[0]) < 10 * edge

    target = cusp * _SAFETY

    def worst(s: float, rows: np.ndarray, ay: np.ndarray, ca: np.ndarray) -> np.ndarray:
        """The cusp (mm, 0 where not counted) of each pair (ay, ay + s) on its section."""
        cancel.poll()
        by = ay + s
        ok = (ay >= y_lo - 1e-9) & (by <= y_hi + 1e-9) & (creases_between(rows, ay - s, by + s) == 0)
        cb, ca0, cb1 = tips(by, rows), tips(ay - s, rows), tips(by + s, rows)
        # the ridge: a's lower surface minus b's grows with y (convex profile); bracket where both reach
        lo, hi = by - r_max, ay + r_max
        for _ in range(_RIDGE_HALVINGS):
            mid = 0.5 * (lo + hi)
            up = lower(ca, ay, mid) >= lower(cb, by, mid)
            hi = np.where(up, mid, hi)
            lo = np.where(up, lo, mid)
        ridge = 0.5 * (lo + hi)
        out = np.zeros(len(ay))
        eps = 1e-9
        points = [(ridge, ((ca, ay), (cb, by), (ca0, ay - s), (cb1, by + s)))]
        if walls:
            points += [(ay + r_max + eps, ((cb, by), (cb1, by + s))),          # beyond a's wall
                       (by - r_max - eps, ((ca, ay), (ca0, ay - s)))]          # before b's wall
        # the pairs above the aim are checked against every pass of their phase within the tool's reach, not
        # only the four: where the CL surface is much higher than E around them (a groove narrower than the tool
        # beside them, reached from passes farther off; mount_rush: 0.40 mm from the four, none from all)
        over = np.zeros(len(ay), dtype=bool)
        values = []
        for y, parts in points:
            h = np.full(len(ay), np.inf)
            for tip, axis in parts:
                h = np.minimum(h, lower(tip, axis, y))
            col = np.clip(np.round((y - ys[0]) / spacing).astype(int), 0, len(ys) - 1)
            good = ok & counted[rows, col] & np.isfinite(h) & (y >= ys[0]) & (y <= ys[-1])
            with np.errstate(invalid="ignore"):
                e_cos = (at(envelope, y, rows), at(cos, y, rows))
                value = (h - e_cos[0]) * e_cos[1]
            value = np.where(good & np.isfinite(value), value, 0.0)
            values.append((y, h, good, e_cos))
            over |= value > target
            out = np.maximum(out, value)
        if over.any():
            k_most = int(math.ceil(2 * r_max / s)) + 1
            i = np.nonzero(over)[0]
            redo = np.zeros(len(i))
            for y, h, good, (e, cs) in values:
                j = i[good[i]]          # (a pair not counted at this point adds nothing)
                if not len(j):
                    continue
                y, h = y[j], h[j]
                # the passes that reach y at all (a margin of a step for the rounding): the others leave inf
                off = y - ay[j]
                k_lo = max(-k_most, math.floor((float(off.min()) - r_max) / s) - 1)
                k_hi = min(k_most, math.ceil((float(off.max()) + r_max) / s) + 1)
                for k in range(k_lo, k_hi + 1):
                    if k not in (-1, 0, 1, 2):   # a - s, a, b, b + s are in h already
                        axis = ay[j] + k * s
                        h = np.minimum(h, lower(tips(axis, rows[j]), axis, y))
                with np.errstate(invalid="ignore"):
                    v = (h - e[j]) * cs[j]
                redo[good[i]] = np.maximum(redo[good[i]], np.where(np.isfinite(v), v, 0.0))
            out[i] = redo
        return out

    def both(s: float, rows: np.ndarray, ay: np.ndarray, ca: np.ndarray) -> np.ndarray:
        """The worse of the pairs (ay, ay + s) and (ay - s, ay): a pair's cusp may hang on either instance's
        place (b on the foot of the tool's roll over a free border: the last pass beyond it sits on the floor);
        with one end on a sample for every step, the other end's phase sweeps smoothly with the step (with a
        only, the worst pair's b jumped a sample as the step grew: a saw of +-10 % in the worst cusp)."""
        return np.maximum(worst(s, rows, ay, ca), worst(s, rows, ay - s, tips(ay - s, rows)))

    all_rows = a_rows

    def worst_first(mask: np.ndarray) -> np.ndarray:
        """The pairs of `mask`, the worst at the last step checked (`values`) first."""
        pick = np.nonzero(mask)[0]
        return pick[np.argsort(-values[pick], kind="stable")]

    def fits(s: float, pick: np.ndarray) -> bool:
        """Whether none of the pairs `pick` leaves more than the aim at step s: the worst few first, alone, so
        that a step too wide (half the search's) is refused at their cost (the same answer: a pair's cusp is
        its own)."""
        head = max(_HEAD_PAIRS, len(pick) // 32)
        for part in (pick[:head], pick[head:]):
            if len(part) and float(both(s, all_rows[part], a_y[part], c_a[:, part]).max()) > target:
                return False
        return True

    # the worst pairs at one step stay the worst near it: search the step on those, then check all of them. Not
    # always: at a free border of the model the worst pair is the one whose b has just rolled over the edge
    # down onto the floor beyond it (the foot of the roll), a different a for every step (seed 000's whole convex
    # surface: 4 rounds of the old search stopped at 0.636 mm, 0.0656 mm left, `limited`). So the pairs kept grow
    # from round to round: each round adds the pairs worst at its step and, around the worst of those that fail,
    # every pair of their section within one step (where the worst a moves to); the step found on a subset is an
    # upper bound of the answer (a subset leaves at most what all pairs leave), and one that fails bounds the next
    s_try = planar if planar is not None else stepover_for_cusp(cutter, cusp, 0.0, s_max)
    s_try = float(np.clip(s_try, s_min, s_max))
    values = both(s_try, all_rows, a_y, c_a)
    keep = np.zeros(len(values), dtype=bool)
    s_hi = s_max
    for _ in range(_SEARCH_ROUNDS):
        if len(values):
            keep |= (values >= 0.5 * values.max()) if values.max() > 0 else keep
            keep |= values >= np.quantile(values, 0.99)
        s = _largest_step(lambda t, pick=worst_first(keep): fits(t, pick), s_min, s_hi)
        values = both(s, all_rows, a_y, c_a)
        if values.max(initial=0.0) <= target or s <= s_min:
            break
        s_hi = s
        failing = np.argsort(values)[-_AROUND_MOST:]
        keep |= _around(failing[values[failing] > target], all_rows, int(math.ceil(s / spacing)))
    else:  # not settled on the subsets: the same search on every pair (exact; ~20 passes over all of them)
        s = _largest_step(lambda t, pick=worst_first(np.ones(len(values), dtype=bool)): fits(t, pick), s_min, s_hi)
        values = both(s, all_rows, a_y, c_a)
    worst_cusp = float(values.max(initial=0.0))
    # the worst sections at this step (a section's worst pair), to look at again between their neighbours
    spots: list[tuple[float, float, float]] = []
    if count > 2 and len(values):
        per = np.zeros(count)
        np.maximum.at(per, all_rows, values)
        for r in np.argsort(per)[::-1][:_REFINE_SPOTS]:
            if per[r] > 0:
                mine = np.nonzero(all_rows == r)[0]
                spots.append((float(xs[max(r - 1, 0)]), float(xs[min(r + 1, count - 1)]),
                              float(a_y[mine[np.argmax(values[mine])]])))
    return SectionStep(stepover=s, cusp=worst_cusp, planar=float(planar) if planar is not None else math.nan,
                       sections=count, spacing=spacing, limited=worst_cusp > cusp, unreachable=unreachable,
                       creases=int(turn.sum())), spots


def _along_lift(cutter: Cutter, slope: np.ndarray) -> np.ndarray:
    """How far the tip stands above a plane sloped by `slope` (tan) when the tool rests on it: its flat part's
    radius times the slope and its corner's rise (a ball: R (sec - 1); a flat end: r tan)."""
    flat, corner = cutter.radius - cutter.corner_radius, cutter.corner_radius
    t = np.abs(slope)
    return flat * t + corner * (np.sqrt(1.0 + t * t) - 1.0)


def _largest_step(fits, s_min: float, s_max: float) -> float:
    """The largest step in [s_min, s_max] that `fits(step)` (its pairs' worst cusp at most the aim; bisection:
    the worst over all phases grows with the step); s_min when even that leaves more."""
    if fits(s_max):
        return s_max
    if not fits(s_min):
        return s_min
    lo, hi = s_min, s_max
    for _ in range(_STEP_HALVINGS):
        mid = 0.5 * (lo + hi)
        if fits(mid):
            lo = mid
        else:
            hi = mid
    return lo


def _around(pairs: np.ndarray, rows: np.ndarray, reach: int) -> np.ndarray:
    """Mask of the pairs within `reach` samples of `pairs` (indices) on the same section (`rows`: each pair's
    section; a section's pairs are contiguous and in order across it)."""
    mask = np.zeros(len(rows), dtype=bool)
    if not len(pairs):
        return mask
    near = np.clip(pairs[:, None] + np.arange(-reach, reach + 1)[None, :], 0, len(rows) - 1)
    near = near[rows[near] == rows[pairs][:, None]]
    mask[near] = True
    return mask


def _swept_layers(surface: DropSurface, tool: Cutter, cutter: Cutter, world: np.ndarray, d: np.ndarray, c: np.ndarray,
                  design: np.ndarray, inside: np.ndarray, floor_z: float, stock_to_leave: float, ys: np.ndarray,
                  y_lo: float, y_hi: float, cusp: float, spacing: float
                  ) -> tuple[list[float], list[np.ndarray], np.ndarray]:
    """The offsets along the passes (mm, 0 first), the CL tips there (sections, samples) and the swept sections
    (indices). Drops of their own only on the sections that cross a low free border of the model inside the
    region (a sample on the model, its neighbour off it, the design there within the tool's reach of the floor:
    the passes beyond it roll over the edge onto the floor, and as the edge runs at an angle to them, differently
    along the pass; the section's instances alone missed the swept tool's reach there by 0.0046 mm on a 30 deg
    sheet, docs/history/results-log.md). A whole section or none, so that H and E of a pair come from the same tool."""
    r_max = cutter.native.max_radius
    on = np.isfinite(design)
    edge = np.zeros(c.shape, dtype=bool)
    edge[:, :-1] |= on[:, :-1] & ~on[:, 1:]
    edge[:, 1:] |= on[:, 1:] & ~on[:, :-1]
    reach = float(profile_height(cutter, np.array([r_max]))[0]) + cusp + stock_to_leave
    with np.errstate(invalid="ignore"):
        edge &= inside & (design <= floor_z + reach)
    edge &= ((ys >= y_lo + 0.5 * r_max) & (ys <= y_hi - 0.5 * r_max))[None, :]
    rows = np.nonzero(edge.any(axis=1))[0]
    if not len(rows):
        return [0.0], [c], rows
    shifts = [0.0] + [sign * f * r_max for f in _SWEEP for sign in (-1.0, 1.0)]
    check_work("CL points", float(len(rows) * c.shape[1] * (len(shifts) - 1)), _BYTES_PER_POINT,
               f"cusp height {cusp:g} mm (samples {spacing:.3g} mm apart across the passes, the tool swept along "
               f"the passes at {len(rows)} sections with a low free border)")
    layers = [c]
    xy = world[rows].reshape(-1, 2)
    for delta in shifts[1:]:
        layer = c.copy()
        layer[rows] = np.maximum(surface.drop(tool, xy + delta * d, floor_z - stock_to_leave) + stock_to_leave,
                                 floor_z).reshape(len(rows), c.shape[1])
        layers.append(layer)
    return shifts, layers, rows



def _envelope_add(envelope: np.ndarray, tips: np.ndarray, cutter: Cutter, spacing: float, delta: float, m: int) -> None:
    """Lowers `envelope` (sections, samples) by every sample's instance of `tips` (delta off the section along
    the pass) within m samples across."""
    for k in range(-m, m + 1):
        hk = float(profile_height(cutter, np.array([math.hypot(k * spacing, delta)]))[0])
        if not math.isfinite(hk):
            continue
        if k >= 0:
            np.minimum(envelope[:, k:], tips[:, :tips.shape[1] - k] + hk, out=envelope[:, k:])
        else:
            np.minimum(envelope[:, :k], tips[:, -k:] + hk, out=envelope[:, :k])


def _corners(surface: DropSurface, tool: Cutter, floor_z: float, stock_to_leave: float, c: np.ndarray,
             world: np.ndarray, shift: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The tips between the samples where c turns by more than _CREASE_RAD at either end (the foot of a slope on
    the floor: a corner the chord cuts off), dropped at `shift` from their left sample (`world`: the samples'
    XY): their section (row), left sample and height."""
    angle = np.arctan(np.diff(c, axis=1) / spacing)
    turn = np.zeros(c.shape, dtype=bool)
    turn[:, 1:-1] = np.abs(np.diff(angle, axis=1)) > _CREASE_RAD
    rows, cols = np.nonzero(turn[:, :-1] | turn[:, 1:])
    if not len(rows):
        return rows, cols, np.zeros(0)
    check_work("CL points", float(len(rows)), _BYTES_PER_POINT, "cusp height: corners of the CL sections")
    xy = world[rows, cols] + shift
    return rows, cols, np.maximum(surface.drop(tool, xy, floor_z - stock_to_leave) + stock_to_leave, floor_z)


def _least_rise(cutter: Cutter, delta: float) -> float:
    """min over u of h(hypot(u, delta)) - h(u), where both are on the tool (a little under it: the samples)."""
    if delta == 0:
        return 0.0
    r_max = cutter.native.max_radius
    u = np.linspace(0.0, r_max, 257)
    rise = profile_height(cutter, np.hypot(u, delta)) - profile_height(cutter, u)
    rise = rise[np.isfinite(rise)]
    return max(0.0, float(rise.min()) - 1e-9) if len(rise) else 0.0
