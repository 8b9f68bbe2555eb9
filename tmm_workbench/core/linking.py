"""The one linker: cut segments (core.segments) -> a tool path, by a policy.

Between segments the tool either stays down (a segment `joined` to the previous one: a zig-zag link the
strategy made of dropped, gouge-free points, then the next pass) or leaves and re-enters:
  retract VERTICAL (3-axis): straight up to the safe height, a rapid across, the entry down;
  retract ALONG_AXIS (5-axis): back along the tool axis by `axis_retract` (the segment's own, else the
      policy's; fed: the tilted tool moves sideways too, through what may still be stock), straight up to
      the transit height (the lowest point of the tilted tool at the safe height), a rapid across with the
      tool already turned, down (fed, as everything below the safe height) to `axis_retract` above the next
      first point on its axis, the entry along it.
Entries (3-axis), rows of ENTRIES; a segment may name its own (CutSegment.entry), else the policy's:
  PLUNGE  straight down at the vertical feed onto the first tip;
  HELIX   down a helix at `ramp_angle_deg` on the circle about `helix_centre` through the first tip, from where
          the material starts (CutSegment.entry_z; else the policy's `material_top` over the helix; else the
          safe height), ending with one full circle at its depth (a flat bottom), at the first tip;
  RAMP    the same, down along the segment's own path at `ramp_angle_deg`: backwards around a closed loop
          (`closed`) from its first tip, back and forth along an open one, ending at the first tip.
Where the material's top over the entry is known (the segment's `entry_z`, the policy's `material_top`: the
lower of the two, both being upper bounds), the tool rapids down to `entry_clearance` above it (or above where
the entry starts, if higher) and is fed only from there, as a machinist does: a plunge from the safe height
through the air earlier cuts left costs most of a finishing op's time. Unknown: fed from the safe height.
A StockHeights as the material top (the stock earlier ops left, as heights) is cut by each segment as it is
linked, so later entries also see what the op's own earlier passes removed.
Helix and ramp are only as gouge-free as the XY they pass over: the strategy gives a centre whose circle
lies where the tool centre may go at the first tip's height and above (the linker does not see the model).
The path starts at the clearance height over the first entry (5-axis: upright, then turned there) and
ends at the clearance height (5-axis: upright again, so any later op starts untilted).
The FEED moves through a segment's tips keep its arcs (CutSegment.arcs -> Move.arc): the move into its first
tip only when the segment is joined (otherwise the entry reaches that tip).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core.cancel import poll
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.limits import check_work
from tmm_workbench.core.params import Spec, check
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.toolpath import MoveKind, Toolpath, Z_AXIS

VERTICAL, ALONG_AXIS = "vertical", "along_axis"
PLUNGE, HELIX, RAMP = "plunge", "helix", "ramp"
Axis = tuple[float, float, float]
# xy (n, 2) -> (n,): the lowest tip height at which the tool clears the material over each XY (the tool dropped
# onto what is left; -inf where there is none, +inf where it is not known)
MaterialTop = Callable[[np.ndarray], np.ndarray]
# A ramp or helix flatter than 0.5 deg is cutting at depth (115 mm of travel per mm of descent); one steeper than
# 45 deg is a plunge (the ops feed such descents at the vertical feed): the entries' range, for every op.
RAMP_ANGLE = Spec("ramp angle", "deg", low=0.5, high=45.0)
# A rapid ends this far above the known material top: 0.1 mm covers the machine's following error, and more
# than 50 mm is no longer an approach.
ENTRY_CLEARANCE = Spec("entry clearance", "mm", low=0.1, high=50.0)
_BYTES_PER_ENTRY_POINT = 64   # a descent's point: numpy, moves


@dataclass
class LinkPolicy:
    safe_height: float                  # mm: rapid moves between segments happen at or above it
    clearance_height: float             # mm: start and end height
    retract: str = VERTICAL             # VERTICAL or ALONG_AXIS
    axis_retract: float = 5.0           # ALONG_AXIS: entry and exit distance along the tool axis, mm
    entry: str = PLUNGE                 # a key of ENTRIES
    # ALONG_AXIS: how far the lowest point of the tool lies below its tip for a tool axis (tool geometry:
    # core.tools.Cutter.lowest_below_tip); the transit height keeps that point at the safe height.
    lowest_below_tip: Optional[Callable[[Axis], float]] = None
    ramp_angle_deg: float = 3.0         # HELIX and RAMP: descent angle from the horizontal (RAMP_ANGLE)
    arc_tol: float = 0.01               # HELIX: chord deviation of the helix from its circle, mm
    entry_clearance: float = 1.0        # mm above the known material top where the rapid down ends
    material_top: Optional[MaterialTop] = None   # 3-axis: what earlier ops left (None: unknown)
    # 3-axis with a material top: hop from one segment to the next just above the material between them (a rapid
    # at entry_clearance over the highest of it along the way) when that is below the safe height
    low_links: bool = False
    # low links with a tool assembly: whether the hop's straight move ((2, 3): its two ends at its height) keeps the
    # shank and holder clear of the model (beyond the tool's reach a wall may rise above them; None: not checked)
    hop_clear: Optional[Callable[[np.ndarray], bool]] = None

    def validate(self) -> None:
        check(Spec("safe height", "mm"), self.safe_height)
        check(Spec("clearance height", "mm"), self.clearance_height)
        check(Spec("axis retract", "mm", low=0, kind="length"), self.axis_retract)
        if self.clearance_height < self.safe_height:
            raise TmmError(f"clearance height {self.clearance_height:g} mm is below the safe height "
                           f"{self.safe_height:g} mm")
        if self.retract not in (VERTICAL, ALONG_AXIS):
            raise TmmError(f"retract must be '{VERTICAL}' or '{ALONG_AXIS}', got {self.retract!r}")
        if self.entry not in ENTRIES:
            raise TmmError(f"entry must be one of {', '.join(ENTRIES)}, got {self.entry!r}")
        check(RAMP_ANGLE, self.ramp_angle_deg)
        check(ENTRY_CLEARANCE, self.entry_clearance)
        check(Spec("arc tolerance", "mm", low=0, low_open=True, kind="length"), self.arc_tol)
        if self.retract == ALONG_AXIS and self.entry != PLUNGE:
            raise TmmError(f"entry {self.entry!r} is 3-axis only; linking along the tool axis enters by "
                           f"'{PLUNGE}'")


# An entry: the fed descent (k, 3) from where it begins (its first point: the XY the tool comes down at,
# at the height where the material starts) to the segment's first tip (its last point, exactly).
def _plunge(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    return seg.tips[:1].copy()


def _top(seg: CutSegment, policy: LinkPolicy) -> float:
    """Where the entry starts cutting: the material's top (entry_z) if below the safe height."""
    top = policy.safe_height if seg.entry_z is None else min(float(seg.entry_z), policy.safe_height)
    return top


