"""What the planner knows of a model before it chooses: its size, how its surface slopes (area per slope band,
from the triangles), its flat areas and steep walls, what faces down (no tool reaches it from above), and per
library tool what that tool cannot reach from above (the reach test of core.footprint.rest: the tool's envelope
dropped at every cell against the design's heights; a tool with a holder dropped whole, its shank and holder keeping
their clearance, as the simulation checks it: a D1 with 4 mm flutes does not reach a floor 5 mm down beside a
wall). The smallest concave radius is bracketed by the reach tests
of the library's radiused tools: a ball that leaves nothing has a radius at most the smallest concave one."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from tmm_workbench.core.footprint.reach import reach_excess
from tmm_workbench.core.footprint.rest import tool_envelope
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.sim.compare import slope_deg
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter

SLOPE_EDGES = (0.0, 1.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0)   # degrees from the horizontal
FLAT_DEG = 1.0           # a face sloping less is a flat (a floor, a plateau)
STEEP_DEG = 60.0         # a face sloping more is a wall for the report's count
FAR_MM = 1.0             # a tool staying this far above the design leaves it to the next (a roughing tool's reach)
SPECK_SHARE = 0.001      # unreached area below this share of the design's is the grid's noise


@dataclass
class Reach:
    """What one tool leaves out of reach from above, on the analysis grid."""
    tool: str
    unreached_area: float    # mm^2 of design cells it stays above by more than the threshold
    deepest_left: float      # mm, the most it stays above the design
    threshold: float         # mm: the tolerance + the grid's own cusp on a flat (cell^2 / 8 r; more on slopes)
    far_area: float = 0.0    # mm^2 of design cells it stays above by more than FAR_MM (out of a roughing's reach)

    def as_dict(self) -> dict:
        return {"tool": self.tool, "unreached_mm2": round(self.unreached_area, 1),
                "deepest_left_mm": round(self.deepest_left, 3), "threshold_mm": round(self.threshold, 4),
                f"farther_than_{FAR_MM:g}_mm_mm2": round(self.far_area, 1)}


@dataclass
class Analysis:
    bounds: tuple[tuple[float, float, float], tuple[float, float, float]]
    triangles: int
    area: float                          # mm^2 of surface
    slope_area: dict                     # "lo-hi" deg -> share of the upward-facing area
    flat_share: float                    # of the upward-facing area
    steep_share: float                   # sloping more than STEEP_DEG
    down_share: float                    # facing down: never reached from above
    slope_map: np.ndarray                # (ny, nx) deg on `grid` (NaN: no design)
    design: np.ndarray                   # (ny, nx) heights (NaN: no design)
    grid: Grid
    reach: dict = field(default_factory=dict)   # tool name -> Reach
    concave_radius: tuple = (0.0, math.inf)     # (at least, at most) mm, from the reach tests

    @property
    def size(self) -> tuple[float, float, float]:
        lo, hi = self.bounds
        return tuple(h - l for l, h in zip(lo, hi))  # type: ignore[return-value]

    @property
    def seen_area(self) -> float:
        """mm^2 of the model seen from above (the design cells)."""
        return float(np.isfinite(self.design).sum()) * self.grid.cell_area

    def share_steeper(self, deg: float) -> float:
        """Share of the design cells (seen from above) sloping more than `deg`."""
        finite = np.isfinite(self.design)
        return float(np.mean(self.slope_map[finite] > deg)) if finite.any() else 0.0

    def as_dict(self) -> dict:
        lo, hi = self.bounds
        lo_r, hi_r = self.concave_radius
        return {"bounds_mm": [[round(v, 3) for v in lo], [round(v, 3) for v in hi]],
                "size_mm": [round(v, 3) for v in self.size], "triangles": self.triangles,
                "surface_area_mm2": round(self.area, 1), "slope_area_share": self.slope_area,
                "flat_share": round(self.flat_share, 4), "steep_share": round(self.steep_share, 4),
                "facing_down_share": round(self.down_share, 4), "analysis_cell_mm": self.grid.cell,
                "reach": {k: v.as_dict() for k, v in sorted(self.reach.items())},
                "smallest_concave_radius_mm": {"at_least": round(lo_r, 3),
                                               "at_most": None if math.isinf(hi_r) else round(hi_r, 3)}}


def slope_shares(mesh: TriMesh) -> tuple[float, dict, float, float, float]:
    """The surface area, the upward area's share per SLOPE_EDGES band, its flat and steep shares and the share of
    the whole area facing down (from the triangles' normals, area weighted)."""
    c = mesh.vertices[mesh.triangles]
    cross = np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])
    doubled = np.linalg.norm(cross, axis=1)
    area = doubled / 2
    nz = np.divide(cross[:, 2], doubled, out=np.zeros(len(area)), where=doubled > 0)
    total = float(area.sum())
    up = nz > 1e-9
    slope = np.degrees(np.arccos(np.clip(nz, -1.0, 1.0)))
    up_area = float(area[up].sum()) or 1.0
    shares = {}
    for lo, hi in zip(SLOPE_EDGES[:-1], SLOPE_EDGES[1:]):
        sel = up & (slope >= lo) & (slope < hi)
        shares[f"{lo:g}-{hi:g}"] = round(float(area[sel].sum()) / up_area, 4)
    flat = float(area[up & (slope < FLAT_DEG)].sum()) / up_area
    steep = float(area[up & (slope > STEEP_DEG)].sum()) / up_area
    down = float(area[nz < -1e-9].sum()) / (total or 1.0)
    return total, shares, flat, steep, down


