"""Where the 3-axis Surface op's 3D offset passes start: `OffsetStart` Boundary (the region's
boundary, inward: what the op always did, and what a document saved before the choice restores with) or Curve
(`OffsetCurve`: a sketch or any object with edges, open or closed, discretised within RegionTolerance and
projected along Z; the passes are offset from it to both sides across the region, core SurfaceParams.offset_from).
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.stage import Args, Field, Stage

BOUNDARY, CURVE = "Boundary", "Curve"
_CHOICES = {BOUNDARY: BOUNDARY, CURVE: CURVE}

def _label(obj: Any) -> str:
    return f"'{getattr(obj, 'Label', obj)}'"


def curves_of_object(obj: Any, tolerance: float) -> list[np.ndarray]:
    """The XY polylines of `obj`'s edges (its wires, or every edge when some belong to no wire); TmmError for no
    object or one without edges."""
    if obj is None:
        raise TmmError("OffsetStart 'Curve': no curve chosen (OffsetCurve is empty): choose a sketch or an object "
                       "with edges")
    shape = getattr(obj, "Shape", None)
    if shape is None or shape.isNull() or not shape.Edges:
        raise TmmError(f"OffsetStart 'Curve': {_label(obj)} has no edges: choose a sketch or an edge loop of a Part")
    wires = list(shape.Wires)
    pieces = wires if sum(len(w.Edges) for w in wires) == len(shape.Edges) else list(shape.Edges)
    out = []
    for piece in pieces:
        p = np.array([(v.x, v.y) for v in piece.discretize(Deflection=tolerance)], dtype=float)
        keep = np.concatenate([[True], np.hypot(*np.diff(p, axis=0).T) > 1e-9]) if len(p) else np.zeros(0, bool)
        p = p[keep]
        if len(p) >= 2:
            out.append(p)
    if not out:
        raise TmmError(f"OffsetStart 'Curve': the edges of {_label(obj)} are points seen from above (vertical "
                       f"edges): choose a curve that runs across the region")
    return out


def curves_of(op: Any, offset3d: bool) -> Optional[list[np.ndarray]]:
    """The op's start curves (None: from the boundary); `offset3d`: StepOverMode is Offset3D."""
    if getattr(op, "OffsetStart", BOUNDARY) != CURVE:
        return None
    if not offset3d:
        raise TmmError(f"OffsetStart 'Curve' needs StepOverMode 'Offset3D' (the passes offset from a curve), got "
                       f"'{op.StepOverMode}'")
    return curves_of_object(op.OffsetCurve, float(op.RegionTolerance.Value))


def api_values(args: Args, model: Any) -> dict[str, Any]:
    """run_surface's offset_from: None (the boundary) or an object with edges of the model's document."""
    offset_from = args.get("offset_from")
    if offset_from is None:
        return {"OffsetStart": BOUNDARY}
    if not hasattr(offset_from, "TypeId"):
        raise TmmError(f"offset_from must be None (the region's boundary) or a sketch / an object with edges, got "
                       f"{offset_from!r}")
    if getattr(offset_from, "Document", None) is not getattr(model, "Document", None):
        raise TmmError(f"offset_from {_label(offset_from)} must be in the model's document (an STL path makes a "
                       f"new one: pass a Mesh or Part object of the curve's document as the model)")
    return {"OffsetStart": CURVE, "OffsetCurve": offset_from}


def ignored(args: Args) -> Optional[str]:
    mode = args.get("stepover_mode")
    if args.get("offset_from") is not None and str(mode).lower() != "offset3d":
        return f"offset_from needs stepover_mode 'offset3d', got {mode!r}"
    return None


STAGE = Stage("offset start", (
    Field("OffsetStart", "choice", "Surface",
          "StepOverMode Offset3D: the passes start from the region's Boundary (inward) or from OffsetCurve (to both "
          "sides of it, across the region)", choices=_CHOICES, default=BOUNDARY, widget="offsetStart"),
    Field("OffsetCurve", "link", "Surface",
          "OffsetStart Curve: a sketch or an object's edges (open or closed), seen from above"),
), ignored=ignored, composite=("offset_from",), composite_values=api_values)
