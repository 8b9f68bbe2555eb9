"""The Surface's third stage, the forward step along the passes: the positioned runs cut into segments in cutting
order (core.strategies.surface.segments; a region's chain by chain), and either thinned by the chord tolerance
above the samples only (SAMPLED) or, for TOLERANCE, fitted by the kernel with the fewest moves within the chord
tolerance of the exact CL path: lines, and arcs where a pass lies in XZ / YZ (core.strategies.lean_kernel)."""
from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Optional

import numpy as np

from tmm_workbench.core.query.drop import Progress
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.strategies.surface.params import SAMPLED, TOLERANCE, SurfaceParams
from tmm_workbench.core.strategies.surface.pattern import Run
from tmm_workbench.core.strategies.surface.segments import segments as cut_segments

if TYPE_CHECKING:
    from tmm_workbench.core.strategies.lean_kernel import ExactDrop


def is_lean(params: SurfaceParams) -> bool:
    """The lean passes: the forward step by the chord tolerance (TOLERANCE, a tolerance above 0)."""
    return params.forward_step == TOLERANCE and params.chord_tol > 0


def segments(runs: list[Run], z: np.ndarray, air: np.ndarray, params: SurfaceParams,
             chains: Optional[list[list[Run]]]) -> list[CutSegment]:
    """The segments in cutting order; thinned by the chord tolerance unless the passes are lean (their fit starts
    from the unthinned points)."""
    lean = is_lean(params)
    if chains is None:
        return cut_segments(runs, z, air, params.pattern, 0.0 if lean else params.chord_tol)
    from tmm_workbench.core.strategies import raster_region

    return raster_region.segments(runs, z, air, replace(params, chord_tol=0.0) if lean else params, chains,
                                  cut_segments)


def lean(segments: list[CutSegment], exact: ExactDrop, params: SurfaceParams,
         progress: Optional[Progress]) -> tuple[list[CutSegment], dict]:
    """The kernel's fit of `segments` (`exact`: the positioner's exact drop) and its
    statistics."""
    from tmm_workbench.core.strategies.lean_kernel import lean_segments_kernel

    return lean_segments_kernel(segments, exact, params.chord_tol, params.sample_step / 2, progress=progress,
                                arcs=params.arcs)


# --- the stage's declaration (core.stage) ---------------------------------------------------------------------
FORWARD_STEPS = {"Tolerance": TOLERANCE, "SampleStep": SAMPLED}


def ignored(args: Args) -> Optional[str]:
    if args.get("arcs") is True and str(args.get("forward_step") or TOLERANCE).lower() == SAMPLED:
        return "arcs need forward_step 'tolerance' (arcs are fitted to the exact tool path), got 'sample'"
    return None


# ForwardStep names no params field: new ops default to Tolerance, documents saved before it restore SampleStep
# (the params' default), so the op passes it (app.op_surface)
STAGE = Stage("forward step", (
    Field("ChordTolerance", "length", "Surface",
          "The tolerance of the moves: with ForwardStep Tolerance, how far above or below the exact tool path a "
          "move may pass; with SampleStep, how far above the CL points a longer straight move may pass where it "
          "replaces them (never below one; 0: keep every point off a straight line)", "chord_tol",
          "chord_tolerance", widget="chordTolerance"),
    Field("ForwardStep", "choice", "Surface",
          "Tolerance: the fewest moves within ChordTolerance of the exact tool path, above or below it (points "
          "added where a move would leave it, removed where a longer move stays in it); SampleStep: a point "
          "every SampleStep, moves above them only", api="forward_step", choices=FORWARD_STEPS,
          api_names={"tolerance": "Tolerance", "sample": "SampleStep"}, default="Tolerance", widget="forwardStep"),
    Field("ArcFitting", "bool", "Surface",
          "With ForwardStep Tolerance, passes at 0 or 90 deg get arcs (G2/G3 in G18 XZ / G19 YZ) where they fit "
          "within ChordTolerance; lines where the Job's post drops K (linuxcnc, mach3_mach4, ...)", "arcs", "arcs",
          widget="arcFitting"),
), ignored=ignored)
