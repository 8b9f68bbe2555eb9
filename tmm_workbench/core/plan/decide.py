"""The planner's decisions: from a checked job (core.plan.job_file) and its model's analysis (core.plan.analysis)
to the list of ops the headless API runs (app.api's run_roughing, run_surface, run_waterline keyword arguments),
each decision written down with its reason for the report. Deterministic: the same job gives the same plan.

- roughing: the largest flat or bull-nose library tool (a ball if there is none) that reaches the depth, layers
  the material's depth per pass allows (at most the flute length), ROUGH_LEAVE left for the finish;
- finishing split by slope: shallow by a cusp-driven raster, steep by waterline, the transition where seed 003's
  comparison (core.plan.optimal_cutter) finds a ball starts to leave less than the shallow cutter;
- the finishing cutter by that comparison (same step-over and raster for every radiused library tool, ranked by
  the volume each leaves), or the largest ball without it;
- rest: a smaller radiused tool where the reach tests say the finishing tool leaves material it reaches;
- pencil: a still smaller one along the concave creases (seed 003 section 4.5's pencil, passes outward over the
  band the rest tool's radius leaves) where the reach tests say it reaches clearly more;
- clean-up: after the pencil, its tool as a raster over what the earlier ops still leave that it reaches.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.footprint.cusp import stepover_for_cusp
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.plan import materials
from tmm_workbench.core.plan.analysis import FAR_MM, Analysis
from tmm_workbench.core.plan.job_file import JobSpec, PlanInputError, ToolSpec
from tmm_workbench.core.plan.stock import PlannedStock, planned_stock
from tmm_workbench.core.strategies.zlevel_layers import PLATEAU_DEG
from tmm_workbench.core.tools.cutter import Cutter

ROUGH_LEAVE = 0.3          # mm left by roughing for the finishing tool (radial and axial)
ROUGH_STAIR = 1.0          # mm, the most the layers' stairs may leave on slopes (seed 000 eq. 3.11): the finishing
#                            ops' rapids come down to a few mm above the model (16 mm stairs were cut by a rapid)
TRANSITION_DEG = 45.0      # shallow / steep split without a comparison saying otherwise
TRANSITION_RANGE = (30.0, 60.0)
MIN_SHARE = 0.005          # of the design cells: a slope class smaller than this gets no op of its own
MIN_STEPOVER = 0.05        # mm: a finish needing a finer step-over than this is refused as too tight
STEP_TIE = 0.05           # step-overs within this share of the largest are equal (the comparison's rank decides)
MAX_COMPARED = 4           # radiused tools compared (the largest first)
ROUGH_SHANK_CLEAR = 1.5    # mm: the roughing's flutes end this far above the stock (the API's shank clearance 1 mm)
ROUGH_WIDTH_SHARE = 0.5    # a roughing tool wider than this share of the model's narrower side does not fit
ROUGH_FAR_SHARE = 0.5      # nor one staying more than FAR_MM above over more than this share of the model's area
WALL_DEG = 80.0            # a face steeper than this is a wall a flat end mill's side finishes
PENCIL_GAIN = 0.02         # a pencil tool must reach at least this share of the model seen from above that the rest
#                            tool does not (a share of the rest tool's unreached area was diluted by what neither
#                            reaches: beet faces 59 % down, and the whole D1 left 0.875 of the D3's, reaching 28 mm2
#                            of creases more, 7 % of the beet)


@dataclass(frozen=True)
class Decision:
    topic: str
    choice: str
    reason: str

    def as_dict(self) -> dict:
        return {"topic": self.topic, "choice": self.choice, "reason": self.reason}


@dataclass
class OpPlan:
    api: str                  # run_roughing | run_surface | run_waterline
    label: str
    tool: str                 # library name
    kwargs: dict              # the API call's keyword arguments (JSON values)
    optional: bool = False    # left out (its material reported) when it alone fails the verification

    def as_dict(self) -> dict:
        return {"api": self.api, "label": self.label, "tool": self.tool, "kwargs": self.kwargs,
                "optional": self.optional}


@dataclass
class Plan:
    stock: PlannedStock       # the stock around the placed model (core.plan.stock)
    ops: list = field(default_factory=list)
    decisions: list = field(default_factory=list)
    cutting: dict = field(default_factory=dict)   # tool name -> materials.Cutting.as_dict()
    reach_tool: str = ""      # the library tool reaching the most: what is left is judged where it reaches
    five_axis: Any = None     # core.plan.five_axis.FiveAxisChoice: the 5-axis op put in, the 3-axis fallback

    @property
    def stock_box(self) -> tuple:
        """(xmin, ymin, zmin, xmax, ymax, zmax) mm of the stock."""
        return self.stock.box

    def decide(self, topic: str, choice: str, reason: str) -> None:
        self.decisions.append(Decision(topic, choice, reason))

    def as_dict(self) -> dict:
        return {"stock_box_mm": [round(v, 4) for v in self.stock_box], "ops": [o.as_dict() for o in self.ops],
                "decisions": [d.as_dict() for d in self.decisions], "tools": self.cutting,
                "left_judged_where_reaches": self.reach_tool}


def cutter_of(tool: ToolSpec) -> Cutter:
    return Cutter(tool.diameter, tool.corner_radius)


def reach_length(tool: ToolSpec) -> float:
    """How deep the tool goes below the stock's top: its stick-out from the holder, or its flutes without one."""
    return tool.stick_out if tool.stick_out is not None else tool.flute_length


