"""The Surface's pencil pattern: its curves (core.footprint.pencil: creases found on the model, an outline offset
by the tool radius, a footprint file's curves), multi-pencil passes outward from them, clipped to the region (or
the boundary box), ordered nearest first, sampled into one chain each: positioned, split and linked as any
pattern's (the tool lifts between chains). Multi-pencil passes are `stepover` apart, or by the cusp height's
planar rule in the cusp mode; the creases are the CL valleys deeper than the cusp height (the tolerance the
finish is held to: a shallower fold leaves less than it between the two contacts)."""
from __future__ import annotations

import math

import numpy as np

from tmm_workbench.core import polygons
from tmm_workbench.core.footprint import pencil
from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.footprint.rest import LEAST_CUT
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.geometry.ordering import nearest_first
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.strategies.surface.params import (PENCIL_CLEANUP, PENCIL_CREASES, PENCIL_OUTLINE, STEPOVER,
                                                          SurfaceParams, crease_cell)
from tmm_workbench.core.tools.cutter import Cutter

Run = tuple[bool, np.ndarray]


def spacing(params: SurfaceParams, cutter: Cutter) -> float:
    return params.stepover if params.stepover_mode == STEPOVER else stepover_for_cusp(cutter, params.cusp, 0.0)


def curves(mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: SurfaceParams,
           floor_z: float) -> list[np.ndarray]:
    """The pencil's XY curves, innermost pass first (not yet clipped)."""
    step, passes = spacing(params, cutter), params.pencil_passes
    if params.pencil_source == PENCIL_CLEANUP:
        return cleanup_passes(mesh, surface, cutter, params, floor_z, step)
    if params.pencil_source == PENCIL_CREASES:
        found = pencil.crease_curves(surface, cutter, params.boundary, crease_cell(params), params.cusp, floor_z)
        if passes == 0 and params.rest is not None:
            rest = params.rest
            cells = rest.grid.centres()[np.isfinite(rest.heights).ravel()]   # the rest cells
            passes = covering_passes(found, cells, rest.grid.cell, step)
        return pencil.around_creases(found, max(passes, 1), step) if found else []
    passes = max(passes, 1)
    given = [np.asarray(c, dtype=float) for c in params.pencil_curves or []]
    if params.pencil_source == PENCIL_OUTLINE:
        closed = [c[:-1] if np.allclose(c[0], c[-1]) else c for c in given if _is_closed(c)]
        open_ = [c for c in given if not _is_closed(c)]
        return pencil.outline_curves(closed, open_, cutter.radius, params.pencil_side, passes, step)
    return pencil.around_creases(given, passes, step)   # a footprint file: the tool centre's own curves


def covering_passes(found: list[np.ndarray], cells: np.ndarray, cell: float, step: float) -> int:
    """Passes around the curves that reach 95 % of the cells' centres `cells` (n, 2) (none: 1), at most 50: the
    clean-up of a finish's strips (seed 000 section 3.6) as a multi-pencil over them."""
    if not found or not len(cells):
        return 1
    from scipy.spatial import cKDTree

    reach = np.percentile(cKDTree(np.vstack(pencil.sampled(found, cell))).query(cells)[0], 95)
    return int(min(50, max(1, math.ceil(reach / step) + 1)))


def cleanup_passes(mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: SurfaceParams, floor_z: float,
                   step: float) -> list[np.ndarray]:
    """Seed 000's clean-up (core.footprint.cleanup): the strips the finishing tool (params.cleanup_reference) left,
    by its normal jumps joined with the rest cells (params.rest), on the rest's grid (else one of the crease cell
    over the boundary); their curves with each point slid to its crease, and passes up both flanks `step` apart
    along the surface (PencilPasses - 1 each side; 0: to the strip's edge, at most 50). What it found is appended
    to params.verify_notes when given (a cleanup.CleanupReport)."""
    from tmm_workbench.core.footprint import cleanup
    from tmm_workbench.core.sim.grid import Grid
    from tmm_workbench.core.sim.stock import mesh_heights

    rest = params.rest
    grid = rest.grid if rest is not None else Grid.covering(*params.boundary, crease_cell(params))
    cells = None if rest is None else np.isfinite(rest.heights)
    finishing = params.cleanup_reference
    # the tolerance the finish is judged by: the rest's (its stock cuts at LEAST_CUT of it), else the cusp height
    tolerance = params.cusp if rest is None else rest.tolerance / LEAST_CUT
    found = cleanup.strips(mesh, surface, finishing, grid, mesh_heights(mesh, grid), cells, tolerance,
                           cutter.diameter)
    curves, slide = cleanup.cleanup_curves(mesh, surface, cutter, found, floor_z, finishing.diameter,
                                           crease_cell(params))
    sides = params.pencil_passes - 1 if params.pencil_passes else 50
    from scipy import ndimage

    near = ndimage.binary_dilation(found.mask, iterations=2)   # a pass ends a little past the strip's edge
    flanks = cleanup.flank_passes(surface, cutter, curves, floor_z, step, sides, (grid, near))
    if params.verify_notes is not None:   # the op's report (app.rest_source)
        params.verify_notes.append(cleanup.CleanupReport(found, slide, len(flanks)))
    return curves + flanks


def _is_closed(c: np.ndarray) -> bool:
    return len(c) >= 4 and bool(np.allclose(c[0], c[-1]))


def chains(mesh: TriMesh, surface: DropSurface, cutter: Cutter, params: SurfaceParams, floor_z: float,
           diagnostics: dict) -> list[list[Run]]:
    """One chain per clipped curve, in the order that walks least between them: diagnostics "passes" (chains)
    and "pencil_curves" (the curves before clipping)."""
    found = curves(mesh, surface, cutter, params, floor_z)
    area = params.region if params.region is not None else [polygons.rectangle(*params.boundary)]
    pieces = [p for p in polygons.clip_open(found, area) if len(p) >= 2] if found else []
    ordered = nearest_first(pieces)
    diagnostics["pencil_curves"] = len(found)
    diagnostics["passes"] = len(ordered)
    return [[(False, c)] for c in pencil.sampled(ordered, params.sample_step)]
