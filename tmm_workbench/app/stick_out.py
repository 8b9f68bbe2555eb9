"""The shortest stick-out per 3-axis op of a Job with which the shank and holder never lift the tool or leave a
place out (core.verify.holder_clearance.minimum_stick_out over each op's feed moves against the design): what the
API's `minimum_stick_out` and the GUI's command report."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from tmm_workbench.app import simulation, tool_assembly, tools
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.verify.holder_clearance import minimum_stick_out, sample_moves

SAMPLE_MM = 0.5   # along every move (arcs by their chords): the guard's own sample step


def per_op(target: Any, holder: Optional[str] = None) -> dict:
    """{op label: core StickOut} for a Job (its active 3-axis ops) or one op. `holder`: a name of the holder
    library for every op; None: each op's own (its Holder, or its tool controller's; an op without one is left
    out). 5-axis ops are left out (their tool tilts). TmmError when no op is left."""
    job = simulation.job_of(target)
    if job is None:
        raise TmmError(f"'{getattr(target, 'Label', target)}' is not in a Job")
    ops = simulation.operations(job) if target is job else [target]
    model = simulation.design_mesh(job, ops)
    out = {}
    for op in ops:
        tp = simulation.toolpath_and_feeds(op)[0]
        if tp.is_five_axis():
            continue
        if holder is not None:
            assembly = tools.assembly_from_tool(op.ToolController.Tool, holder, None)
        else:
            assembly = tool_assembly.assembly_of(op) if hasattr(op, "Holder") else None
        if assembly is None:
            continue
        tips, _, move = sample_moves(tp, SAMPLE_MM, 0.0)
        cutting = np.array([m.kind is MoveKind.FEED for m in tp.moves])[move]   # rapids and plunges cut nothing
        out[str(op.Label)] = minimum_stick_out(model, assembly, tips[cutting, :2])
    if not out:
        raise TmmError("no 3-axis op with a holder: give holder= (a name from the holder library)")
    return out


def table(told: dict) -> str:
    """The report as lines a user reads: op, the shortest stick-out and what sets it."""
    return "\n".join(f"{label}: {s.summary()}" for label, s in told.items())