GRIP_DIAMETERS = 3.0         # shank diameters held in the holder (app.tools' default grip)
LENGTH_PAST_FLUTES = 4.0     # a tool without a holder: its overall length past the flutes, in diameters


def overall_length(tool: ToolSpec) -> float:
    """The ToolBit's overall length: the library's, or the stick-out plus the grip in the holder, or the flutes plus
    a shank."""
    if tool.length is not None:
        return tool.length
    if tool.stick_out is not None:
        return tool.stick_out + GRIP_DIAMETERS * tool.diameter
    return tool.flute_length + LENGTH_PAST_FLUTES * tool.diameter


def api_tool(tool: ToolSpec) -> dict:
    """The API's tool arguments of a library tool."""
    shape = {"flat": "endmill", "ball": "ballend", "bull": "bullnose"}[tool.type]
    out: dict[str, Any] = {"tool": shape, "diameter": tool.diameter}
    if tool.type == "bull":
        out["corner_radius"] = tool.corner_radius
    return out   # the flute length, overall length and holder go on the tool controller (app/plan_run.py)


def feeds(plan: Plan, job: JobSpec, tool: ToolSpec) -> dict:
    c = materials.cutting(job.material, tool.diameter, tool.flutes, job.machine.spindle_max, job.machine.feed_max)
    plan.cutting[tool.name] = c.as_dict() | {"tool": tool.describe()}
    return {"horiz_feed": round(c.feed, 1), "vert_feed": round(c.plunge, 1), "spindle_speed": round(c.rpm)}