def _helix(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    end = seg.tips[0]
    if seg.helix_centre is None:
        raise TmmError("a helix entry needs the helix centre of its segment (CutSegment.helix_centre)")
    c = np.asarray(seg.helix_centre, dtype=float)
    r = float(np.hypot(*(end[:2] - c)))
    if not r > 1e-9:
        raise TmmError(f"helix entry at ({end[0]:g}, {end[1]:g}): the first tip lies on the helix centre")
    drop = _top(seg, policy) - float(end[2])
    sense = 1.0 if seg.helix_ccw else -1.0
    dt = 2.0 * math.acos(1.0 - policy.arc_tol / r) if policy.arc_tol < r else math.pi / 4
    t_end = math.atan2(end[1] - c[1], end[0] - c[0])
    pieces = []
    if drop > 0:
        sweep = drop / math.tan(math.radians(policy.ramp_angle_deg)) / r
        _check_entry(math.ceil(sweep / dt) + 1, policy,
                     f"on a helix of diameter {2 * r:.3g} mm over a {drop:.3g} mm descent")
        f = np.linspace(0.0, 1.0, max(2, math.ceil(sweep / dt) + 1))
        t = t_end - sense * sweep * (1.0 - f)
        pieces.append(np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t), end[2] + drop * (1.0 - f)]))
    f = np.linspace(0.0, 1.0, max(4, math.ceil(2 * math.pi / dt) + 1))[1 if pieces else 0:]
    t = t_end + sense * 2 * math.pi * f                    # the full circle at depth: a flat bottom
    pieces.append(np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t), np.full(len(t), end[2])]))
    out = np.vstack(pieces)
    out[-1] = end
    return out


