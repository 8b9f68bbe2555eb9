"""5-axis finishing on the Tarus where it pays (docs/planner.md, "The Tarus 5-axis machine"): after the 3-axis plan
(core.plan.decide), on a `tarus5` machine, seed 000's tilted flat end (core.strategies.mesh5, the TMM 5-axis Mesh
op's strategy) is estimated over the model with the library's flat-end tools without planning the op
(core.plan.mesh5_estimate: passes from the tilted tool's strip width at the cusp, their path timed by the Tarus
post); the 3-axis finishing raster it would replace is computed and timed as the Job's simulation times it
(core.sim.cycle_time, at machine.rapid). Both keep the finish's cusp: the raster by its step-over for the cusp up
to the transition slope, the 5-axis passes with the cusp as their scallop tolerance. The faster wins
(planner.five_axis: always takes the 5-axis op when it can be made); the decision and both times go into the
report, and after the Job's run the op's own simulated time beside the estimate (after_run). The 3-axis ops it
replaces are kept as the fallback: the FreeCAD side (app.plan_five) runs them when the 5-axis op fails or does not
verify.

Where it applies: a model the mesh op can finish whole (it has no region yet): an open surface facing up (nothing
facing down), at most MIN_SHARE of its area steeper than the job's tilt limit (45 deg, the Tarus's C range:
steeper, the flat bottom cannot lie on the face), and a tool with a tilt clearing the mesh at every probed CC
point (no strip left for clean-up: the same finish everywhere). It replaces the 3-axis finishing ops (the shallow raster and the steep waterline, both
timed)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.plan import decide, materials
from tmm_workbench.core.plan.analysis import Analysis
from tmm_workbench.core.plan.job_file import JobSpec, ToolSpec
from tmm_workbench.core.plan.mesh5_estimate import Mesh5Estimate, estimate
from tmm_workbench.core.sim.cycle_time import DEFAULT_RAPID_MM_S

TOPIC = "5-axis finishing"
REPLACED = ("Finish shallow", "Finish steep")   # the 3-axis finishing ops the 5-axis op replaces (decide's labels)
MAX_CANDIDATES = 3                # flat-end tools estimated (the largest first): about 1.5 s each
FORWARD_STEP = 2.0                # mm between CC points along a pass (the op's default)
LABEL = "Finish 5-axis"


@dataclass
class FiveAxisChoice:
    """What the 5-axis decision changed: the op put in and the 3-axis ops it replaced (the fallback plan), the
    estimated times (s) and, once the Job is simulated, the op's own (seconds_built, after_run)."""
    op: decide.OpPlan
    fallback_ops: list
    seconds_5axis: float
    seconds_3axis: float
    notes: list = field(default_factory=list)
    passes: int = 0
    seconds_built: Optional[float] = None

    def as_dict(self) -> dict:
        return {"op": self.op.label, "fallback_ops": [o.as_dict() for o in self.fallback_ops],
                "estimated_seconds": {"5-axis": round(self.seconds_5axis, 1), "3-axis": round(self.seconds_3axis, 1)},
                "estimated_passes": self.passes,
                "built_seconds": None if self.seconds_built is None else round(self.seconds_built, 1)}


def flat_tools(job: JobSpec, an: Analysis) -> list:
    """The library's flat and bull-nose tools that reach the model's height and fit it (decide's width rule),
    the largest first."""
    narrow = min(an.size[0], an.size[1])
    fit = [t for t in job.tools if t.type in ("flat", "bull") and decide.reach_length(t) >= an.size[2]
           and t.diameter <= decide.ROUGH_WIDTH_SHARE * narrow]
    return sorted(fit, key=lambda t: (-t.diameter, t.corner_radius, job.tools.index(t)))[:MAX_CANDIDATES]


def steep_area_share(mesh: TriMesh, slope_deg: float) -> float:
    """The share of the model's area steeper than `slope_deg` (its triangles; the open surface's rim, which the
    slope map from above reads as a cliff, is not a face)."""
    n = mesh.face_normals()
    e1 = mesh.vertices[mesh.triangles[:, 1]] - mesh.vertices[mesh.triangles[:, 0]]
    e2 = mesh.vertices[mesh.triangles[:, 2]] - mesh.vertices[mesh.triangles[:, 0]]
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    steep = n[:, 2] < math.cos(math.radians(slope_deg))
    return float(area[steep].sum() / max(area.sum(), 1e-12))


def why_not(job: JobSpec, mesh: TriMesh, an: Analysis, plan: decide.Plan) -> Optional[str]:
    """The reason the model is not one the 5-axis mesh op finishes in place of the 3-axis finishing, None when it
    is."""
    if an.down_share > 0:
        return (f"{an.down_share * 100:.1f} % of the model's area faces down (a solid's underside too: the mesh op "
                "finishes an open surface facing up, the whole model: no region yet)")
    steep = steep_area_share(mesh, job.machine.tilt_limit)
    if steep >= decide.MIN_SHARE:
        return (f"{steep * 100:.1f} % of the model's area slopes more than the Tarus's {job.machine.tilt_limit:g} deg "
                "tilt (its flat bottom cannot lie on it; the mesh op finishes the whole model: no region yet)")
    if not any(op.label.startswith(REPLACED) for op in plan.ops):
        return "no 3-axis finishing op to replace"
    return None


