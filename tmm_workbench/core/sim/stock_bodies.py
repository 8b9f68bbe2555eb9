"""The shank and holder against the in-process stock: what the Job's earlier ops left standing above the model
(a roughing's stair steps, the material a finishing tool could not reach, the frame's top beyond the model), as
heights on the simulation's grid. The holder guard, the rest's joins and the linker's low hops drop the bodies
above the flutes onto the model (core.query.drop_assembly) only; an op after others (a rest, a pencil, a clean-up)
then drove its shank into stock the model does not show, and only the Job's verification (the kernel's body check,
core.sim.stock_collisions) saw it. With an InProcessStock the bodies' height at a point is the higher of the
model's drop and the stock's:

- only the material standing more than `within` off the design counts (cells within it are the model, which the
  mesh drop sees exactly): no stock known, or none off the design, gives the model's heights unchanged;
- a cell's material may stand anywhere within it (the verification samples the stock on a grid of its own: on
  the same material the op's cells' centres alone left the shank 0.002 mm short of a 0.5 mm grid's), so it is
  taken half a diagonal nearer the axis; the body is the frustum grown by its clearance (its lower envelope over
  the distance from the axis: the flat bottom lowered by the clearance, the rounded rim, the side's offset line);
  cells finer than CELL_MM are gathered into CELL_MM cells (their highest);
- a cell wholly within the cutter's radius that the flutes reach is cut by the tool at the point itself (the body
  check stamps the cutter before it tests the bodies): it counts only above the flutes' top;
- cost: per body the highest stock over coarse blocks, dilated by the body's reach, bounds every point's height
  at once; only points that bound lifts above the model's height are dropped onto the cells, body by body.

The stock is the one before the op (its own passes cut more of it): a bound from above, as the guard's lift is.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Iterable, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.query.drop_assembly import PIECES, AssemblyDrop, body_pieces
from tmm_workbench.core.sim.stock import mesh_heights, op_within

CELL_MM = 0.25      # the stock's cells gathered up to this size for the bodies (a shank is 1 mm wide or more)
BLOCK_MM = 2.0      # the coarse blocks of the bound
TOLERANCE_MM = 1e-9


@dataclass
class InProcessStock:
    """The stock an op starts from: `heights` (ny, nx) at the centres of `grid` (core.sim's Grid: x0, y0, cell,
    nx, ny), `design` the model's heights there (NaN: none; None: taken when first asked from `source`, the op's
    core.linking.StockHeights, once its linker knows them (know_op_design: the same mesh heights on the same
    grid), else from `mesh`), `within`: material this near the design is the model's."""
    grid: Any
    heights: np.ndarray
    within: float = 0.0
    design: Optional[np.ndarray] = None
    mesh: Any = None
    source: Any = field(default=None, repr=False)
    _excess: Optional[np.ndarray] = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self.heights = np.array(self.heights, dtype=float)   # a copy: the linker cuts its stock as it links
        if self.heights.shape != (self.grid.ny, self.grid.nx):
            raise TmmError(f"stock heights have shape {self.heights.shape}, the grid "
                           f"{(self.grid.ny, self.grid.nx)}")
        if not (math.isfinite(self.within) and self.within >= 0):
            raise TmmError(f"stock within must be a length >= 0 mm, got {self.within!r}")
        if self.design is None and self.mesh is None:
            raise TmmError("an in-process stock needs the design's heights or the mesh to take them from")

    def excess(self) -> np.ndarray:
        """(ny, nx) the stock's height where it stands more than `within` above the design, else -inf."""
        if self._excess is None:
            known = getattr(self.source, "design", None)
            if self.design is None and known is not None and np.shape(known) == self.heights.shape:
                self.design = known   # the linker's: not dropped onto the mesh a second time
            if self.design is None:
                self.design = mesh_heights(self.mesh, self.grid)
            d = np.nan_to_num(np.asarray(self.design, dtype=float), nan=-math.inf)
            self._excess = np.where(self.heights > d + self.within, self.heights, -math.inf)
        return self._excess


