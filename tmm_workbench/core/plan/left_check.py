"""What a verified Job leaves where the library reaches (issue's target: the material left within the tolerance
wherever the smallest library tool reaches, the rest reported): the simulated deviation on the cells the smallest
radiused library tool reaches from above, against the tolerance.

A cell is reached when that tool's envelope (core.footprint.rest.tool_envelope: dropped at every cell) comes within
the tolerance of the design beyond the grid's own cusp, as the planner's reach tests judge
(core.footprint.reach.reach_excess); where more than the tolerance is left it is told again by the tool dropped
between the grid's positions (core.footprint.reach.nearest_reach: on a steep wall the grid's positions lie farther
apart along it than a small ball's width, and the grid's cusp allowance there is 0.3 mm).
The deviation is taken along the normal of the stock left (the vertical one times the cosine of its slope): the
vertical measure of a wall's cusps is many times their depth.
What no library tool reaches from above (sharp inner corners, undercuts) is reported as its area, not judged. Where
the finish asks a cusp larger than the tolerance, its passes leave cusps up to it by design: what is left is also
counted against that allowance."""
from __future__ import annotations

from typing import Optional

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.footprint.reach import nearest_reach, reach_excess
from tmm_workbench.core.plan.analysis import reach_envelope
from tmm_workbench.core.sim.compare import slope_cosine
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter


def left_in_reach(mesh: TriMesh, grid: Grid, design: np.ndarray, deviation: np.ndarray, tool: str,
                  cutter: Cutter, tolerance: float, cusp: float = 0.0, assembly: Optional[ToolAssembly] = None
                  ) -> dict:
    """`deviation` (ny, nx, vertical, + left; NaN without design) of the simulated Job against `design` on `grid`,
    judged where `cutter` (the library's smallest radiused tool, named `tool`) reaches: areas in mm^2, depths in mm
    along the normal; above the tolerance, and above the allowance: the larger of it and the finish's `cusp`.
    `assembly`: the tool with its shank and holder (core.tools.assembly), which reaches only where they keep their
    clearance (a 4 mm flute does not reach a floor 5 mm down beside a wall); None: the cutter alone."""
    finite = np.isfinite(design) & np.isfinite(deviation)
    surface = DropSurface(mesh)
    envelope = reach_envelope(mesh, cutter, grid, surface, assembly)
    radius = max(cutter.corner_radius, cutter.radius)
    with np.errstate(invalid="ignore"):
        reached = finite & (reach_excess(envelope, design, grid.cell, radius) <= tolerance)
    # along the normal of the stock left (its vertical deviation times the cosine of its slope)
    stock = np.where(finite, design + np.where(finite, deviation, 0.0), np.nan)
    left = np.where(finite, deviation, 0.0) * slope_cosine(stock, grid.cell)
    # the grid's test told again between its positions where more than the tolerance is left: whether the tool
    # reaches those cells decides what is judged
    doubt = finite & (left > tolerance)
    near = nearest_reach(mesh, cutter, grid, design, np.argwhere(doubt), surface, assembly)
    reached[doubt] = near <= tolerance
    left = np.where(reached, left, 0.0)
    above = reached & (left > tolerance)
    allowance = max(tolerance, cusp)
    inside = left[reached]
    return {"tool": tool, "reached_mm2": round(float(reached.sum()) * grid.cell_area, 1),
            "out_of_reach_mm2": round(float((finite & ~reached).sum()) * grid.cell_area, 1),
            "left_above_tolerance_mm2": round(float(above.sum()) * grid.cell_area, 2),
            "allowance_mm": allowance,
            "left_above_allowance_mm2": round(float((reached & (left > allowance)).sum()) * grid.cell_area, 2),
            "most_left_mm": round(float(inside.max()) if inside.size else 0.0, 4),
            "left_99_percentile_mm": round(float(np.percentile(inside, 99)) if inside.size else 0.0, 4)}


GRIP_DIAMETERS = 3.0   # shank diameters in the holder when the library gives no stick-out (app.tools' default)


def whole_tool(cutter: Cutter, spec: dict) -> Optional[ToolAssembly]:
    """The library tool `spec` (the plan document's tools entry: flute_length, length, shank_diameter, holder,
    stick_out) as the assembly the simulation checks; None without a holder (no shank is checked then either)."""
    if spec.get("holder") is None:
        return None
    shank = float(spec.get("shank_diameter") or cutter.diameter)
    stick_out = spec.get("stick_out") or float(spec["length"]) - GRIP_DIAMETERS * shank
    return ToolAssembly(cutter, shank_diameter=shank, stick_out=float(stick_out),
                        flute_length=float(spec["flute_length"]), holder=spec["holder"],
                        overall_length=float(spec["length"]))