def choose_roughing(plan: Plan, job: JobSpec, an: Analysis) -> ToolSpec:
    depth = plan.stock_box[5] - an.bounds[0][2]
    narrow = min(an.size[0], an.size[1])
    reaching = [t for t in job.tools if reach_length(t) >= depth]
    if not reaching:
        longest = max(job.tools, key=reach_length)
        raise PlanInputError(f"tools: no tool reaches the roughing depth {depth:.1f} mm (stock top to the model's "
                             f"lowest point); the longest, {longest.name}, reaches {reach_length(longest):g} mm")
    fitting = [t for t in reaching if t.diameter <= ROUGH_WIDTH_SHARE * narrow] or \
        [min(reaching, key=lambda t: t.diameter)]
    # flat and bull-nose tools clear layers; a ball only when there is nothing else
    fitting.sort(key=lambda t: (t.type != "ball", t.diameter, -job.tools.index(t)), reverse=True)
    # and one that gets down into most of the model: a tool wider than the gaps between its features (a sign's
    # letters) removes nothing (the roughing op then refuses: no material to remove)
    xy_area = float(np.isfinite(an.design).sum()) * an.grid.cell_area
    into = [t for t in fitting if t.name not in an.reach or an.reach[t.name].far_area <= ROUGH_FAR_SHARE * xy_area]
    tool = into[0] if into else min(fitting, key=lambda t: an.reach[t.name].far_area)
    c = materials.cutting(job.material, tool.diameter, tool.flutes, job.machine.spindle_max, job.machine.feed_max)
    step_down = round(min(c.step_down, tool.flute_length), 3)
    plan.decide("roughing tool", tool.describe(),
                f"the largest {'flat or bull-nose ' if tool.type != 'ball' else ''}tool of the library that "
                f"reaches the {depth:.1f} mm depth ({reach_length(tool):g} mm), is at most "
                f"{ROUGH_WIDTH_SHARE:g} x the model's narrower side ({narrow:.1f} mm) and gets within {FAR_MM:g} mm of "
                f"at least {1 - ROUGH_FAR_SHARE:g} of its area from above (the reach test)")
    plan.decide("roughing layers", f"step-down at most {step_down:g} mm, stairs at most {ROUGH_STAIR:g} mm, "
                f"step-over {c.stepover_percent:g} %, leave {ROUGH_LEAVE:g} mm",
                f"{job.material}: {materials.TABLE[job.material][2]:g} x D per layer, at most the flute length "
                f"{tool.flute_length:g} mm; layers closer where the slopes would keep stairs over {ROUGH_STAIR:g} mm "
                f"(seed 000 eq. 3.11: the finishing tool takes at most that, its rapids stay out of the stock), a "
                f"layer on each plateau; {ROUGH_LEAVE:g} mm left for the finishing passes")
    kwargs = api_tool(tool) | feeds(plan, job, tool) | {
        "step_down": step_down, "layer_mode": "tolerance", "remaining_height": ROUGH_STAIR,
        "stepover_percent": round(c.stepover_percent, 1), "stock_to_leave": ROUGH_LEAVE,
        "stock": list(plan.stock_box), "post": job.machine.post}
    if tool.flute_length - ROUGH_SHANK_CLEAR < depth:
        # below its flutes the shank (as wide as the cut) would rub the walls the layers leave ROUGH_LEAVE from
        kwargs["final_z"] = round(plan.stock_box[5] - tool.flute_length + ROUGH_SHANK_CLEAR, 4)
        plan.decide("roughing depth", f"down to Z{kwargs['final_z']:g}",
                    f"{tool.name}'s flutes are {tool.flute_length:g} mm long, the depth {depth:.1f} mm: deeper, its "
                    f"shank would rub the walls {ROUGH_LEAVE:g} mm away (the flutes' top kept {ROUGH_SHANK_CLEAR:g} "
                    "mm above the stock: the shank's clearance); the finishing ops take what is below")
    plan.ops.append(OpPlan("run_roughing", f"Roughing {tool.name}", tool.name, kwargs))
    return tool


def largest_ball(radiused: list) -> ToolSpec:
    balls = [t for t in radiused if t.type == "ball"] or radiused
    return max(balls, key=lambda t: (t.corner_radius, t.diameter, -radiused.index(t)))


def transition_from(comparison: Any, winner: str, ball: str) -> Optional[float]:
    """The lower edge of the first slope band (from the flat up) where the ball leaves less than the winner; None
    when it never does (or they are the same tool)."""
    if winner == ball:
        return None
    by = {s.label: s.by_slope for s in comparison.scores}
    for band in sorted(by[winner]):
        w, b = by[winner][band], by[ball][band]
        if not (math.isnan(w) or math.isnan(b)) and b < w:
            return band[0]
    return None