def finishing_seconds(job: JobSpec, mesh: TriMesh, op: decide.OpPlan) -> float:
    """A planned 3-axis finishing op's cycle time, s: its path made by the core (the API's strategy with the op's
    step-over or step-down, sampling, slope range, lift off the model) and timed as the Job's simulation times it
    (core.sim.cycle_time, at machine.rapid)."""
    from tmm_workbench.core.linking import LinkPolicy, link
    from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds
    from tmm_workbench.core.strategies import waterline
    from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath

    k = op.kwargs
    tool = next(t for t in job.tools if t.name == op.tool)
    cutter = decide.cutter_of(tool)
    lo, hi = mesh.bounds
    top = float(hi[2])
    policy = LinkPolicy(top + 5.0, top + 10.0)
    if op.api == "run_waterline":   # the API's boundary 'model': the model's box grown by the tool's radius
        r = tool.diameter / 2
        params = waterline.WaterlineParams(boundary=(float(lo[0]) - r, float(lo[1]) - r, float(hi[0]) + r,
                                                     float(hi[1]) + r), step_down=k["step_down"])
        tp = link(waterline.compute(mesh, cutter, params).segments, policy)
    else:
        slopes = k.get("slope_range", [0.0, 90.0])
        params = SurfaceParams(boundary=(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])),
                               stepover=k["stepover"], sample_step=k["sample_step"],
                               off_model=k.get("off_model", "floor"), slope_min_deg=slopes[0],
                               slope_max_deg=slopes[1], chord_tol=k.get("chord_tolerance", 0.001))
        tp = compute_surface_toolpath(mesh, cutter, params, policy)
    rapid = [r / 60.0 for r in job.machine.rapid] if job.machine.rapid else [None, None]
    return three_axis_time(tp.points(), toolpath_feeds(tp, k["horiz_feed"] / 60.0, k["vert_feed"] / 60.0),
                           *rapid).seconds


def mesh5_args(job: JobSpec, tool: ToolSpec) -> dict:
    """run_mesh5's arguments for `tool` (but its feeds): the cusp as the scallop, the job's tilt limit."""
    return decide.api_tool(tool) | {"tolerance": job.finish.cusp, "tilt_limit_deg": job.machine.tilt_limit,
                                    "forward_step": FORWARD_STEP,
                                    "chord_tolerance": round(min(0.01, job.finish.tolerance / 2), 4),
                                    "post": job.machine.post}


def mesh5_estimate(job: JobSpec, mesh: TriMesh, tool: ToolSpec) -> Mesh5Estimate:
    """The 5-axis finish with `tool` estimated without planning it (core.plan.mesh5_estimate: the strip width
    at the cusp from the tilted tool's profile over the surface's sections, the passes, their path timed by the
    Tarus post at the materials table's feeds). TmmError: the op would refuse it (the tool, the work limits)."""
    from tmm_workbench.core.post import ToolInfo
    from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params

    args = mesh5_args(job, tool)
    params = Mesh5Params(tolerance=args["tolerance"], tilt_max_deg=args["tilt_limit_deg"],
                         forward_step=args["forward_step"], chord_tol=args["chord_tolerance"])
    c = materials.cutting(job.material, tool.diameter, tool.flutes, job.machine.spindle_max, job.machine.feed_max)
    info = ToolInfo(number=1, label=tool.name, shape="endmill" if tool.type == "flat" else "bullnose",
                    diameter=tool.diameter, corner_radius=tool.corner_radius, cutting_height=tool.flute_length,
                    spindle_rpm=c.rpm)
    return estimate(mesh, decide.cutter_of(tool), params, info, c.feed / 60.0, c.plunge / 60.0)


