"""Clean-up strips (seed 000 section 3.6): where the finishing tool bridged a concave crease or a groove, found as
the seed finds them, thinned into curves, and the clean-up tool's CL points found by translating it along a vector
towards the crease (eq. 3.126-3.188, the kernel's drop along a direction).

Recognition (eq. 3.125). Along the finishing tool's paths (here its drop at every cell of a grid, read along the
grid's rows, columns and diagonals: core.footprint.pencil.STEPS) the normal of the CL surface is the normal of the
design at the contact (the tool's configuration obstacle is the design swept by the tool: their normals agree), so
the jump of the contact normal between neighbouring contacts is the jump of the CL surface's slope. The seed sets
its threshold by hand; here it is derived: a tool whose corner has radius r (a ball: its radius) that bridges a
crease whose flanks' normals differ by theta touches both flanks and leaves the corner r (sec(theta / 2) - 1) deep
(along the bisector); that exceeds the tolerance tol when theta > 2 arccos(r / (r + tol)) (jump_limit). Where the
jump is larger, the cells between the two contacts (P1, P2 in the seed's Figure 3-31) are the strip; a kink that
falls between two grid points is caught by the jump of the slopes two steps either side. The strip is joined with
the rest cells (the cells the finishing tool could not reach: core.footprint.rest), and thinned into its medial
curves (the ridges of the distance to its edge, core.footprint.pencil.valley_curves) with their short branches
(into a strip's corners: a groove's sloped ends).

CL points by translation. At each point of a strip curve, across it, the clean-up tool slides from the point down
the flank it stands on (a vertical tool: the slope of its CL surface behind the point; 0 on a floor: horizontal)
until it touches the other flank: the kernel's exact drop along that vector (core.query.drop_direction). The XY
found is where the tool touches both flanks; the path's CL height there is the ordinary vertical drop (which also
guards the shank). For a vertical tool the translation reaches no position the vertical drop could not, on a part
without undercuts: what it adds is the place of the fold across the crease to the kernel's precision, from a strip
point anywhere on the approach side, instead of a grid cell's. It matters where the CL surface's fold is a cliff:
a steep wall meeting a floor (a cell's error on the floor side leaves a sliver on the wall's foot, on the wall side
lifts the tool off the floor by the cell times the wall's slope). In a groove symmetric about the strip curve the
slide is nil: the vertical drop there already touches both flanks; a point within a probe of such a fold is put
at its bottom (the lowest vertical drop across it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import pencil
from tmm_workbench.core.footprint.rest import without_specks
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_direction import DirectionalDrop
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.tools.cutter import Cutter

LIFT = 1e-3            # mm: the slide starts this far above the flank (a grazing line is ill-conditioned)
ANGLE_BIN = math.radians(1.0)   # slide directions within a degree share one directional index of the mesh
FLAT = 1e-4          # a slope below this (on either side of a strip point) is a floor: the slide goes both ways
OFF_MODEL = 1.0        # mm below the model's lowest point: the finishing tool's drop there is off the model
BRANCH = 3             # cells: a short medial curve this near a longer one is its branch, a shorter one a speck
FOLD_STEPS = 30         # golden-section steps placing a point in its fold (0.618^30 of the bracket: 1e-7 mm)


def jump_limit(cutter: Cutter, tolerance: float) -> float:
    """The normal jump (rad) between neighbouring contacts above which the corner the `cutter` leaves bridging a
    crease stands more than `tolerance` out: 2 arccos(r / (r + tol)), r its corner radius (see the module)."""
    if not (math.isfinite(tolerance) and tolerance > 0):
        raise TmmError(f"clean-up tolerance must be a length > 0 mm, got {tolerance!r}")
    r = cutter.radius if cutter.is_plain and cutter.corner_radius >= cutter.radius - 1e-12 else cutter.corner_radius
    if not r > 0:
        raise TmmError(f"clean-up: the finishing tool {cutter.describe()} has no corner radius: the strips are "
                       f"recognised for a ball or a bull nose finish (a corner radius > 0 mm)")
    return 2.0 * math.acos(r / (r + tolerance))


def _contact_offset(cutter: Cutter, g: np.ndarray) -> np.ndarray:
    """Horizontal offset (along the path) of the contact from the tip where the CL section's slope is g: the
    corner circle's point whose normal is (-g, 1) (a ball: r g / sqrt(1 + g^2); a bull adds the ring radius)."""
    r = cutter.corner_radius if cutter.corner_radius > 0 else cutter.radius
    ring = max(cutter.radius - r, 0.0)
    return ring * np.sign(g) + r * g / np.sqrt(1.0 + g * g)