def transition_of(cmp: Any, tool: ToolSpec, ball: ToolSpec) -> tuple[float, str]:
    """The transition slope (deg) with `tool` as the shallow cutter and its reason: where the comparison finds
    the ball leaving less, kept within TRANSITION_RANGE, else TRANSITION_DEG."""
    edge = transition_from(cmp, tool.name, ball.name)
    if edge is None:
        return TRANSITION_DEG, (f"the ball {ball.name} never leaves less than {tool.name} in a slope band: the "
                                "default split" if tool is not ball else "the ball everywhere: the default split")
    return float(np.clip(edge, *TRANSITION_RANGE)), (
        f"the ball {ball.name} leaves less than {tool.name} from {edge:g} deg up (mean left per slope band in the "
        f"comparison), kept within {TRANSITION_RANGE[0]:g}-{TRANSITION_RANGE[1]:g} deg")


def reaching(plan: Plan, an: Analysis, radiused: list) -> list:
    """The radiused tools that reach the model's lowest point from its top (the finishing and rest tools)."""
    height = an.size[2]
    out = [t for t in radiused if reach_length(t) >= height]
    if not out:
        longest = max(radiused, key=reach_length)
        raise PlanInputError(f"tools: no ball or bull-nose tool reaches the model's height {height:.1f} mm; the "
                             f"longest, {longest.name}, reaches {reach_length(longest):g} mm")
    short = [f"{t.name} ({reach_length(t):g} mm)" for t in radiused if t not in out]
    if short:
        plan.decide("tools left out", ", ".join(short), f"they do not reach the model's {height:.1f} mm height "
                    "(stick-out from the holder, else the flute length)")
    return out


def finishing_candidates(plan: Plan, an: Analysis, radiused: list) -> list:
    """The tools fit to finish: wide at most ROUGH_WIDTH_SHARE of the model's narrower side (the smallest
    otherwise) and at least as wide as the largest such ball: a smaller tool would finish the whole part at its
    small step-over for details the rest op takes with it (seed 003 compares cutters of one size class)."""
    narrow = min(an.size[0], an.size[1])
    fitting = [t for t in radiused if t.diameter <= ROUGH_WIDTH_SHARE * narrow] or \
        [min(radiused, key=lambda t: (t.diameter, radiused.index(t)))]
    ball = largest_ball(fitting)
    chosen = [t for t in fitting if t.diameter >= ball.diameter]
    left_out = [t.name for t in radiused if t not in chosen]
    plan.decide("finishing candidates", ", ".join(t.name for t in chosen),
                f"radiused tools reaching the model's {an.size[2]:.1f} mm height, at most "
                f"{ROUGH_WIDTH_SHARE:g} x its narrower side ({narrow:.1f} mm) and at least as wide as the largest "
                f"ball {ball.name}" + (f"; left for the rest: {', '.join(left_out)}" if left_out else ""))
    return chosen