def consider(job: JobSpec, mesh: TriMesh, an: Analysis, plan: decide.Plan) -> Optional[FiveAxisChoice]:
    """On a tarus5 machine: the 5-axis finish in place of the 3-axis raster when it is faster (or planner.five_axis
    is always), the decision written with both times; None when the plan is kept (the reason written too)."""
    if not job.machine.five_axis:
        return None
    if job.planner.five_axis == "never":
        plan.decide(TOPIC, "none", "planner.five_axis: never")
        return None
    reason = why_not(job, mesh, an, plan)
    tools = flat_tools(job, an)
    if reason is None and not tools:
        reason = (f"no flat or bull-nose library tool reaches the model's {an.size[2]:.1f} mm height and is at most "
                  f"{decide.ROUGH_WIDTH_SHARE:g} x its narrower side (the mesh op cuts with a tilted flat bottom)")
    if reason is not None:
        plan.decide(TOPIC, "none", reason)
        return None
    replaced = [op for op in plan.ops if op.label.startswith(REPLACED)]
    three = {op.label: finishing_seconds(job, mesh, op) for op in replaced}
    timed, notes = [], []
    for tool in tools:
        try:
            est = mesh5_estimate(job, mesh, tool)
        except TmmError as exc:
            notes.append(f"{tool.name}: {exc}")
            continue
        if est.blocked:
            notes.append(f"{tool.name}: at {est.blocked} of {est.probed} probed CC points no tilt clears the mesh and "
                         "finishes it within the cusp (the op may leave them for clean-up: not the same finish)")
            continue
        timed.append((est.seconds, est.passes, tool))
    if not timed:
        plan.decide(TOPIC, "none", "the 5-axis mesh op cannot finish the model: " + "; ".join(notes))
        return None
    seconds, passes, tool = min(timed, key=lambda s: (s[0], tools.index(s[2])))
    total = sum(three.values())
    compared = (f"estimated cycle times at the cusp {job.finish.cusp:g} mm: 5-axis {tool.name} {seconds / 60:.2f} min "
                f"(about {passes} passes: the strip width at the cusp, timed by the Tarus post"
                + "".join(f"; {t.name} {sec / 60:.2f} min" for sec, _, t in timed if t is not tool)
                + ") against the 3-axis "
                + " + ".join(f"{label} {t / 60:.2f}" for label, t in three.items())
                + (f" = {total / 60:.2f}" if len(three) > 1 else "") + " min (the core's paths, rapids "
                + ("at machine.rapid" if job.machine.rapid else f"at the estimate's {DEFAULT_RAPID_MM_S * 60:g} mm/min")
                + ")"
                + "".join(f"; {n}" for n in notes))
    if seconds >= total and job.planner.five_axis != "always":
        plan.decide(TOPIC, "none", f"it does not pay: {compared}")
        return None
    why = "planner.five_axis: always" if seconds >= total else f"{total / max(seconds, 1e-9):.2f} x faster"
    op = decide.OpPlan("run_mesh5", f"{LABEL} {tool.name}", tool.name,
                       mesh5_args(job, tool) | decide.feeds(plan, job, tool))
    fallback = list(plan.ops)
    at = plan.ops.index(replaced[0])
    plan.ops[:] = [o for o in plan.ops if o not in replaced]
    plan.ops.insert(at, op)
    plan.decide(TOPIC, f"{tool.describe()} tilted (seed 000's 3D C-space), in place of "
                f"{', '.join(three)}",
                f"{why}: {compared}; the tilt at most {job.machine.tilt_limit:g} deg from the normal; verified by "
                "the 5-axis stock simulation, the 3-axis plan run instead when it does not verify")
    return FiveAxisChoice(op, fallback, seconds, total, notes, passes)


def fallen_back(plan: decide.Plan, choice: FiveAxisChoice, reason: str) -> None:
    """The plan back to its 3-axis ops after the 5-axis op failed or did not verify (the reason written)."""
    plan.ops[:] = choice.fallback_ops
    plan.decide(TOPIC, "fell back to the 3-axis plan", f"{choice.op.label} {reason}")


def after_run(plan: decide.Plan, verified: dict) -> None:
    """The Job's outcome (app.plan_five's verify.json) into the 5-axis decision: the fallback's reason, or the
    built op's simulated cycle time beside the estimate, and whether it came out slower than the 3-axis estimate."""
    choice = plan.five_axis
    if choice is None:
        return
    if verified.get("five_axis_fallback"):
        fallen_back(plan, choice, verified["five_axis_fallback"])
        return
    built = next((o["cycle_seconds"] for o in verified.get("ops", []) if o["label"] == choice.op.label), None)
    if built is None:
        return
    choice.seconds_built = float(built)
    slower = built > choice.seconds_3axis
    verified["five_axis"] = {"op": choice.op.label, "estimated_seconds": round(choice.seconds_5axis, 1),
                             "estimated_passes": choice.passes, "built_seconds": round(built, 1),
                             "three_axis_estimated_seconds": round(choice.seconds_3axis, 1),
                             "slower_than_three_axis": slower}
    plan.decide(TOPIC, "built: slower than the 3-axis estimate" if slower else "built",
                f"{choice.op.label} {built / 60:.2f} min as built and simulated against the estimated "
                f"{choice.seconds_5axis / 60:.2f} min ({(built / max(choice.seconds_5axis, 1e-9) - 1) * 100:+.0f} %)"
                + (f"; the 3-axis finishing was estimated at {choice.seconds_3axis / 60:.2f} min: it would have been "
                   "faster (the op verified, so it is kept)" if slower else
                   f"; still faster than the 3-axis estimate {choice.seconds_3axis / 60:.2f} min"))