@dataclass
class Strips:
    grid: Grid
    jumps: np.ndarray      # (ny, nx) cells between two contacts whose normals jump more than the limit
    rest: np.ndarray       # (ny, nx) the rest cells joined to them
    mask: np.ndarray       # the strip cells: both, without specks
    limit: float           # rad, the derived threshold
    curves: list           # the strips' medial curves, XY (n, 2)

    def summary(self) -> str:
        a = self.grid.cell_area
        return (f"clean-up strips {self.mask.sum() * a:.0f} mm2 ({self.jumps.sum() * a:.0f} mm2 by the normal jump "
                f"> {math.degrees(self.limit):.1f} deg, {self.rest.sum() * a:.0f} mm2 of rest cells), "
                f"{len(self.curves)} curve(s)")

    def length(self) -> float:
        """mm: the curves' total length."""
        return sum(pencil.curve_length(c) for c in self.curves)


def normal_jumps(z: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per grid point of the CL heights `z`: the largest concave jump (rad) of the section's normal across it over
    the directions of pencil.STEPS (the slopes of the steps before and after it, or of the steps two away: a kink
    between grid points), the direction index, and the slopes before and after that gave it. 0 at the border."""
    ny, nx = z.shape
    best = np.zeros((ny, nx))
    along = np.zeros((ny, nx), dtype=int)
    g0, g1 = np.zeros((ny, nx)), np.zeros((ny, nx))
    inner = (slice(2, ny - 2), slice(2, nx - 2))
    near = {k: (b, a) for k, b, a in pencil.neighbours(z, 1)}
    for k, far_b, far_a in pencil.neighbours(z, 2):
        h = cell * math.hypot(*pencil.STEPS[k])
        b, a = (x[1:-1, 1:-1] for x in near[k])
        c = z[inner]
        for before, after in (((c - b) / h, (a - c) / h), ((b - far_b) / h, (far_a - a) / h)):
            theta = np.arctan(after) - np.arctan(before)
            win = theta > best[inner]
            best[inner] = np.where(win, theta, best[inner])
            along[inner] = np.where(win, k, along[inner])
            g0[inner] = np.where(win, before, g0[inner])
            g1[inner] = np.where(win, after, g1[inner])
    return best, along, g0, g1


def jump_cells(z: np.ndarray, grid: Grid, cutter: Cutter, limit: float, on_model: np.ndarray) -> np.ndarray:
    """(ny, nx) the cells between the two contacts wherever the normal jumps more than `limit` (the finishing
    tool's CL heights `z` on the grid's centres; `on_model`: where it and its neighbours touch the model)."""
    theta, along, g0, g1 = normal_jumps(z, grid.cell)
    jj, ii = np.nonzero((theta > limit) & on_model)
    out = np.zeros_like(on_model)
    if not len(jj):
        return out
    steps = np.array(pencil.STEPS, dtype=float)[along[jj, ii]]
    u = steps / np.linalg.norm(steps, axis=1)[:, None]
    p = np.column_stack([grid.xs()[ii], grid.ys()[jj]])
    a = p + _contact_offset(cutter, g0[jj, ii])[:, None] * u
    b = p + _contact_offset(cutter, g1[jj, ii])[:, None] * u
    n = int(math.ceil(2.0 * cutter.radius / (0.5 * grid.cell))) + 2
    t = np.linspace(0.0, 1.0, n)
    pts = (a[:, None, :] * (1 - t)[None, :, None] + b[:, None, :] * t[None, :, None]).reshape(-1, 2)
    i = np.floor((pts[:, 0] - grid.x0) / grid.cell).astype(int)
    j = np.floor((pts[:, 1] - grid.y0) / grid.cell).astype(int)
    ok = (i >= 0) & (i < grid.nx) & (j >= 0) & (j < grid.ny)
    out[j[ok], i[ok]] = True
    return out


def strips(mesh: TriMesh, surface: DropSurface, finishing: Cutter, grid: Grid, design: np.ndarray,
           rest_cells: Optional[np.ndarray], tolerance: float, min_length: float) -> Strips:
    """The clean-up strips on `grid` (see the module): the cells between contacts of the `finishing` tool whose
    normals jump more than the derived limit, joined with `rest_cells` ((ny, nx) or None), over the design
    (`design` finite), thinned into curves at least `min_length` long."""
    limit = jump_limit(finishing, tolerance)
    floor = float(mesh.vertices[:, 2].min()) - OFF_MODEL
    z = surface.drop(finishing, grid.centres(), floor).reshape(grid.ny, grid.nx)
    touching = z > floor + 1e-9
    on_model = touching.copy()
    for _, b, a in pencil.neighbours(touching.astype(np.int8), 2):
        on_model[2:-2, 2:-2] &= (b > 0) & (a > 0)
    has_design = np.isfinite(design)
    jumps = jump_cells(z, grid, finishing, limit, on_model) & has_design
    rest = (np.zeros_like(jumps) if rest_cells is None else np.asarray(rest_cells, dtype=bool)) & has_design
    mask = without_specks(jumps | rest)
    return Strips(grid, jumps, rest, mask, limit, medial_curves(mask, grid, min_length))


def medial_curves(mask: np.ndarray, grid: Grid, min_length: float) -> list[np.ndarray]:
    """The mask's medial curves: the ridges of the distance to its edge (pencil.valley_curves of its negative),
    those at least `min_length` long and the shorter branches of them (a curve whose end lies within BRANCH cells
    of a longer one): where a strip ends in a corner (the sloped end of a groove meeting its flanks), its medial
    axis forks towards the corner in branches shorter than the tool, along the creases only they lead to."""
    if not mask.any():
        return []
    from scipy import ndimage

    dist = ndimage.distance_transform_edt(np.pad(mask, 1))[1:-1, 1:-1] * grid.cell
    found = pencil.valley_curves(grid.xs(), grid.ys(), -dist, 0.25 * grid.cell, BRANCH * grid.cell, within=mask,
                                 strict=True)
    long = [c for c in found if pencil.curve_length(c) >= min_length]
    if not long:
        return []
    trunk = np.vstack(long)
    def gap(p: np.ndarray) -> float:
        return float(np.hypot(*(trunk - p).T).min())

    branches = [c for c in found if pencil.curve_length(c) < min_length
                and min(gap(c[0]), gap(c[-1])) <= BRANCH * grid.cell]
    return long + branches


def _across(curve: np.ndarray) -> np.ndarray:
    """(n, 2) unit normals of an XY polyline (its tangent turned a quarter left)."""
    closed = len(curve) > 3 and np.allclose(curve[0], curve[-1])
    if closed:
        t = np.roll(curve[:-1], -1, axis=0) - np.roll(curve[:-1], 1, axis=0)
        t = np.vstack([t, t[:1]])
    else:
        t = np.gradient(curve, axis=0)
    n = np.column_stack([-t[:, 1], t[:, 0]])
    length = np.linalg.norm(n, axis=1)
    return n / np.where(length > 0, length, 1.0)[:, None]


@dataclass
class Slide:
    """The translation of each strip point towards its crease: the XY where the tool touches the far flank."""
    xy: np.ndarray          # (n, 2) the CL points' XY after the slide
    moved: np.ndarray       # (n,) how far in XY each moved (0: kept)
    direction: np.ndarray   # (n, 3) the slide's unit vector (0: none)
    folded: Optional[np.ndarray] = None   # (n,) placed at the bottom of the fold they stood within a probe of

    def missed(self) -> np.ndarray:
        """The points that found no crease: neither slid to a far flank nor placed in a fold."""
        folded = np.zeros(len(self.xy), dtype=bool) if self.folded is None else self.folded
        return ~folded & ~self.direction.any(axis=1)


@dataclass
class CleanupReport:
    """What the clean-up found and did, for the op's report: its strips, their curves' slide, the flank passes."""
    strips: Strips
    slide: Slide
    passes: int

    def summary(self) -> str:
        n, missed = len(self.slide.xy), int(self.slide.missed().sum())
        text = (f"{self.strips.summary()} {self.strips.length():.0f} mm long; {n - missed} of {n} curve points placed in their "
                f"crease, {self.passes} flank pass(es)")
        if missed:
            text += f"; {missed} found no crease within reach (cut where they stand)"
        return text


def slide_to_crease(mesh: TriMesh, surface: DropSurface, cutter: Cutter, points: np.ndarray, across: np.ndarray,
                    floor_z: float, reach: float, probe: Optional[float] = None) -> Slide:
    """Each XY point (n, 2) moved across (its unit XY normal `across`) to where `cutter` (vertical axis), slid down
    the flank it stands on, touches the other flank (see the module): the kernel's drop along that vector, from a
    `probe` behind the point (default a twentieth of the diameter), at most `reach` mm. A point already at the
    fold within a probe (both sides higher) is moved to the lowest vertical drop between its probes (_fold_bottom):
    there a tool a few hundredths off the fold stands on one flank and is lifted off the other by that times their
    slope. A slide blocked before the point or touching nothing within reach keeps its XY."""
    a = probe if probe is not None else 0.05 * cutter.diameter
    n = len(points)
    offs = np.array([0.0, -1.0, 1.0])
    probes = (points[:, None, :] + offs[None, :, None] * a * across[:, None, :]).reshape(-1, 2)
    z0, zm, zp = surface.drop(cutter, probes, floor_z).reshape(n, 3).T
    flat = np.abs(zp - zm) <= FLAT * a
    at_fold = (zm > z0 + FLAT * a) & (zp > z0 + FLAT * a)      # both sides higher: the tool is in the fold
    xy, moved, direction = points.copy(), np.full(n, np.inf), np.zeros((n, 3))
    length = _slide_length(mesh, cutter)
    tri = Triangles(mesh)
    for s in (1.0, -1.0):   # downhill; on a floor both ways, the nearer contact kept
        todo = np.flatnonzero(~at_fold & (flat | ((zp < zm) == (s > 0))))
        behind = np.where(s > 0, zm, zp)
        g = np.where(flat, 0.0, (z0 - behind) / a)   # the flank's slope along s * across (<= 0 going down)
        v = np.column_stack([s * across, g])
        v /= np.linalg.norm(v, axis=1)[:, None]
        back = a * np.sqrt(1.0 + g * g)
        start = np.column_stack([points, z0 + LIFT]) - back[:, None] * v   # from the probe behind
        for rows in _by_direction(v, todo):
            travel = _slide(tri, cutter, start[rows], v[rows], back[rows] + reach, length)
            ok = (travel > back[rows] + 1e-9) & (travel < back[rows] + reach)
            r, t = rows[ok], travel[ok]
            to = (start[r] + t[:, None] * v[r])[:, :2]
            d = np.linalg.norm(to - points[r], axis=1)
            nearer = d < moved[r]
            r, to, d = r[nearer], to[nearer], d[nearer]
            xy[r], moved[r], direction[r] = to, d, v[r]
    moved[~np.isfinite(moved)] = 0.0
    # each point (slid or not) in a fold within a probe: to the fold's bottom
    z0, zm, zp = surface.drop(cutter, (xy[:, None, :] + offs[None, :, None] * a * across[:, None, :]).reshape(-1, 2),
                              floor_z).reshape(n, 3).T
    fold = np.flatnonzero((zm > z0 + FLAT * a) & (zp > z0 + FLAT * a))
    t = _fold_bottom(surface, cutter, xy[fold], across[fold], a, floor_z)
    xy[fold] += t[:, None] * across[fold]
    moved[fold] = np.linalg.norm(xy[fold] - points[fold], axis=1)
    folded = np.zeros(n, dtype=bool)
    folded[fold] = True
    return Slide(xy, moved, direction, folded)


def _fold_bottom(surface: DropSurface, cutter: Cutter, points: np.ndarray, across: np.ndarray, a: float,
                 floor_z: float) -> np.ndarray:
    """Offsets t in (-a, a) along `across` of the lowest vertical drop near each point (both probes a away stand
    higher: the fold is bracketed), by golden-section search (one drop per point and step)."""
    lo, hi = np.full(len(points), -a), np.full(len(points), a)
    if not len(points):
        return lo
    k = (math.sqrt(5.0) - 1.0) / 2.0

    def z_at(t: np.ndarray) -> np.ndarray:
        return surface.drop(cutter, points + t[:, None] * across, floor_z)

    c, d = hi - k * (hi - lo), lo + k * (hi - lo)
    zc, zd = z_at(c), z_at(d)
    for _ in range(FOLD_STEPS):
        left = zc <= zd                       # the bottom lies in (lo, d): d becomes hi, c the new d
        lo, hi = np.where(left, lo, c), np.where(left, d, hi)
        new = np.where(left, hi - k * (hi - lo), lo + k * (hi - lo))
        z_new = z_at(new)
        c, d, zc, zd = (np.where(left, new, d), np.where(left, c, new), np.where(left, z_new, zd),
                        np.where(left, zc, z_new))
    return 0.5 * (lo + hi)


def _slide_length(mesh: TriMesh, cutter: Cutter) -> Cutter:
    """The cutter with a cutting length for a drop across its axis (a plain one has none): its own, or the
    model's height and a diameter (the part above that never meets the model; the CL height is the vertical
    drop's, which guards the shank)."""
    if math.isfinite(cutter.cutting_length):
        return cutter
    lo, hi = mesh.bounds
    return Cutter(cutter.diameter, cutter.corner_radius, cutting_length=float(hi[2] - lo[2]) + cutter.diameter)


def _by_direction(v: np.ndarray, rows: np.ndarray) -> list[np.ndarray]:
    """The rows grouped by their slide direction rounded to ANGLE_BIN (azimuth and tilt)."""
    if not len(rows):
        return []
    az = np.round(np.arctan2(v[rows, 1], v[rows, 0]) / ANGLE_BIN).astype(int)
    tilt = np.round(np.arcsin(np.clip(v[rows, 2], -1, 1)) / ANGLE_BIN).astype(int)
    keys = az * 100_000 + tilt
    return [rows[keys == k] for k in np.unique(keys)]


class Triangles:
    """The mesh's triangles' corners and XY bounds, gathered once for all the slides' groups."""

    def __init__(self, mesh: TriMesh) -> None:
        self.mesh = mesh
        self.corners = mesh.vertices[mesh.triangles]               # (m, 3, 3)
        self.lo, self.hi = self.corners[:, :, :2].min(axis=1), self.corners[:, :, :2].max(axis=1)


def _slide(tri: Triangles, cutter: Cutter, starts: np.ndarray, v: np.ndarray, most: np.ndarray,
           cutter_l: Cutter) -> np.ndarray:
    """Travel of each start along the group's common direction (their mean, rounded within ANGLE_BIN) until the
    tool touches; only triangles that can lie ahead of the starts take part (the kernel's drop comes from
    infinitely far behind: what lies behind the start is not in the way of a slide from it)."""
    d = v.mean(axis=0)
    d /= np.linalg.norm(d)
    lo = starts[:, :2].min(axis=0) - most.max() - cutter.diameter
    hi = starts[:, :2].max(axis=0) + most.max() + cutter.diameter
    near = np.flatnonzero((tri.hi >= lo).all(axis=1) & (tri.lo <= hi).all(axis=1))
    keep = near[(tri.corners[near] @ d).max(axis=1) >= (starts @ d).min() - cutter.diameter]
    if not len(keep):
        return np.full(len(starts), np.inf)
    mesh = tri.mesh
    part = TriMesh(mesh.vertices, mesh.triangles[keep], mesh.name)
    travel, _ = DirectionalDrop(part, d).drop(cutter_l, starts, np.array([0.0, 0.0, 1.0]), float(most.max()))
    return travel


def cleanup_curves(mesh: TriMesh, surface: DropSurface, cutter: Cutter, found: Strips, floor_z: float,
                   reach: float, step: float) -> tuple[list[np.ndarray], Slide]:
    """The strips' curves sampled `step` apart with each point slid to its crease (slide_to_crease), smoothed
    along the curve as the pencil's creases are; and the slide of all their points (for the report)."""
    curves = pencil.sampled(found.curves, step)
    if not curves:
        return [], Slide(np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3)))
    pts = np.vstack(curves)
    normals = np.vstack([_across(c) for c in curves])
    slide = slide_to_crease(mesh, surface, cutter, pts, normals, floor_z, reach)
    out, k = [], 0
    for c in curves:
        out.append(slide.xy[k:k + len(c)])
        k += len(c)
    return out, slide