def choose_finishing(plan: Plan, job: JobSpec, an: Analysis, mesh: TriMesh, radiused: list,
                     compare: Any) -> tuple[ToolSpec, ToolSpec, float]:
    """(shallow raster tool, steep waterline tool, transition slope deg) among `radiused`, the candidates."""
    ball = largest_ball(radiused)
    cusp = job.finish.cusp
    step = stepover_for_cusp(cutter_of(ball), cusp)
    if step < MIN_STEPOVER:
        raise PlanInputError(f"finish.cusp: {cusp:g} mm needs a step-over of {step:.4f} mm with the largest ball "
                             f"{ball.name}, finer than {MIN_STEPOVER:g} mm: tighter than the library's tools "
                             f"leave in a sensible time")
    plan.decide("steep finishing tool", ball.describe(), "seed 003 (Fig. 4.9): a ball leaves the least on steep "
                "slopes; the largest ball of the library")
    candidates = sorted(radiused, key=lambda t: (-t.diameter, -t.corner_radius, radiused.index(t)))[:MAX_COMPARED]
    if compare is None or len(candidates) < 2:
        why = "the comparison is off in the job file" if compare is None else "one finishing candidate"
        plan.decide("shallow finishing tool", ball.describe(), f"{why}: the steep areas' ball")
        plan.decide("transition slope", f"{TRANSITION_DEG:g} deg", "the default split (no comparison)")
        return ball, ball, TRANSITION_DEG
    cmp = compare(mesh, [(t.name, cutter_of(t)) for t in candidates], stepover=round(step, 4))
    by_volume = next(t for t in candidates if t.name == cmp.scores[0].label)
    splits = {t.name: transition_of(cmp, t, ball) for t in candidates}
    steps = {t.name: stepover_for_cusp(cutter_of(t), cusp, splits[t.name][0]) for t in candidates}
    # the finish's cusp, not the volume at one step-over, sets each tool's raster: the raster's length goes with
    # 1 / its step-over; the comparison's rank decides between step-overs within STEP_TIE of the largest
    widest = max(steps.values())
    best = next(t for t in (next(c for c in candidates if c.name == s.label) for s in cmp.scores)
                if steps[t.name] >= (1 - STEP_TIE) * widest)
    transition, why = splits[best.name]
    plan.decide("shallow finishing tool", best.describe(),
                "the largest step-over keeping the finish's cusp up to each tool's transition slope ("
                + ", ".join(f"{t.name} {steps[t.name]:.3f} mm at {splits[t.name][0]:g} deg" for t in candidates)
                + f"; the raster's time goes with 1 / step-over); seed 003 section 4.2: the same raster (step-over "
                f"{step:.3f} mm, the ball's for the cusp) with {len(candidates)} radiused tools simulated, ranked by "
                f"the volume left" + (f" ({by_volume.name} first: at its own cusp step-over it would take "
                                      f"{steps[best.name] / steps[by_volume.name]:.2f} x the passes)"
                                      if by_volume is not best else "") + ": " + " | ".join(cmp.reasons))
    plan.decide("transition slope", f"{transition:g} deg", why)
    return best, ball, transition


def sample_step(tool: ToolSpec) -> float:
    """A raster's sampling along its passes: a twentieth of the diameter, within 0.1-0.5 mm."""
    return round(min(0.5, max(0.1, tool.diameter / 20.0)), 3)


def finishing_ops(plan: Plan, job: JobSpec, an: Analysis, shallow: ToolSpec, steep: ToolSpec,
                  transition: float) -> None:
    cusp, tol = job.finish.cusp, job.finish.tolerance
    steep_share = an.share_steeper(transition)
    common = {"post": job.machine.post}
    if 1.0 - steep_share >= MIN_SHARE:
        sample = sample_step(shallow)
        # the steepest slope the raster cuts sets its step-over (the op's own cusp mode measures the crossings
        # of the whole surface: 40x slower on beet_mm, and its curvature term is not needed on a planned split)
        step = math.floor(stepover_for_cusp(cutter_of(shallow), cusp, transition) * 1000) / 1000
        kwargs = api_tool(shallow) | feeds(plan, job, shallow) | common | {
            "stepover": step, "sample_step": sample, "slope_range": [0.0, transition], "off_model": "skip",
            "chord_tolerance": round(min(0.01, tol / 2), 4)}
        plan.ops.append(OpPlan("run_surface", f"Finish shallow {shallow.name}", shallow.name, kwargs))
        plan.decide("shallow finishing", f"raster 0-{transition:g} deg, step-over {step:g} mm",
                    f"{(1 - steep_share) * 100:.0f} % of the model seen from above slopes less than "
                    f"{transition:g} deg; the step-over keeps the cusp {cusp:g} mm on a {transition:g} deg plane "
                    f"across the passes, the steepest the raster cuts; it lifts where no part of the model lies under "
                    "the tool (a through hole, beside the model: nothing to finish there; along the model's lowest "
                    "point it drove the shank into the stock the roughing left in a hole's corners)")
    else:
        plan.decide("shallow finishing", "none", f"less than {MIN_SHARE * 100:g} % of the model is shallow")
    if steep_share >= MIN_SHARE:
        c = cutter_of(steep)
        t = math.radians(transition)
        step_down = min(steep.corner_radius, stepover_for_cusp(c, cusp, transition) * math.tan(t))
        step_down = math.floor(step_down * 1000) / 1000
        kwargs = api_tool(steep) | feeds(plan, job, steep) | common | {"step_down": step_down}
        plan.ops.append(OpPlan("run_waterline", f"Finish steep {steep.name}", steep.name, kwargs))
        plan.decide("steep finishing", f"waterline, step-down {step_down:g} mm",
                    f"{steep_share * 100:.0f} % of the model seen from above slopes more than {transition:g} deg; "
                    f"levels {step_down:g} mm apart keep the cusp {cusp:g} mm from {transition:g} deg up")
    else:
        plan.decide("steep finishing", "none", f"less than {MIN_SHARE * 100:g} % of the model is steeper than "
                    f"{transition:g} deg")


