"""The 3-axis Surface op's pencil (Pattern 'Pencil', core.strategies.surface.pencil_pattern): the curves come from
the model's creases (PencilSource Creases: found by the tool itself), from an outline in the drawing (Outline:
`PencilCurve`, a sketch or any object with edges, closed loops offset by the tool radius to `PencilSide`; seed
003's pencil along lettering and logos), from a footprint file (File: `PencilFile`, x y lift per line) or from
seed 000's clean-up strips (CleanUp: with Region Rest; the finishing tool's normal jumps joined with the rest cells,
each point slid to its crease: core.footprint.cleanup); `PencilPasses` passes outward from them (multi-pencil), the
step-over or the cusp height's spacing apart."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.app import rest_source, simulation, tools
from tmm_workbench.app.offset_start import curves_of_object
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import pencil
from tmm_workbench.core.stage import Args, Field, Stage
from tmm_workbench.core.tools.cutter import Cutter

CREASES, OUTLINE, FILE, CLEANUP = "Creases", "Outline", "File", "CleanUp"
SOURCES = {CREASES: "creases", OUTLINE: "outline", FILE: "file", CLEANUP: "cleanup"}
SIDES = {"Outside": pencil.OUTSIDE, "Inside": pencil.INSIDE, "Both": pencil.BOTH}


def curves_of(op: Any) -> Optional[list[np.ndarray]]:
    """The op's given pencil curves: the outline's XY polylines, or the footprint file's; None for creases or
    another pattern."""
    if getattr(op, "Pattern", "") != "Pencil":
        return None
    source = getattr(op, "PencilSource", CREASES)
    if source == OUTLINE:
        if op.PencilCurve is None:
            raise TmmError("PencilSource 'Outline': no outline chosen (PencilCurve is empty): choose the sketch of "
                           "the lettering or logo")
        try:
            return curves_of_object(op.PencilCurve, float(op.RegionTolerance.Value))
        except TmmError as exc:   # said in the pencil's terms
            raise TmmError(str(exc).replace("OffsetStart 'Curve'", "PencilSource 'Outline'")
                           .replace("OffsetCurve", "PencilCurve")) from None
    if source == FILE:
        if not str(op.PencilFile or ""):
            raise TmmError("PencilSource 'File': no footprint file chosen (PencilFile is empty)")
        return pencil.read_footprint(str(op.PencilFile))
    return None


def finishing_cutter(op: Any, cutter: Cutter) -> Optional[Cutter]:
    """PencilSource CleanUp: the tool that finished before (whose strips are cleaned up): RestReference's with
    RestFrom ReferenceTool, else the last earlier op's with a ball or bull nose tool; None for another source.
    TmmError naming what is missing or too small."""
    if getattr(op, "Pattern", "") != "Pencil" or getattr(op, "PencilSource", CREASES) != CLEANUP:
        return None
    if getattr(op, "Region", "") != rest_source.REST:
        raise TmmError(f"PencilSource 'CleanUp' cleans up the strips a finish left: it needs Region 'Rest' (got "
                       f"{getattr(op, 'Region', '')!r})")
    if op.RestFrom == rest_source.REFERENCE_TOOL:
        return rest_source.reference_cutter(op, cutter)
    for earlier in reversed(simulation.earlier_ops(op) or []):
        finishing = tools.cutter_from_tool(earlier.ToolController.Tool)
        if finishing.corner_radius > 0:
            if finishing.diameter < cutter.diameter:
                raise TmmError(f"PencilSource 'CleanUp': the finishing op {earlier.Label} has the tool "
                               f"{finishing.describe()}, smaller than this op's {cutter.describe()}: the clean-up "
                               f"tool must be at most {finishing.diameter:g} mm")
            return finishing
    raise TmmError("PencilSource 'CleanUp': no earlier op of the Job finished with a ball or bull nose tool (the "
                   "strips are found along its paths): put the clean-up after the finishing op, or take the rest "
                   "from a reference tool (RestFrom ReferenceTool)")


def ignored(args: Args) -> Optional[str]:
    """The pencil's settings mean nothing with another pattern; each source's input nothing with another."""
    is_pencil = str(args.get("pattern") or "").lower() == "pencil"
    for name in ("pencil_source", "pencil_curve", "pencil_file", "pencil_side", "pencil_passes"):
        if args.get(name) is not None and not is_pencil:
            return f"{name} is used with pattern='pencil' only"
    source = str(args.get("pencil_source") or "creases").lower()
    if args.get("pencil_curve") is not None and source != "outline":
        return "pencil_curve is used with pencil_source='outline' only"
    if args.get("pencil_side") is not None and source != "outline":
        return "pencil_side is used with pencil_source='outline' only"
    if args.get("pencil_file") is not None and source != "file":
        return "pencil_file is used with pencil_source='file' only"
    if source == "outline" and args.get("pencil_curve") is None:
        return "pencil_source='outline' needs pencil_curve= (a sketch or an object with edges: the outline)"
    if source == "cleanup" and str(args.get("region") or "").lower() != "rest":
        return "pencil_source='cleanup' needs region='rest' (it cleans up the strips a finish left)"
    if source == "file" and args.get("pencil_file") is None:
        return "pencil_source='file' needs pencil_file= (a footprint file: x y lift per line)"
    return None


STAGE = Stage("pencil", (
    Field("PencilSource", "choice", "Pencil",
          "Pattern Pencil: along the model's concave creases (Creases, found by the tool: where it touches the "
          "model on two sides at once), along an outline of the drawing offset by the tool radius (Outline: "
          "PencilCurve), along a footprint file (File: PencilFile), or along seed 000's clean-up strips (CleanUp, "
          "with Region Rest: where the finishing tool's contact normals jump, each point slid to the crease)",
          "pencil_source", "pencil_source", choices=SOURCES,
          api_names={"creases": CREASES, "outline": OUTLINE, "file": FILE, "cleanup": CLEANUP}, default=CREASES,
          widget="pencilSource"),
    Field("PencilCurve", "link", "Pencil", "PencilSource Outline: the sketch (or edges) of the lettering or logo",
          api="pencil_curve"),
    Field("PencilFile", "file", "Pencil", "PencilSource File: the footprint file, a point per line: x y lift "
          "(1: lift before this point)", api="pencil_file"),
    Field("PencilSide", "choice", "Pencil",
          "PencilSource Outline: the tool runs Outside the loops (around raised letters), Inside them (engraved), "
          "or on Both sides", "pencil_side", "pencil_side", choices=SIDES, default="Outside", widget="pencilSide"),
    Field("PencilPasses", "int", "Pencil",
          "Pattern Pencil: passes outward from each curve (1: pencil; more: multi-pencil), the step-over apart (or "
          "the cusp height's spacing); 0 with Region Rest: as many as cover the rest (a clean-up of the strips "
          "the finish left)", "pencil_passes", "pencil_passes"),   # its spin box: gui.region_panel
), ignored=ignored)