def _walk(xy: np.ndarray, length: float) -> np.ndarray:
    """The polyline through `xy` (in that order, repeated as given by the caller) cut at `length` mm."""
    d = np.hypot(*np.diff(xy, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(d)])
    k = int(np.searchsorted(s, length))
    if k >= len(xy):
        return xy
    w = (length - s[k - 1]) / d[k - 1] if d[k - 1] > 0 else 0.0
    return np.vstack([xy[:k], xy[k - 1] + w * (xy[k] - xy[k - 1])])


def _ramp(seg: CutSegment, policy: LinkPolicy) -> np.ndarray:
    tips = seg.tips
    end = tips[0]
    drop = _top(seg, policy) - float(end[2])
    if drop <= 0:
        return tips[:1].copy()
    length = drop / math.tan(math.radians(policy.ramp_angle_deg))
    xy = tips[:, :2]
    if seg.closed:
        loop = np.vstack([xy[:1], xy[::-1]])               # backwards from the first tip round to it
        per = float(np.hypot(*np.diff(loop, axis=0).T).sum())
        if not per > 0:
            raise TmmError(f"ramp entry at ({end[0]:g}, {end[1]:g}): the loop has no length to ramp along")
        turns = math.ceil(length / per) + 1
        _check_entry(turns * len(loop), policy, f"along a loop of {per:.3g} mm over a {drop:.3g} mm descent")
        back = _walk(np.vstack([loop[:1]] + [loop[1:]] * turns), length)
        path = back[::-1]
    else:
        there = np.vstack([xy, xy[-2::-1]])                 # out and back along the pass
        per = float(np.hypot(*np.diff(there, axis=0).T).sum())
        if not per > 0:
            raise TmmError(f"ramp entry at ({end[0]:g}, {end[1]:g}): the pass has no length to ramp along")
        turns = math.ceil(length / per) + 1
        _check_entry(turns * len(there), policy, f"along a pass of {per / 2:.3g} mm over a {drop:.3g} mm descent")
        out = _walk(np.vstack([there[:1]] + [there[1:]] * turns), length / 2)
        path = np.vstack([out, out[-2::-1]])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
    z = float(end[2]) + drop * (1.0 - s / s[-1])
    ramp = np.column_stack([path, z])
    ramp[-1] = end
    return ramp


ENTRIES: dict[str, Callable[[CutSegment, LinkPolicy], np.ndarray]] = {PLUNGE: _plunge, HELIX: _helix,
                                                                      RAMP: _ramp}


def _check_entry(count: int, policy: LinkPolicy, where: str) -> None:
    """One descent's points against the work limits before they are made (a flat angle on a small circle)."""
    check_work("entry points", count, _BYTES_PER_ENTRY_POINT, f"ramp angle {policy.ramp_angle_deg:g} deg {where}")


def _descent(seg: CutSegment, policy: LinkPolicy, name: str) -> np.ndarray:
    """The entry's fed descent; a helix or ramp without the segment's entry_z starts where the policy's material
    top over its whole path lies (found on the descent from the safe height), if that is lower."""
    make = ENTRIES[name]
    descent = make(seg, policy)
    if len(descent) == 1 or seg.entry_z is not None or policy.material_top is None:
        return descent
    top = float(np.max(policy.material_top(descent[:, :2])))
    if not top < _top(seg, policy):                       # none lower known (or NaN)
        return descent
    return make(dataclasses.replace(seg, entry_z=max(top, float(seg.tips[0, 2]))), policy)


def _known_top(seg: CutSegment, policy: LinkPolicy, x: float, y: float, plunge: bool = False) -> Optional[float]:
    """The material's top over the entry at (x, y): the lower of the segment's entry_z and the policy's
    material_top (each an upper bound; a `plunge` onto the segment's first tip: what stands off the design, see
    _approach); -inf: none there; None: not known."""
    tops = [] if seg.entry_z is None else [float(seg.entry_z)]
    if policy.material_top is not None:
        top = policy.material_top
        if plunge:
            top = getattr(top, "above_design", top)
        tops.append(float(np.max(top(np.array([[x, y]], dtype=float)))))
    top = min(tops, default=math.inf)
    return None if math.isnan(top) or top == math.inf else top