def walls_op(plan: Plan, job: JobSpec, an: Analysis, finishing: list) -> None:
    """Walls deeper than the finishing tools' flutes: their shanks would pass within their clearance of the stock
    the roughing leaves on them (a guard keeps the clearance from the design, not from the stock). The flat or
    bull-nose tool whose flutes reach deepest finishes them first by waterline, nothing left, as deep as its own
    shank stays clear; the finishing tools' guards then keep them clear of the finished walls."""
    top = plan.stock_box[5]
    depth = top - an.bounds[0][2]
    held = [t for t in finishing if t.holder is not None]   # a tool without a holder: no shank is checked
    short = min((t.flute_length - ROUGH_SHANK_CLEAR for t in held), default=depth)
    if short >= depth or an.share_steeper(WALL_DEG) < MIN_SHARE:
        return
    sides = [t for t in job.tools if t.type != "ball" and reach_length(t) >= depth
             and t.flute_length - ROUGH_SHANK_CLEAR > short]
    names = ", ".join(dict.fromkeys(t.name for t in held))
    if not sides:
        plan.decide("deep walls", "none", f"{names}: flutes shorter than the {depth:.1f} mm depth, and no flat or "
                    "bull-nose library tool with longer flutes reaches it (their shanks may meet the walls' stock)")
        return
    tool = max(sides, key=lambda t: (t.flute_length, t.diameter, -job.tools.index(t)))
    bottom = max(an.bounds[0][2], top - tool.flute_length + ROUGH_SHANK_CLEAR)
    c = materials.cutting(job.material, tool.diameter, tool.flutes, job.machine.spindle_max, job.machine.feed_max)
    step_down = round(min(c.step_down, tool.flute_length), 3)
    kwargs = api_tool(tool) | feeds(plan, job, tool) | {
        "step_down": step_down, "stock_to_leave": 0.0, "top_z": round(an.bounds[1][2], 4),
        "bottom_z": round(bottom, 4), "chord_tolerance": round(min(0.01, job.finish.tolerance / 2), 4),
        "post": job.machine.post}
    plan.ops.insert(1, OpPlan("run_waterline", f"Finish walls {tool.name}", tool.name, kwargs))
    # the plateaus first (the tops of the walls keep the stock over the model when it is within the roughing's
    # stairs): faced flat, nothing left, so a later shank passing a wall's top at its clearance meets no stock
    face = api_tool(tool) | feeds(plan, job, tool) | {
        "stepover": round(c.stepover_percent / 100 * tool.diameter, 3), "sample_step": sample_step(tool),
        "slope_range": [0.0, PLATEAU_DEG], "off_model": "skip", "final_depth": kwargs["bottom_z"],
        "chord_tolerance": kwargs["chord_tolerance"], "post": job.machine.post}
    plan.ops.insert(1, OpPlan("run_surface", f"Face plateaus {tool.name}", tool.name, face))
    plan.decide("deep walls", f"{tool.describe()}: waterline Z{bottom:g}-{an.bounds[1][2]:g}, step-down "
                f"{step_down:g} mm, nothing left, after the roughing",
                f"{an.share_steeper(WALL_DEG) * 100:.0f} % of the model seen from above slopes more than "
                f"{WALL_DEG:g} deg and the stock is {depth:.1f} mm deep; more than {short:g} mm below its top the "
                f"finishing tools ({names}) hold their shanks, as wide as the cut, within their clearance of the "
                f"{ROUGH_LEAVE:g} mm the roughing leaves on a wall; {tool.name}'s {tool.flute_length:g} mm flutes "
                f"finish the walls first (its shank {ROUGH_SHANK_CLEAR:g} mm above the stock; a flat's side cuts a "
                f"wall over its flutes' length: levels the roughing's step-down apart), so the later shanks pass the "
                f"finished walls at their clearance; before it the plateaus (within {PLATEAU_DEG:g} deg) faced flat, "
                f"step-over {face['stepover']:g} mm: the walls' tops keep the stock above the model where it is "
                "within the roughing's stairs")