def give(params: Any, left: Any, mesh: Any) -> None:
    """Sets `params.stock` (core.strategies.holder_guard.WholeToolParams) to what the Job's earlier ops left
    (`left`: a core.linking.StockHeights, None: not known) when the params carry a tool assembly; material
    within core.sim.stock.op_within of the design (a rest's tolerance) is the design's, as for the linker's entries
    (core.linking.know_op_design)."""
    if left is None or getattr(params, "assembly", None) is None:
        params.stock = None
        return
    rest = getattr(params, "rest", None)
    if rest is not None and getattr(rest, "design", None) is not None and rest.grid == left.grid:
        params.stock = InProcessStock(left.grid, left.heights, float(rest.within), rest.design)
        return
    params.stock = InProcessStock(left.grid, left.heights, op_within(params), mesh=mesh, source=left)


def lower_envelope(body: tuple, rho: np.ndarray) -> np.ndarray:
    """The lowest point, above the tip, of the frustum (z0, z1, r0, r1, clearance) grown by its clearance on the
    vertical lines `rho` mm from the axis (+inf where they miss it): its bottom edge and side, each grown into a
    capsule, the lower of the two."""
    z0, z1, r0, r1, c = (float(v) for v in body)
    return np.minimum(_capsule_low((0.0, z0), (r0, z0), c, rho), _capsule_low((r0, z0), (r1, z1), c, rho))


def _capsule_low(p: tuple, q: tuple, c: float, x: np.ndarray) -> np.ndarray:
    """The lowest point at abscissa x within c of the segment p-q (in the (rho, z) plane), +inf where none."""
    out = np.full(x.shape, math.inf)
    for a, b in (p, q):   # the end discs
        d = np.abs(x - a)
        inside = d <= c
        out[inside] = np.minimum(out[inside], b - np.sqrt(np.maximum(c * c - d[inside] ** 2, 0.0)))
    (a0, b0), (a1, b1) = p, q
    length = math.hypot(a1 - a0, b1 - b0)
    if length > 0 and abs(a1 - a0) > TOLERANCE_MM:   # the side's offset line, on its downward side
        nx, nz = (b1 - b0) / length, -(a1 - a0) / length
        if nz > 0:
            nx, nz = -nx, -nz
        s0, s1 = a0 + c * nx, a1 + c * nx
        lo, hi = min(s0, s1), max(s0, s1)
        on = (x >= lo) & (x <= hi)
        t = (x[on] - s0) / (s1 - s0)
        out[on] = np.minimum(out[on], b0 + c * nz + t * (b1 - b0))
    return out