def _approach(tp: Toolpath, seg: CutSegment, policy: LinkPolicy, descent: np.ndarray) -> float:
    """Rapids down from the safe height to `entry_clearance` above the known material top at the descent's start
    (or above the start, when higher); the height reached. Straight down onto the first tip (a plunge), what
    stands off the design is the top where the material top knows the design (StockHeights.above_design): the
    tip is a drop onto the model, so the tool clears the model all the way down to it (beside a wall the
    whole material top is the wall's top: a rest's entries at the walls' feet were fed from there)."""
    x0, y0, start = (float(v) for v in descent[0])
    top = _known_top(seg, policy, x0, y0, len(descent) == 1)
    if top is None:
        return policy.safe_height
    z = max(start, top) + policy.entry_clearance
    if z >= policy.safe_height:
        return policy.safe_height
    tp.add(MoveKind.RAPID, x0, y0, z, seg.axis(0))
    return z


def _hop_height(policy: LinkPolicy, last: Any, x: float, y: float, start: float = -math.inf) -> Optional[float]:
    """The height of a low link from the tool's position to above (x, y): `entry_clearance` (at least 1 mm) over
    the highest material top along the straight line, sampled a tenth of the tool's reach apart (the top is the
    tool dropped on the material, so the samples' footprints overlap), and over the entry's `start` (a start the
    holder guard lifted above the material: crossing lower and rising there drove the shank into a wall beside
    it); None when the policy keeps links at the safe height, the top is not known, the hop would not be
    lower, or its straight move would bring the shank or holder too near the model (`hop_clear`)."""
    top = policy.material_top
    if not policy.low_links or top is None:
        return None
    reach = float(getattr(getattr(getattr(top, "cutter", None), "native", None), "max_radius", 1.0))
    step = min(0.5, max(0.05, 0.1 * reach))
    n = max(2, int(math.ceil(math.hypot(x - last.x, y - last.y) / step)) + 1)
    xy = np.column_stack([np.linspace(last.x, x, n), np.linspace(last.y, y, n)])
    hop = max(float(np.max(top(xy))), last.z, start) + max(policy.entry_clearance, 1.0)
    if not (math.isfinite(hop) and hop < policy.safe_height):
        return None
    if policy.hop_clear is not None and not policy.hop_clear(np.array([[last.x, last.y, hop], [x, y, hop]])):
        return None   # the shank or holder would meet a wall beside the way: up to the safe height
    return hop