def rest_op(plan: Plan, job: JobSpec, an: Analysis, finishing: list, radiused: list) -> Optional[ToolSpec]:
    """A smaller radiused tool where the finishing tools leave material out of their reach that it reaches (the
    rest tool, None without one)."""
    left = min(an.reach[t.name].unreached_area for t in finishing)
    if left == 0.0:
        plan.decide("rest", "none", "the reach tests find nothing the finishing tools leave")
        return None
    smaller = [t for t in radiused if t.diameter < min(f.diameter for f in finishing)
               and an.reach[t.name].unreached_area < left]
    if not smaller:
        plan.decide("rest", "none", f"the finishing tools leave {left:.0f} mm2 out of reach and no smaller library "
                    "tool reaches more (reported as left)")
        return None
    tool = max(smaller, key=lambda t: (t.diameter, -radiused.index(t)))
    step = rest_raster(plan, job, tool, f"Rest {tool.name}")
    plan.decide("rest", tool.describe(),
                f"the finishing tools leave {left:.0f} mm2 out of reach (reach test); {tool.name} leaves "
                f"{an.reach[tool.name].unreached_area:.0f} mm2; raster over what the earlier ops leave, step-over "
                f"{step:g} mm for the cusp")
    return tool


def rest_raster(plan: Plan, job: JobSpec, tool: ToolSpec, label: str) -> float:
    """An optional raster of `tool` over what the earlier ops leave that it reaches, its step-over the cusp's
    (returned)."""
    step = round(stepover_for_cusp(cutter_of(tool), job.finish.cusp), 4)
    kwargs = api_tool(tool) | feeds(plan, job, tool) | rest_args(job, tool) | {"stepover": step}
    plan.ops.append(OpPlan("run_surface", label, tool.name, kwargs, optional=True))
    return step


def rest_args(job: JobSpec, tool: ToolSpec) -> dict:
    """A rest op's region: where more than the tolerance is left by the earlier ops that `tool` reaches."""
    return {"region": "rest", "rest_from": "earlier_ops", "rest_tolerance": job.finish.tolerance,
            "sample_step": sample_step(tool), "post": job.machine.post}