class StockBodies:
    """An assembly's bodies dropped onto an InProcessStock's material off the design (see the module)."""

    def __init__(self, stock: InProcessStock, assembly: Any) -> None:
        g = stock.grid
        k = max(1, int(CELL_MM // g.cell))     # stock cells gathered per side
        h = stock.excess()
        ny, nx = -(-g.ny // k), -(-g.nx // k)
        padded = np.full((ny * k, nx * k), -math.inf)
        padded[:g.ny, :g.nx] = h
        self.h = padded.reshape(ny, k, nx, k).max(axis=(1, 3))
        self.cell = g.cell * k
        self.x0, self.y0 = g.x0, g.y0
        self.pad = self.cell * math.sqrt(0.5)
        self.bodies = assembly.bodies()
        self.pieces = body_pieces(assembly)
        self.radius = float(assembly.cutter.radius)
        self.flute_top = float(assembly.flute_length)
        self.any = bool(np.isfinite(self.h).any())
        b = max(1, int(BLOCK_MM // self.cell))
        self.block = b
        by, bx = -(-ny // b), -(-nx // b)
        blocks = np.full((by * b, bx * b), -math.inf)
        blocks[:ny, :nx] = self.h
        self.block_max = blocks.reshape(by, b, bx, b).max(axis=(1, 3))
        self._bounds: dict[int, np.ndarray] = {}

    def reach(self, i: int) -> float:
        _, _, r0, r1, c = self.bodies[i]
        return max(r0, r1) + c + self.pad

    def _bound(self, i: int) -> np.ndarray:
        """Per block, the highest stock within body i's reach of any point of it."""
        if i not in self._bounds:
            size = self.cell * self.block
            n = int(math.ceil(self.reach(i) / size)) + 1
            oy, ox = np.mgrid[-n:n + 1, -n:n + 1]
            near = np.maximum(np.hypot(ox, oy) - math.sqrt(2.0), 0.0) * size <= self.reach(i)
            m = self.block_max
            big = np.full((m.shape[0] + 2 * n, m.shape[1] + 2 * n), -math.inf)
            big[n:n + m.shape[0], n:n + m.shape[1]] = m
            out = np.full(m.shape, -math.inf)
            for dy, dx in zip(oy[near], ox[near]):
                out = np.maximum(out, big[n + dy:n + dy + m.shape[0], n + dx:n + dx + m.shape[1]])
            self._bounds[i] = out
        return self._bounds[i]

    def heights(self, keep: Iterable[int], xy: np.ndarray, below: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(z, owner): the lowest tip heights at the (n, 2) points at which bodies `keep` (positions in the
        assembly's bodies) keep their clearance from the stock, where that is above `below` (the model's heights;
        elsewhere -inf), and the body that set each (-1 none)."""
        n = len(xy)
        z, owner = np.full(n, -math.inf), np.full(n, -1, dtype=np.int64)
        if not self.any or not n:
            return z, owner
        size = self.cell * self.block
        bi = np.clip(np.floor((xy[:, 0] - self.x0) / size).astype(np.int64), 0, self.block_max.shape[1] - 1)
        bj = np.clip(np.floor((xy[:, 1] - self.y0) / size).astype(np.int64), 0, self.block_max.shape[0] - 1)
        for i in keep:
            low = float(lower_envelope(self.bodies[i], np.zeros(1))[0])
            ask = np.flatnonzero(self._bound(i)[bj, bi] - low > np.maximum(below, z) + TOLERANCE_MM)
            for p in ask:
                zi = self._point(i, float(xy[p, 0]), float(xy[p, 1]))
                if zi > max(below[p], z[p]):
                    z[p], owner[p] = zi, i
        return z, owner

    def _point(self, i: int, x: float, y: float) -> float:
        """Body i's lowest tip height over the cells within its reach of (x, y) (-inf: none)."""
        r = self.reach(i)
        i0 = max(0, math.floor((x - r - self.x0) / self.cell))
        i1 = min(self.h.shape[1], math.ceil((x + r - self.x0) / self.cell) + 1)
        j0 = max(0, math.floor((y - r - self.y0) / self.cell))
        j1 = min(self.h.shape[0], math.ceil((y + r - self.y0) / self.cell) + 1)
        if i1 <= i0 or j1 <= j0:
            return -math.inf
        w = self.h[j0:j1, i0:i1]
        jj, ii = np.nonzero(np.isfinite(w))
        if not len(jj):
            return -math.inf
        cx = self.x0 + (i0 + ii + 0.5) * self.cell - x
        cy = self.y0 + (j0 + jj + 0.5) * self.cell - y
        d = np.hypot(cx, cy)
        env = lower_envelope(self.bodies[i], np.maximum(d - self.pad, 0.0))
        # within the cutter's radius the flutes cut what stands below their top
        env = np.where(d + self.pad < self.radius, np.maximum(env, self.flute_top), env)
        return float(np.max(w[jj, ii] - env))


class StockAwareDrop(AssemblyDrop):
    """AssemblyDrop whose heights_of (the bodies above the flutes) keep their clearance from the in-process stock
    as well as from the model (see the module)."""

    def __init__(self, mesh: Any, assembly: Any, surface: Any, stock: InProcessStock) -> None:
        super().__init__(mesh, assembly, surface)
        self.stock = StockBodies(stock, assembly)

    def heights_of(self, pieces: Iterable[str], xy: np.ndarray, floor_z: Optional[float] = None,
                   progress: Any = None, threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
        z, owner = super().heights_of(pieces, xy, floor_z, progress, threads)
        wanted = set(pieces) if not isinstance(pieces, str) else {pieces}
        keep = [i for i, p in enumerate(self.pieces) if p in wanted and p != PIECES[0]]
        zs, os_ = self.stock.heights(keep, np.asarray(xy, dtype=float).reshape(-1, 2), z)
        higher = zs > z
        return np.where(higher, zs, z), np.where(higher, os_, owner).astype(owner.dtype)


def bodies_drop(mesh: Any, assembly: Any, surface: Any = None, stock: Optional[InProcessStock] = None
                ) -> AssemblyDrop:
    """The bodies' drop of the holder guard: onto the model, and onto `stock` when one is known."""
    if stock is None:
        return AssemblyDrop(mesh, assembly, surface)
    return StockAwareDrop(mesh, assembly, surface, stock)