def analyse(mesh: TriMesh, cell: float, tools: Optional[list] = None, tolerance: float = 0.01) -> Analysis:
    """The model's analysis on a grid of `cell` mm over its XY box; `tools`: (name, Cutter) pairs to reach-test,
    or (name, Cutter, ToolAssembly or None) to reach-test a tool with its shank and holder."""
    lo, hi = mesh.bounds
    grid = Grid.covering(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), cell)
    surface = DropSurface(mesh)
    design = mesh_heights(mesh, grid, surface)
    slope = np.where(np.isfinite(design), slope_deg(design, cell), np.nan)
    area, shares, flat, steep, down = slope_shares(mesh)
    out = Analysis((tuple(map(float, lo)), tuple(map(float, hi))), len(mesh.triangles), area, shares, flat, steep,
                   down, slope, design, grid)
    finite = np.isfinite(design)
    design_area = float(finite.sum()) * grid.cell_area
    for name, cutter, *whole in tools or []:
        env = reach_envelope(mesh, cutter, grid, surface, whole[0] if whole else None)
        left = np.where(finite, env - design, 0.0)
        radius = max(cutter.corner_radius, cutter.radius)
        threshold = tolerance + cell * cell / (8.0 * radius)
        unreached = float(np.sum(finite & (reach_excess(env, design, cell, radius) > tolerance))) * grid.cell_area
        if unreached < SPECK_SHARE * design_area:
            unreached = 0.0
        out.reach[name] = Reach(name, unreached, float(left.max()) if finite.any() else 0.0, threshold,
                                float(np.sum(left > FAR_MM)) * grid.cell_area)
    out.concave_radius = concave_bracket(out.reach, {t[0]: t[1] for t in tools or []})
    return out


def reach_envelope(mesh: TriMesh, cutter: Cutter, grid: Grid, surface: DropSurface,
                   assembly: Optional[ToolAssembly] = None) -> np.ndarray:
    """(ny, nx) the tool's envelope on `grid` (core.footprint.rest.tool_envelope; the whole `assembly`'s tip
    heights when given) from positions on `grid` grown by the tool's radius: an open sheet's rim at the grid's edge
    is reached by the tool beyond it (on a slope a ball touches uphill of its axis), not by a position on the grid."""
    radius = float(cutter.native.max_radius)
    pad = int(math.ceil(radius / grid.cell))
    grown = Grid(grid.x0 - pad * grid.cell, grid.y0 - pad * grid.cell, grid.cell, grid.nx + 2 * pad, grid.ny + 2 * pad)
    # beyond a rim at the model's lowest point the tool touches the rim's edge with its tip below it
    floor = float(mesh.vertices[:, 2].min()) - radius
    if assembly is None:
        tips = surface.drop(cutter, grown.centres(), floor).reshape(grown.ny, grown.nx)
    else:
        tips = whole_tool_tips(mesh, assembly, grown, surface, floor)
    env = tool_envelope(mesh, cutter, grown, surface, tips=tips)
    return env[pad:pad + grid.ny, pad:pad + grid.nx]


def whole_tool_tips(mesh: TriMesh, assembly: ToolAssembly, grid: Grid, surface: DropSurface,
                    floor_z: Optional[float] = None) -> np.ndarray:
    """(ny, nx) the lowest tip heights (not under `floor_z`, by default the mesh's lowest point) on `grid`'s cell
    centres at which neither the cutter nor the shank or holder of `assembly` comes closer to the mesh than its
    clearance (core.query.drop_assembly)."""
    z = AssemblyDrop(mesh, assembly, surface).heights(grid.centres(), floor_z)[0]
    return z.reshape(grid.ny, grid.nx)




def concave_bracket(reach: dict, cutters: dict) -> tuple[float, float]:
    """(at least, at most) the smallest concave radius: a ball (or corner) that reaches everything has a radius at
    most it; one that leaves some, more than it somewhere (or the model has a sharp inner corner)."""
    at_least, at_most = 0.0, math.inf
    for name, r in reach.items():
        radius = cutters[name].corner_radius
        if radius <= 0:
            continue
        if r.unreached_area == 0.0:
            at_least = max(at_least, radius)
        else:
            at_most = min(at_most, radius)
    return at_least, at_most