def pencil_op(plan: Plan, job: JobSpec, an: Analysis, rest: ToolSpec, radiused: list) -> Optional[ToolSpec]:
    """After the rest: the smaller radiused tool that reaches the most of what the rest tool leaves, along the
    concave creases (where it touches the model on two sides), with passes outward the cusp's step-over apart
    across the band between its radius and the rest tool's, only where more than the tolerance is left; when the
    reach tests say it reaches at least PENCIL_GAIN of the model seen from above that the rest tool does not (a
    ball D2.8 after a D3 on the sign: 0.2 %, a D1: 15 %). (Seed 000's clean-up strips
    were tried: on beet_mm they joined the rest tool's out-of-reach undercuts into 92,805 flank passes, minutes
    of computing; this pencil took 13 s and the same corners, 48.2 -> 11.2 mm3.)"""
    left = an.reach[rest.name].unreached_area
    least = PENCIL_GAIN * an.seen_area
    smaller = [t for t in radiused if t.diameter < rest.diameter
               and left - an.reach[t.name].unreached_area >= least]
    if left == 0.0 or not smaller:
        plan.decide("pencil", "none", f"the rest tool {rest.name} leaves {left:.0f} mm2 out of reach and no "
                    f"smaller library tool reaches {least:.0f} mm2 ({PENCIL_GAIN:g} of the model seen from above) "
                    "of it (reported as left)")
        return None
    tool = min(smaller, key=lambda t: (an.reach[t.name].unreached_area, -t.diameter, radiused.index(t)))
    step = round(stepover_for_cusp(cutter_of(tool), job.finish.cusp), 4)
    passes = min(50, 1 + math.ceil((rest.corner_radius - tool.corner_radius) / step))
    kwargs = api_tool(tool) | feeds(plan, job, tool) | rest_args(job, tool) | {
        "pattern": "pencil", "pencil_source": "creases", "pencil_passes": passes, "stepover": step}
    plan.ops.append(OpPlan("run_surface", f"Pencil {tool.name}", tool.name, kwargs, optional=True))
    plan.decide("pencil", tool.describe(),
                f"the rest tool {rest.name} leaves {left:.0f} mm2 out of reach (reach test), {tool.name} "
                f"{an.reach[tool.name].unreached_area:.0f} mm2: along the concave creases (seed 003 section 4.5), "
                f"{passes} passes {step:g} mm apart outward over the band between the two tools' radii, only where "
                f"more than {job.finish.tolerance:g} mm is left")
    return tool


def cleanup_op(plan: Plan, job: JobSpec, tool: ToolSpec) -> None:
    """After the pencil: the pencil's tool as a raster over what the earlier ops still leave that it reaches (the
    pencil's passes follow the creases: on pycam_textbox they left 395 mm2 of the floor between the letters, most
    0.54 mm, where the D1 reaches and the D3 does not). Optional, as the rest."""
    step = rest_raster(plan, job, tool, f"Clean-up {tool.name}")
    plan.decide("clean-up", tool.describe(),
                f"the pencil's passes follow the creases; what they and the earlier ops leave more than "
                f"{job.finish.tolerance:g} mm above the model where {tool.name} reaches (between letters, on floors "
                f"narrower than the rest tool) is taken by a raster of it, step-over {step:g} mm for the cusp")


def plan_job(job: JobSpec, mesh: TriMesh, an: Analysis, compare: Any = None,
             stock: Optional[PlannedStock] = None) -> Plan:
    """The ops and decisions for `job` on its placed `mesh` with its analysis `an` (reach-tested with every
    library tool); `compare`: core.plan.optimal_cutter.compare_cutters bound to its cell (None: not compared);
    `stock`: the job's planned_stock when the caller has it (else found here)."""
    plan = Plan(stock if stock is not None else planned_stock(job, mesh))
    radiused = [t for t in job.tools if t.corner_radius > 0]
    if not radiused:
        raise PlanInputError("tools: no ball or bull-nose tool in the library; a sculptured surface is finished "
                             "with a radiused tool")
    plan.decide("model", f"{an.size[0]:.1f} x {an.size[1]:.1f} x {an.size[2]:.1f} mm, {an.triangles} triangles",
                f"slope shares {an.slope_area}, flat {an.flat_share * 100:.0f} %, facing down "
                f"{an.down_share * 100:.1f} % (never reached from above)")
    choose_roughing(plan, job, an)
    radiused = reaching(plan, an, radiused)
    plan.reach_tool = min(radiused, key=lambda t: (an.reach[t.name].unreached_area, t.corner_radius,
                                                   radiused.index(t))).name
    shallow, steep, transition = choose_finishing(plan, job, an, mesh, finishing_candidates(plan, an, radiused),
                                                  compare)
    finishing_ops(plan, job, an, shallow, steep, transition)
    walls_op(plan, job, an, [shallow, steep])
    rest = rest_op(plan, job, an, [shallow, steep], radiused)
    pencil = None if rest is None else pencil_op(plan, job, an, rest, radiused)
    if pencil is not None:
        cleanup_op(plan, job, pencil)
    return plan