def flank_passes(surface: DropSurface, cutter: Cutter, curves: list[np.ndarray], floor_z: float, step: float,
                 passes: int, inside: Optional[tuple[Grid, np.ndarray]] = None) -> list[np.ndarray]:
    """Passes up each flank of each crease curve (its points at the fold): on each side, `passes` curves whose
    points walk out across the crease, each XY step `step` cos(a)^1.5 with tan(a) the steepest slope of the CL
    surface (the design's at the contact) the exact drop finds just ahead, across and along the curve: the passes
    step at most sqrt(cos a) along the surface, which keeps the cusp's height measured vertically (as the rest and
    the simulation measure it) to the planar step's; close on a steep wall, wide on a floor. (The slope across alone
    under-reads a flank that falls along the curve too, as a groove's sloped end does by its branch.) Cut where they leave the strip (`inside`: a grid and its mask),
    kept as runs of two points or more; innermost first."""
    out: list[np.ndarray] = []
    if not curves or passes < 1:
        return out
    pts = np.vstack(curves)
    across = np.vstack([_across(c) for c in curves])
    along = np.column_stack([across[:, 1], -across[:, 0]])
    ends = np.cumsum([len(c) for c in curves])[:-1]
    a = 0.05 * cutter.diameter
    for side in (1.0, -1.0):
        pos, alive = pts.copy(), np.ones(len(pts), dtype=bool)
        for _ in range(passes):
            probes = np.vstack([pos, pos + side * a * across, pos + a * along])
            z = surface.drop(cutter, probes, floor_z).reshape(3, -1)
            slope2 = ((z[1] - z[0]) ** 2 + (z[2] - z[0]) ** 2) / (a * a)   # the steepest slope's, squared
            pos = pos + side * (step * (1.0 + slope2) ** -0.75)[:, None] * across
            if inside is not None:
                alive &= _in_mask(pos, *inside)
            for c, ok in zip(np.split(pos, ends), np.split(alive, ends)):
                out += [c[r] for r in _runs(ok) if len(r) >= 2]
            if not alive.any():
                break
    return out


def _in_mask(xy: np.ndarray, grid: Grid, mask: np.ndarray) -> np.ndarray:
    i = np.floor((xy[:, 0] - grid.x0) / grid.cell).astype(int)
    j = np.floor((xy[:, 1] - grid.y0) / grid.cell).astype(int)
    ok = (i >= 0) & (i < grid.nx) & (j >= 0) & (j < grid.ny)
    out = np.zeros(len(xy), dtype=bool)
    out[ok] = mask[j[ok], i[ok]]
    return out


def _runs(ok: np.ndarray) -> list[np.ndarray]:
    """Index runs of consecutive True."""
    idx = np.flatnonzero(ok)
    if not len(idx):
        return []
    return np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
