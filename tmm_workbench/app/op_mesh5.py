"""'TMM 5-axis Mesh': a Path operation that finishes a mesh (or a Part model, tessellated) with a tilted flat
end mill or bull-nose by seed 000's 3D C-space (core.strategies.mesh5.finish: adaptive passes, the posture at
every CC point chosen for the Tarus motion time, the scallop within the tolerance).

What is machined: as the other mesh ops (op_mesh: `StlFile`, then `Model`, then the Job's model). The tool:
the tool controller's ToolBit through the one ToolBit map (app.tools); a flat end mill or a bull-nose, any
other refused by the strategy naming it. Tilt limits (least tilt and tilt limit, from the surface normal)
must lie within the Tarus's C range; the yaw limit and the grid step make the C-space's grid.

Path (docs/path5.md): X Y Z = tool tip, U V W = unit tool axis, linked as the 5-axis Multipoint op does (the
one linker, core.strategies.multipoint.link_policy): each pass entered and left `AxisRetract` along its tool
axis, transits at the safe height for the tilted tool's lowest point, the op starting and ending upright at
the clearance height. `Mesh5Summary` says passes, CC points and what was left for clean-up: strips no
posture finishes within the tolerance and their CC points (a count and their extent), also printed as a
warning; `CleanupRegions` holds points on the model covering those strips (the 3D view draws them), and with
`SimulateLeft` (the default) the cells the simulated finish leaves above the tolerance outside them
(core.strategies.mesh5.cleanup.left_above; a companion 3-axis ball op machines both: app.api.run_mesh5's
cleanup_diameter, a TMM Surface op with Region 'Rest' after this one). The
whole tool (app.tool_assembly: Holder, StickOut, the clearances; by default the tool controller's holder):
its shank and holder bound every C-space, so the tool tilts away where they would come closer, or the place
is left for clean-up; the cut moves are checked against the model and one that would come closer is left out,
and so are the links (a pass whose exit straight up would bring the holder into an overhang leaves along its
axis to the transit height: mesh5.holder.link_clear); `HolderReport` and `HolderRegions` say what they
changed. Errors never leave a partial path.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Optional

import FreeCAD
import numpy as np
import Path

from tmm_workbench.app import op_base, op_mesh, stages, tool_assembly, work_estimate
from tmm_workbench.app.compat import PathSetupSheet
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.mesh5 import cleanup, finish, holder
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params
from tmm_workbench.core.strategies.multipoint import link_policy

OP_NAME = "TMM_Mesh5"
MAX_MARKS = 20_000   # cells the simulated finish leaves marked on the view (every k-th of more)

PROPERTIES: list[Prop] = op_mesh.MODEL_PROPERTIES + [
    Prop("App::PropertyDistance", "Tolerance", "Mesh5",
         "Largest scallop left between passes and below each posture (the passes are placed for it)", "tolerance"),
    Prop("App::PropertyAngle", "FeedAngle", "Mesh5", "Direction of the passes seen from above, from +X",
         "feed_angle_deg"),
    Prop("App::PropertyDistance", "ForwardStep", "Mesh5", "Distance between CC points along a pass (at most)",
         "forward_step"),
    Prop("App::PropertyDistance", "ChordTolerance", "Mesh5", "Largest deviation of a pass's chords from the mesh",
         "chord_tol"),
    Prop("App::PropertyAngle", "LeastTilt", "Posture", "Least inclination of the tool axis from the surface "
         "normal (within the machine's C range)", "tilt_min_deg"),
    Prop("App::PropertyAngle", "TiltLimit", "Posture", "Largest inclination of the tool axis from the surface "
         "normal (within the machine's C range)", "tilt_max_deg"),
    Prop("App::PropertyAngle", "YawLimit", "Posture", "Largest yaw of the tilted tool from the feed direction, "
         "either way", "yaw_limit_deg"),
    Prop("App::PropertyAngle", "GridStep", "Posture", "Step of the (tilt, yaw) grid the postures are chosen on "
         "(seed 000: 3 deg)", "grid_step_deg"),
    Prop("App::PropertyBool", "ZigZag", "Mesh5", "Alternate the direction of the passes", "zigzag"),
    Prop("App::PropertyDistance", "AxisRetract", "Linking",
         "Entry and exit distance along the tool axis (then straight up/down to the safe height)"),
    Prop("App::PropertyBool", "SimulateLeft", "Mesh5",
         "Simulate the finish (the 5-axis stock simulation, 0.25 mm cells, from 0.5 mm over the model) and mark "
         "what it leaves above the tolerance outside the strips too (the passes' ends along a slanted boundary) "
         "in CleanupRegions"),
    Prop("App::PropertyString", "Mesh5Summary", "Mesh5",
         "Result of the last computation: passes, CC points, what is left for clean-up"),
    Prop("App::PropertyVectorList", "CleanupRegions", "Mesh5",
         "Points on the model no pass finishes within the tolerance (an empty C-space: the strips of "
         "Mesh5Summary), marked for clean-up: drawn on the 3D view"),
]
CHOICES: dict[str, dict[str, str]] = {}
DEFAULTS: dict[str, Any] = {**op_mesh.MODEL_DEFAULTS, "AxisRetract": 5.0, "SimulateLeft": True}

# the whole tool (app.tool_assembly): its shank and holder bound every C-space, so the tool tilts away where they
# would come closer, or the place is left for clean-up (no Lift / LeaveOut choice: the C-space decides)
TOOL_STAGE = replace(tool_assembly.STAGE, fields=tuple(
    f for f in tool_assembly.STAGE.fields if f.prop != "HolderCollision"))
TOOL_STAGES = (TOOL_STAGE,)
PROPERTIES += stages.properties(TOOL_STAGES)
CHOICES.update(stages.choices(TOOL_STAGES))
DEFAULTS.update(stages.defaults(TOOL_STAGES))


class ObjectTmmMesh5(op_mesh.MeshOp):
    """Proxy of the operation. Transient results of the last run (not saved): `toolpath`, `mesh`, `segments`,
    `diagnostics` (the strategy's: the plan, unfinished strips, empty CC points)."""

    ESTIMATE = staticmethod(work_estimate.mesh5)  # its strategy's inputs from the properties
    STRATEGY = finish  # its estimate_work (core.work)

    VIEW_KIND = "mesh5_op"
    PARAMS = Mesh5Params
    PROPERTIES = PROPERTIES
    CHOICES = CHOICES
    DEFAULTS = DEFAULTS
    SPECS = stages.specs(TOOL_STAGES)
    RESTORED_DEFAULTS = {**stages.restored(TOOL_STAGES),   # documents from before the holder: none
                         "SimulateLeft": False}             # from before the simulation: the plan's strips only
    READ_ONLY = ("Mesh5Summary", "CleanupRegions")
    segments: Optional[list] = None
    diagnostics: Optional[dict] = None

    def clear_results(self) -> None:
        self.mesh = self.toolpath = self.segments = self.diagnostics = None

    def compute(self, obj: Any) -> None:
        mesh = self.model_mesh(obj)
        cutter = self.cutter()
        params = self.params_from(obj)
        finish.check_tool(cutter)
        params.grid()  # tilt limits within the machine's range, before the model is worked on
        safe, clearance = obj.SafeHeight.Value, obj.ClearanceHeight.Value
        top = float(mesh.bounds[1][2])
        if safe <= top:
            raise TmmError(f"safe height {safe:g} mm must be above the model's top {top:g} mm")
        if clearance < safe:
            raise TmmError(f"clearance height {clearance:g} mm is below the safe height {safe:g} mm")
        tool_assembly.prepare(obj, params)  # the shank and holder bound the C-space (no holder: the cutter alone)
        with self.reporting(obj) as cb:
            result = finish.compute(mesh, cutter, params, cb)
            policy = link_policy(cutter, safe, clearance, obj.AxisRetract.Value)
            toolpath, links = holder.link_clear(mesh, result.segments, policy, params.assembly)
        self.mesh, self.toolpath, self.segments = mesh, toolpath, result.segments
        self.diagnostics = dict(result.diagnostics)
        if links is not None:
            self.diagnostics["links"] = links
        marks = self.diagnostics["cleanup_points"]
        if obj.SimulateLeft:   # what the plan does not list: the simulation of the linked path finds it
            left = cleanup.left_above(mesh, cutter, toolpath, params.tolerance,
                                      strips=self.diagnostics["strip_corners"])
            self.diagnostics["left"] = left
            extra = left.points(left.outside)
            marks = np.vstack([marks, extra[::max(1, len(extra) // MAX_MARKS)]])
        text = finish.report(self.diagnostics)
        if obj.Mesh5Summary != text:
            obj.Mesh5Summary = text
        obj.CleanupRegions = [FreeCAD.Vector(*map(float, p)) for p in marks]
        tool_assembly.report(obj, params)
        if len(marks):
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {text}\n")
        else:
            FreeCAD.Console.PrintMessage(f"{obj.Label}: {text}\n")
        self.commandlist.extend(Path.Command(n, p) for n, p in
                                path5.encode_toolpath(toolpath, self.horizFeed, self.vertFeed))

    def on_fail(self, obj: Any) -> None:
        if obj.Mesh5Summary:
            obj.Mesh5Summary = ""
        if obj.CleanupRegions:
            obj.CleanupRegions = []


def SetupProperties() -> list[str]:
    """Properties the Job's SetupSheet may hold defaults for."""
    return op_base.setup_properties(ObjectTmmMesh5, exclude=("StlFile", "Model", "Mesh5Summary", "CleanupRegions"))


def Create(name: str = OP_NAME, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`."""
    return op_base.create(ObjectTmmMesh5, "mesh5_op", name, obj, parentJob, values)


PathSetupSheet.RegisterOperation(OP_NAME, Create, SetupProperties)