def heights_top(grid: Any, heights: np.ndarray, radius: float,
                profile: Optional[Callable[[np.ndarray], np.ndarray]] = None,
                outside: float = -math.inf) -> MaterialTop:
    """A MaterialTop from material heights at the cell centres of `grid` (x0, y0, cell, nx, ny: core.sim's Grid):
    the tool of `radius` (its lower surface `profile(rho)` above the tip, vectorised; None: flat) dropped onto the
    cells within its reach. A cell stands for material anywhere within half its diagonal of its centre, so its
    rho is taken that much shorter (a rapid never clips a cell's column); `outside`: what lies off the grid
    (-inf: nothing, +inf: not known)."""
    h = np.asarray(heights, dtype=float)
    cell = float(grid.cell)
    pad = cell * math.sqrt(0.5)
    reach = radius + pad

    def top(xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.full(len(xy), -math.inf)
        for k, (x, y) in enumerate(xy):
            i0, i1 = math.floor((x - reach - grid.x0) / cell), math.ceil((x + reach - grid.x0) / cell)
            j0, j1 = math.floor((y - reach - grid.y0) / cell), math.ceil((y + reach - grid.y0) / cell)
            if i0 < 0 or j0 < 0 or i1 > grid.nx or j1 > grid.ny:
                out[k] = outside
            i0, j0, i1, j1 = max(i0, 0), max(j0, 0), min(i1, grid.nx), min(j1, grid.ny)
            if i1 <= i0 or j1 <= j0:
                continue
            cx = grid.x0 + (np.arange(i0, i1) + 0.5) * cell - x
            cy = grid.y0 + (np.arange(j0, j1) + 0.5) * cell - y
            rho = np.maximum(np.hypot(*np.meshgrid(cx, cy)) - pad, 0.0)
            near = rho <= radius
            if near.any():
                lift = profile(rho[near]) if profile is not None else 0.0
                out[k] = max(out[k], float(np.max(_window_tops(h, j0, j1, i0, i1)[near] - lift)))
        return out
    return top


def cell_tops(heights: np.ndarray) -> np.ndarray:
    """Each cell's height raised to the highest of its 8 neighbours' (see _window_tops)."""
    h = np.asarray(heights, dtype=float)
    return _window_tops(h, 0, h.shape[0], 0, h.shape[1])


def _window_tops(h: np.ndarray, j0: int, j1: int, i0: int, i1: int) -> np.ndarray:
    """The heights of rows j0:j1, columns i0:i1, each the highest of its cell and its 8 neighbours: a height is
    the stock's at the cell's centre only, and between a cut centre and an uncut one the stock rises to the
    uncut one (a wall of a relief between two samples: a rapid 11 mm into mount_rush's stock without this)."""
    a, b = max(j0 - 1, 0), max(i0 - 1, 0)
    w = h[a:min(j1 + 1, h.shape[0]), b:min(i1 + 1, h.shape[1])]
    top = w.copy()
    top[1:] = np.maximum(top[1:], w[:-1])
    top[:-1] = np.maximum(top[:-1], w[1:])
    rows = top.copy()
    top[:, 1:] = np.maximum(top[:, 1:], rows[:, :-1])
    top[:, :-1] = np.maximum(top[:, :-1], rows[:, 1:])
    return top[j0 - a:j0 - a + (j1 - j0), i0 - b:i0 - b + (i1 - i0)]


class StockHeights:
    """The stock as heights on a grid (what earlier ops left: core.sim), a MaterialTop for a cutter that the
    linker keeps up to date as it cuts (`cut`, after each segment): an op's later entries then rapid down to
    just above what its own earlier passes left (a waterline's level above, a verification's finished surface).
    The grid's cells are updated in place; off the grid lies `outside` (-inf: nothing, +inf: not known).
    With the design's heights on the grid (`know_design`), `above_design` is the top of the material standing
    more than a tolerance off the design only: what a tool coming straight down onto a tip at or above its drop
    onto the model can meet (the model itself it clears all the way down)."""

    def __init__(self, grid: Any, heights: np.ndarray, cutter: Any, outside: float = -math.inf) -> None:
        self.grid, self.cutter, self.outside = grid, cutter, outside
        self.heights = np.array(heights, dtype=float)
        self._top = heights_top(grid, self.heights, cutter.radius, cutter.native.height, outside)
        self.design: Optional[np.ndarray] = None
        self._excess: Optional[np.ndarray] = None
        self._excess_top: Optional[MaterialTop] = None
        self.within = 0.0

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        return self._top(xy)

    def know_design(self, design: np.ndarray, within: float) -> None:
        """The design's heights at the grid's cells (NaN: none there); a cell within `within` of them (either
        way: a cell the stock stands well below was not sampled where the model is, a wall's top beside its
        foot) holds no material but the model's."""
        design = np.asarray(design, dtype=float)
        if design.shape != self.heights.shape:
            raise TmmError(f"design heights have shape {design.shape}, the stock's grid {self.heights.shape}")
        self.design, self.within = design, float(within)
        self._excess = np.empty_like(self.heights)
        self._update_excess(slice(None), slice(None))
        self._excess_top = heights_top(self.grid, self._excess, self.cutter.radius, self.cutter.native.height,
                                       self.outside)

    def _update_excess(self, rows: slice, cols: slice) -> None:
        h, d = self.heights[rows, cols], self.design[rows, cols]
        model = np.abs(h - d) <= self.within    # NaN (no design) compares False: material
        self._excess[rows, cols] = np.where(model, -math.inf, h)

    def above_design(self, xy: np.ndarray) -> np.ndarray:
        """The MaterialTop of what stands off the design (all of the stock before `know_design`)."""
        return self._top(xy) if self._excess_top is None else self._excess_top(xy)

    def cut(self, path: Toolpath) -> None:
        """`path`'s moves cut into the heights (the cells within the tool's reach of them only)."""
        from tmm_workbench.core.sim.simulate import simulate  # the simulation links too: imported when used

        if len(path) < 2:
            return
        g, pts = self.grid, path.points()
        reach = self.cutter.native.max_radius
        i0 = max(0, math.floor((pts[:, 0].min() - reach - g.x0) / g.cell))
        i1 = min(g.nx, math.ceil((pts[:, 0].max() + reach - g.x0) / g.cell))
        j0 = max(0, math.floor((pts[:, 1].min() - reach - g.y0) / g.cell))
        j1 = min(g.ny, math.ceil((pts[:, 1].max() + reach - g.y0) / g.cell))
        if i1 <= i0 or j1 <= j0:
            return
        sub = type(g)(g.x0 + i0 * g.cell, g.y0 + j0 * g.cell, g.cell, i1 - i0, j1 - j0)
        self.heights[j0:j1, i0:i1] = simulate(path, self.cutter, sub, self.heights[j0:j1, i0:i1]).heights
        if self._excess is not None:
            self._update_excess(slice(j0, j1), slice(i0, i1))


def know_design(policy: LinkPolicy, mesh: Any, within: float, stock_to_leave: float = 0.0,
                known: Optional[tuple[Any, np.ndarray]] = None) -> bool:
    """Gives the policy's StockHeights the design (StockHeights.know_design), so that plunges onto tips (drops onto
    the model) rapid down to just above what stands off it: at a wall's foot, and on a waterline's wall under the
    loops above, the highest stock within the tool's reach is the wall's top, and the plunge was fed from there
    (ktoolcav's waterline: 22 mm at the plunge feed per loop). `known`: the design already on a grid (grid,
    heights; a rest's), used when it is the stock's grid, else the mesh's heights on the stock's grid. Material
    within `within` of the design (either way) counts as the design: at most the stock to leave and what the op's
    own cuts leave on it (its chord tolerance), which the tool coming down onto its tip clears. Not with a negative
    stock to leave (a tip then lies below the model) nor without a StockHeights; whether it was given."""
    top = policy.material_top
    if not isinstance(top, StockHeights) or stock_to_leave < 0:
        return False
    g = top.grid
    if known is not None and known[1] is not None:
        k = known[0]
        if (k.x0, k.y0, k.cell, k.nx, k.ny) == (g.x0, g.y0, g.cell, g.nx, g.ny):
            top.know_design(known[1], within)
            return True
    from tmm_workbench.core.sim.stock import mesh_heights   # imported when used, as the simulation in cut

    top.know_design(mesh_heights(mesh, g), within)
    return True


def know_op_design(policy: LinkPolicy, mesh: Any, params: Any) -> bool:
    """know_design for an op's strategy parameters: a rest's design and rest tolerance (params.rest), else the
    mesh's heights within core.sim.stock.op_within."""
    from tmm_workbench.core.sim.stock import op_within   # imported when used, as in know_design

    s = float(getattr(params, "stock_to_leave", 0.0))
    rest = getattr(params, "rest", None)
    if rest is not None and getattr(rest, "design", None) is not None:
        return know_design(policy, mesh, rest.within, s, (rest.grid, rest.design))
    return know_design(policy, mesh, op_within(params), s)


def link(segments: Sequence[CutSegment], policy: LinkPolicy) -> Toolpath:
    """The tool path through `segments` in order (see the module doc). No segments: an empty path."""
    policy.validate()
    segments = [s for s in segments if len(s)]
    if not segments:
        return Toolpath()
    return (_link_vertical if policy.retract == VERTICAL else _link_along_axis)(segments, policy)


def _link_vertical(segments: list[CutSegment], policy: LinkPolicy) -> Toolpath:
    tp = Toolpath()
    for seg in segments:
        poll()   # Python per move: a million moves take seconds, Cancel is heard and a dialog repaints
        pts = seg.tips
        first = 0
        start = len(tp.moves) - 1                 # the cut begins where the tool is (joined) ...
        if not tp.moves or not seg.joined:
            name = seg.entry or policy.entry
            if name not in ENTRIES:
                raise TmmError(f"entry must be one of {', '.join(ENTRIES)}, got {name!r}")
            descent = _descent(seg, policy, name)
            x0, y0, top = descent[0]
            hop = _hop_height(policy, tp.moves[-1], x0, y0, top) if tp.moves else None
            if hop is not None:  # up to just above the material between, across
                last = tp.moves[-1]
                tp.add(MoveKind.RAPID, last.x, last.y, hop, last.axis)
                tp.add(MoveKind.RAPID, x0, y0, hop, seg.axis(0))
            elif tp.moves:  # lift straight up, cross over at the safe height
                last = tp.moves[-1]
                tp.add(MoveKind.RAPID, last.x, last.y, policy.safe_height, last.axis)
            else:
                tp.add(MoveKind.RAPID, x0, y0, policy.clearance_height)
            if hop is None:
                tp.add(MoveKind.RAPID, x0, y0, policy.safe_height, seg.axis(0))
            z = _approach(tp, seg, policy, descent)
            start = len(tp.moves) - 1             # ... or where its rapid down ends
            if len(descent) == 1:                 # straight down onto the tip
                tp.add(MoveKind.PLUNGE, *pts[0], seg.axis(0))
            else:
                if top < z:                       # through the clearance to where the material starts
                    tp.add(MoveKind.PLUNGE, x0, y0, top, seg.axis(0))
                for p in descent[1:]:
                    tp.add(MoveKind.FEED, *p, seg.axis(0))
            first = 1
        for i in range(first, len(pts)):
            tp.add(MoveKind.FEED, *pts[i], seg.axis(i), seg.arc(i))
        if hasattr(policy.material_top, "cut"):   # a StockHeights: what this segment cut, for the later entries
            policy.material_top.cut(Toolpath(tp.moves[start:]))
    last = tp.moves[-1]
    tp.add(MoveKind.RAPID, last.x, last.y, policy.clearance_height, last.axis)
    return tp


def _link_along_axis(segments: list[CutSegment], policy: LinkPolicy) -> Toolpath:
    below = policy.lowest_below_tip
    if below is None:
        raise TmmError("linking along the tool axis needs the tool's geometry (lowest_below_tip)")
    r = policy.axis_retract
    if any(seg.entry not in (None, PLUNGE) for seg in segments):
        raise TmmError(f"helix and ramp entries are 3-axis only; linking along the tool axis enters by '{PLUNGE}'")

    def along(seg: CutSegment) -> float:
        return r if seg.axis_retract is None else seg.axis_retract

    def above(tip: np.ndarray, a: Axis, d: float) -> tuple[float, float, float]:
        """On the axis `d` above the tip, raised to the transit height if lower."""
        p = tip + d * np.asarray(a)
        return float(p[0]), float(p[1]), max(float(p[2]), policy.safe_height + below(a))

    tp = Toolpath()
    a0 = segments[0].axis(0)
    x, y, z = above(segments[0].tips[0], a0, along(segments[0]))
    tp.add(MoveKind.RAPID, x, y, max(policy.clearance_height, z), Z_AXIS)
    tp.add(MoveKind.RAPID, x, y, max(policy.clearance_height, z), a0)
    for k, seg in enumerate(segments):
        poll()
        start = 0
        if k == 0 or not seg.joined:
            a = seg.axis(0)
            d = along(seg)
            tp.add(MoveKind.RAPID, *above(seg.tips[0], a, d), a)           # transit, the tool turned above the entry
            # below the safe height at the vertical feed, as the 3-axis entry: rapids stay above the stock
            tp.add(MoveKind.PLUNGE, *(seg.tips[0] + d * np.asarray(a)), a)  # down to the entry point on the axis
            tp.add(MoveKind.PLUNGE, *seg.tips[0], a)                         # along the axis onto the face
            start = 1
        for i in range(start, len(seg)):
            tp.add(MoveKind.FEED, *seg.tips[i], seg.axis(i), seg.arc(i))
        if k + 1 < len(segments) and segments[k + 1].joined:
            continue
        a1, d = seg.axis(len(seg) - 1), along(seg)
        tp.add(MoveKind.PLUNGE, *(seg.tips[-1] + d * np.asarray(a1)), a1)   # back along the axis, fed: the
        tp.add(MoveKind.RAPID, *above(seg.tips[-1], a1, d), a1)             # tilted tool moves sideways; up
    last = tp.moves[-1]
    top = max(policy.clearance_height, last.z)
    tp.add(MoveKind.RAPID, last.x, last.y, top, last.axis)
    tp.add(MoveKind.RAPID, last.x, last.y, top, Z_AXIS)                       # upright at the clearance height
    return tp
