"""G-code for the Tarus 5-axis mill from TMM's 5-axis Path representation (core.path5).

Two output modes:
* joints (default; a control without tool-centre-point mode): every motion line is the machine position
  X Y Z A C from `TarusMachine.inverse`: X, Y, Z are the pivot point (pivot-compensated: the tip plus
  (pivot length + tool length) along the tool axis), so tool length compensation stays off (G49).
* TCP (`tcp=True`; a control with tool-centre-point mode, e.g. Fanuc G43.4): X, Y, Z are the tool tip,
  A, C the joint angles; TCP is switched on with `G43.4 H<tool>` after each tool change, off with G49.
A and C are printed in degrees, never scaled by `inches`. A is planned per cut (core.machine.rotary): each
cut, with its approach and retract, gets the whole turns (and C branch) that keep it inside the A limits
(default +-360 deg) with the least A travel, so A unwinds only at the transits above the part, never inside
a cut; a cut that cannot fit raises RotaryPlanError naming its commands.
Joint mode: a G1 that turns A or C is split into pieces until a control interpolating the joints linearly
keeps the tip within `tip_tolerance` (default 0.005 mm) of the straight line and the axis within
`axis_tolerance` (default 0.05 deg) of its interpolation. A G1 whose axis passes within half the axis
tolerance (at most 0.025 deg) of the vertical goes through it: C down to 0, A turned there (it moves nothing), then on, A's way
round chosen for the limits (core.machine.rotary). TCP mode writes the tip and axis as given, split
only where the control's linear A and C would leave the axis interpolation by more than `axis_tolerance`.
Feeds: a G1 at a constant orientation uses G94 with F in mm/min (in/min); a G1 that turns A or C uses
inverse time (G93, F = 1 / minutes). Either way the move's time is the longer of tip distance / feed and
the joint motion time at the machine's joint speeds (seed 000 eq. 3.121-3.123), so every move can be done
in its programmed time; the estimated cycle time adds up the same times. Rapids carry no F. Arcs (G2/G3)
are allowed at a constant orientation.
A move out of the joint limits raises `JointLimitError` (a TmmError) naming the operation, the command,
the joint and its value: nothing is written.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine import rotary
from tmm_workbench.core.machine.tarus import JointLimitError, Joints, TarusMachine
from tmm_workbench.core.path5 import AXIS_WORDS, MOTION_NAMES, TIP_WORDS, Pose, decode
from tmm_workbench.core.post import (MM_PER_INCH, ArgumentParser, Operation, Program, ToolInfo, comment_text,
                                     is_comment, number, post_argument_parser, strip_comment, write_program)

_CANONICAL = {"G00": "G0", "G01": "G1", "G02": "G2", "G03": "G3"}
_INT_WORDS = ("T", "H", "D", "S", "L", "P")


@dataclass
class TarusOptions:
    """tcp: tip coordinates for a control in TCP mode (else pivot-compensated joints). inches: G20, lengths
    and linear feeds in inches (rotary words and inverse-time feeds unchanged). precision / angle_precision:
    decimals of lengths (and F) and of angles. comments: operation and tool comments. line_numbers: N words.
    program_end: 'M2' or 'M30'."""
    tcp: bool = False
    inches: bool = False
    tip_tolerance: float = 0.005                 # mm: joint-mode tip deviation from the straight line
    axis_tolerance: float = math.radians(0.05)   # rad: joint-mode axis deviation from its interpolation
    precision: int = 4
    angle_precision: int = 6
    comments: bool = True
    line_numbers: bool = False
    program_end: str = "M2"


@dataclass
class TarusResult:
    text: str
    cycle_time: float  # seconds, estimated from the joint speeds and feeds
    moves: int


class _Writer:
    def __init__(self, machine: TarusMachine, options: TarusOptions) -> None:
        self.m, self.o = machine, options
        self.lines: list[str] = []
        self.n = 0
        self.joints: Optional[Joints] = None  # machine position after the last motion
        self.tip: tuple[float, float, float] = (math.nan, math.nan, math.nan)
        self.feed_mode = "G94"
        self.tool: Optional[ToolInfo] = None
        self.coolant = "None"
        self.time = 0.0
        self.moves = 0
        # half the axis tolerance (at most the default's half) for taking the axis through the vertical, the
        # rest for the pieces around it
        self.pole_tol = min(0.5 * options.axis_tolerance, rotary.POLE_TOL)

    # --- formatting --------------------------------------------------------------------------
    def emit(self, text: str) -> None:
        if self.o.line_numbers and not text.startswith("%"):
            self.n += 10
            text = f"N{self.n} {text}"
        self.lines.append(text)

    def comment(self, text: str) -> None:
        if self.o.comments:
            self.emit(f"({comment_text(text)})")

    def length(self, v: float) -> str:
        return number(v / MM_PER_INCH if self.o.inches else v, self.o.precision)

    def angle(self, rad: float) -> str:
        return number(math.degrees(rad), self.o.angle_precision)

    def linear_feed(self, mm_s: float) -> str:
        per_min = mm_s * 60.0
        return self.feed_word(per_min / MM_PER_INCH if self.o.inches else per_min)

    def feed_word(self, value: float) -> str:
        """F rounded down at the precision: the programmed time is never shorter than the joints need."""
        scale = 10.0 ** self.o.precision
        return number(math.floor(value * scale * (1 + 1e-15)) / scale, self.o.precision)

    # --- program parts -----------------------------------------------------------------------
    def header(self) -> None:
        m, o = self.m, self.o
        self.emit("%")
        self.comment(f"TMM Tarus post - {m.name}")
        self.comment(f"head: A rotates about Z and carries the tilt C; pivot length {m.pivot_length:.3f} mm, "
                     f"tool length {m.tool_length:.3f} mm")
        if o.tcp:
            self.comment("output: X Y Z = tool tip, A C = joints; the control's TCP mode (G43.4) on")
        else:
            self.comment("output: X Y Z = pivot point (pivot-compensated joints), A C = joints; no TCP")
        self.comment(f"units: {'inch' if o.inches else 'mm'}; A and C in degrees")
        self.emit(f"G17 {'G20' if o.inches else 'G21'} G40 G49 G80 G90 G94")

    def tool_change(self, t: ToolInfo) -> None:
        shape = t.shape if t.shape and t.shape not in t.label else ""
        desc = " ".join(x for x in (t.label, shape, f"D{t.diameter:g}" if t.diameter else "") if x)
        self.comment(f"tool change: T{t.number} {desc}".rstrip())
        self.emit("M5")
        self.emit(f"T{int(t.number)} M6")
        if self.o.tcp:
            self.emit(f"G43.4 H{int(t.number)}")
        if t.spindle_dir != "OFF" and t.spindle_rpm > 0:
            self.emit(f"S{int(round(t.spindle_rpm))} {'M4' if t.spindle_dir == 'CCW' else 'M3'}")
        self.tool = t

    def footer(self) -> None:
        if self.coolant != "None":
            self.emit("M9")
        self.emit("M5")
        if self.feed_mode != "G94":
            self.emit("G94")
        if self.o.tcp:
            self.emit("G49")
        minutes, seconds = divmod(self.time, 60.0)
        self.comment(f"estimated cycle time {int(minutes)} min {seconds:.1f} s ({self.moves} moves, "
                     f"joint speeds and feeds)")
        self.emit(self.o.program_end)
        self.emit("%")

    def operation(self, op: Operation) -> None:
        self.comment(f"operation: {op.label}")
        if op.coolant in ("Flood", "Mist") and op.coolant != self.coolant:
            self.emit("M8" if op.coolant == "Flood" else "M7")
        elif op.coolant == "None" and self.coolant != "None":
            self.emit("M9")
        self.coolant = op.coolant if op.coolant in ("Flood", "Mist") else "None"
        pose = Pose()  # axis words are modal per Path, starting vertical (core.path5)
        pose.tip = self.tip  # coordinates not given yet are where the machine is
        items: list[tuple[int, str, Any, Optional[Pose]]] = []  # (index, name, params, pose of a motion)
        for i, (name, params) in enumerate(op.commands):
            up = str(name).upper()
            if is_comment(up) or up not in MOTION_NAMES:
                items.append((i, str(name), params, None))
                continue
            try:
                pose = decode(up, params, pose)
            except TmmError as exc:
                raise TmmError(f"operation '{op.label}', command {i} ({name}): {exc}") from None
            items.append((i, _CANONICAL.get(up, up), params, pose))
        motions = [(i, p) for i, name, _, p in items if p is not None]
        planned = self.plan(op, [(i, name, p) for i, name, _, p in items if p is not None])
        joints_of = {i: j for (i, _), j in zip(motions, planned)}
        for i, name, params, p in items:
            if p is None:
                if is_comment(name.upper()):
                    self.comment(strip_comment(name))
                else:
                    self.other(op, i, name, params)
                continue
            try:
                self.motion(name, p, params, i, joints_of[i])
            except JointLimitError as exc:
                raise JointLimitError(f"operation '{op.label}', command {i} ({name}): {exc}", exc.joint,
                                      exc.value, exc.limits, i) from None
            except TmmError as exc:
                raise TmmError(f"operation '{op.label}', command {i} ({name}): {exc}") from None

    def plan(self, op: Operation, motions: list[tuple[int, str, Pose]]) -> np.ndarray:
        """Joints of the operation's motions, A planned per cut (core.machine.rotary)."""
        for i, name, p in motions:  # a tilted axis needs the whole tip
            tip = np.array(p.tip, dtype=float)
            vertical = math.hypot(p.axis[0], p.axis[1]) <= self.m.singular_tol and p.axis[2] > 0
            if np.isnan(tip).any() and not vertical:
                raise TmmError(f"operation '{op.label}', command {i} ({name}): the tool position {tuple(tip)} "
                               "is not fully known for a tilted tool axis")
        moves = [rotary.Move(tuple(p.tip), tuple(p.axis), name == "G0") for _, name, p in motions]
        a_start = self.joints.a if self.joints is not None else None
        try:
            return rotary.plan(self.m, moves, a_start, self.pole_tol)
        except rotary.RotaryPlanError as exc:
            first, last = motions[exc.first][0], motions[exc.last][0]
            raise rotary.RotaryPlanError(f"operation '{op.label}', commands {first}..{last}: {exc}",
                                         first, last) from None
        except JointLimitError as exc:
            i, name, _ = motions[exc.index] if exc.index is not None else (None, "?", None)
            raise JointLimitError(f"operation '{op.label}', command {i} ({name}): "
                                  f"{TarusMachine._limit_message(exc.joint, exc.value, exc.limits)} ({self.m.name})",
                                  exc.joint, exc.value, exc.limits, i) from None

    def other(self, op: Operation, i: int, name: str, params: Mapping[str, Any]) -> None:
        if any(w in params for w in TIP_WORDS + AXIS_WORDS + ("A", "B", "C")):
            raise TmmError(f"operation '{op.label}', command {i}: '{name}' with coordinates is not supported "
                           f"by the Tarus post (only G0, G1, G2, G3 move the tool)")
        if name.upper() in ("G91", "G20", "G21", "G93", "G94"):
            raise TmmError(f"operation '{op.label}', command {i}: '{name}' would change the post's modes")
        words = [name]
        for k, v in params.items():
            words.append(f"{k}{int(v)}" if k in _INT_WORDS else f"{k}{number(float(v), self.o.precision)}")
        self.emit(" ".join(words))

    def motion(self, name: str, pose: Pose, params: Mapping[str, Any], index: int, planned: np.ndarray) -> None:
        m = self.m
        tip = np.array(pose.tip, dtype=float)
        known = ~np.isnan(tip)
        j = Joints.from_array(planned)
        prev = self.joints
        turns = _turns(prev, j)
        if name == "G0":
            for step in self.a_steps(prev, j):  # an unwinding turn in steps of at most 90 degrees of A
                step_tip = tip if step is j else m.forward(step.as_array())[0]
                self.emit("G0 " + self.words(step_tip, step, known))
                self.advance(step, step_tip, m.motion_time(self.joints, step) if self.joints is not None else 0.0)
            return
        feed = pose.feed
        if feed is None or not feed > 0:
            raise TmmError(f"{name} without a feed rate (F {feed})")
        if name in ("G2", "G3"):
            if turns or prev is None:
                raise TmmError("an arc must keep the tool orientation (A and C) of the move before it")
            extra = " ".join(f"{w}{self.length(float(params[w]))}" for w in ("I", "J", "K", "R") if w in params)
            dist = self.distance(tip, known)
            seconds = max(dist / feed if math.isfinite(dist) else 0.0, m.motion_time(prev, j))
            self.emit(f"{self.set_feed_mode('G94')}{name} {self.words(tip, j, known)} {extra} "
                      f"F{self.linear_feed(feed)}")
            self.advance(j, tip, seconds)
            return
        if not (turns and known.all() and not np.isnan(self.tip).any()):
            self.linear(name, j, tip, feed, known)
            return
        # TCP: the control keeps the tip on its line but turns A and C linearly, so only the axis is held to
        # its tolerance; joint mode: both
        tip_tol = math.inf if self.o.tcp else self.o.tip_tolerance
        start, tip0 = prev.as_array(), np.array(self.tip)
        tip_dev, axis_dev = rotary.deviation(m, start, planned)
        if tip_dev <= tip_tol and axis_dev <= self.o.axis_tolerance:  # the control follows it as it is
            self.linear(name, j, tip, feed, known)
            return
        pole = self.pole_crossing(start, planned)
        if pole is None:
            if abs(prev.c) <= m.singular_tol and abs(j.a - prev.a) > 1e-12:
                # leaving the vertical: turn A first, where it moves neither tip nor axis
                start = np.array([prev.x, prev.y, prev.z, j.a, prev.c])
                self.linear(name, Joints.from_array(start), tip0, feed, known)
            self.follow(name, start, planned, tip, feed, known, tip_tol, self.o.axis_tolerance)
            return
        # through the vertical: there at the A it has, A turned at C = 0, then on at its new A; the pole point
        # is off the move's slerp by at most pole_tol, the rest of the tolerance is the pieces'
        pole_tip = tip0 + (tip - tip0) * pole
        pivot = pole_tip + np.array([0.0, 0.0, m.length])
        arrive = np.array([*pivot, prev.a, 0.0])
        leave = np.array([*pivot, j.a, 0.0])
        axis_tol = self.o.axis_tolerance - self.pole_tol
        for a, b, b_tip in ((start, arrive, pole_tip), (arrive, leave, pole_tip), (leave, planned, tip)):
            if np.abs(b - a).max() > 1e-12:
                self.follow(name, a, b, b_tip, feed, known, tip_tol, axis_tol)

    def pole_crossing(self, j0: np.ndarray, j1: np.ndarray) -> Optional[float]:
        """The fraction of the move j0 -> j1 where its axis passes within pole_tol of the vertical (the
        planner freed A there), None if it does not."""
        if not rotary.snaps_to_pole(self.m, self.pole_tol):
            return None
        d, s = rotary.pole_pass(self.m.forward(j0)[1], self.m.forward(j1)[1])
        return s if d <= self.pole_tol * (1 + 1e-9) else None  # the slack: the planner's A turns, rounded

    def follow(self, name: str, j0: np.ndarray, j1: np.ndarray, tip: np.ndarray, feed: float, known: np.ndarray,
               tip_tol: float, axis_tol: float) -> None:
        """The G1 from j0 (where the machine is) to j1 (tip `tip`), in pieces where the control's linear
        joints would leave the tolerances (the pieces' tips are on the straight line: subdivide's targets)."""
        pieces = [j1]
        tip_dev, axis_dev = rotary.deviation(self.m, j0, j1)
        if tip_dev > tip_tol or axis_dev > axis_tol:
            pieces = list(rotary.subdivide(self.m, j0, j1, tip_tol, axis_tol))
        for k, piece in enumerate(pieces):
            piece_tip = tip if k == len(pieces) - 1 else self.m.forward(piece)[0]
            self.linear(name, Joints.from_array(piece), piece_tip, feed, known)

    def a_steps(self, prev: Optional[Joints], j: Joints) -> list[Joints]:
        """The joints j reached in equal linear joint steps of at most 90 degrees of A (a control may take a
        rotary move of 180 degrees or more the other way round); [j] for a smaller move."""
        if prev is None or abs(j.a - prev.a) <= math.pi / 2:
            return [j]
        n = math.ceil(abs(j.a - prev.a) / (math.pi / 2))
        p0, p1 = prev.as_array(), j.as_array()
        if np.isnan(p0).any():
            p0 = np.where(np.isnan(p0), p1, p0)
        return [Joints.from_array(p0 + (p1 - p0) * k / n) for k in range(1, n)] + [j]

    def linear(self, name: str, j: Joints, tip: np.ndarray, feed: float, known: np.ndarray) -> None:
        """One G1 (or a piece of one) at `feed` mm/s, no faster than the joints can go; A turns of more than
        90 degrees in steps (a_steps), along the same joint motion."""
        steps = self.a_steps(self.joints, j)
        if len(steps) > 1:
            start = np.array(self.tip)
            for k, step in enumerate(steps, 1):
                if step is j:
                    step_tip = tip
                elif self.o.tcp:  # the control keeps the tip on its line: the steps' tips are on it too
                    step_tip = start + (tip - start) * k / len(steps)
                else:
                    step_tip = self.m.forward(step.as_array())[0]
                self.linear(name, step, step_tip, feed, known)
            return
        prev = self.joints
        joint_time = self.m.motion_time(prev, j) if prev is not None else 0.0
        dist = self.distance(tip, known)
        seconds = max(dist / feed if math.isfinite(dist) else 0.0, joint_time)
        words = self.words(tip, j, known)
        if _turns(prev, j):
            minutes = max(seconds, 1e-6) / 60.0
            line = f"{self.set_feed_mode('G93')}{name} {words} F{self.feed_word(1.0 / minutes)}"
        else:
            speed = dist / seconds if seconds > 0 and math.isfinite(dist) else feed  # capped by the joints
            line = f"{self.set_feed_mode('G94')}{name} {words} F{self.linear_feed(min(feed, speed))}"
        self.emit(line)
        self.advance(j, tip, seconds)

    def words(self, tip: Any, j: Joints, known: np.ndarray) -> str:
        """X Y Z (the tip in TCP mode, else the pivot point) where known, A and C."""
        xyz = tip if self.o.tcp else (j.x, j.y, j.z)
        out = [f"{w}{self.length(float(v))}" for w, v, k in zip("XYZ", xyz, known) if k]
        return " ".join(out + [f"A{self.angle(j.a)}", f"C{self.angle(j.c)}"])

    def distance(self, tip: np.ndarray, known: np.ndarray) -> float:
        if np.isnan(self.tip).any() or not known.all():
            return math.nan
        return float(np.linalg.norm(tip - np.array(self.tip)))

    def advance(self, j: Joints, tip: np.ndarray, seconds: float) -> None:
        self.time += seconds
        self.moves += 1
        self.joints = j
        self.tip = tuple(float(v) for v in tip)  # type: ignore[assignment]

    def set_feed_mode(self, mode: str) -> str:
        if mode == self.feed_mode:
            return ""
        self.feed_mode = mode
        return mode + " "


def _turns(prev: Optional[Joints], j: Joints) -> bool:
    """The move from prev to j turns A or C."""
    return prev is not None and (abs(j.a - prev.a) > 1e-12 or abs(j.c - prev.c) > 1e-12)


def write_tarus(program: Program, machine: Optional[TarusMachine] = None,
                options: Optional[TarusOptions] = None) -> TarusResult:
    """Tarus G-code for `program` (tool changes and operations in order). Raises TmmError (JointLimitError
    for limits) before anything is returned."""
    w = _Writer(machine or TarusMachine(), options or TarusOptions())
    write_program(w, program)
    return TarusResult("\n".join(w.lines) + "\n", w.time, w.moves)


def argument_parser() -> ArgumentParser:
    p = post_argument_parser("tarus", "G20, lengths in inches (A and C stay in degrees)",
                             "no comments in the output")
    p.add_argument("--tcp", action="store_true",
                   help="tool-centre-point mode: X Y Z = tool tip (control with TCP, G43.4); default: "
                        "pivot-compensated joint coordinates")
    p.add_argument("--line-numbers", action="store_true", help="N words on every line")
    p.add_argument("--precision", type=int, default=4, help="decimals of lengths and feeds (default 4)")
    p.add_argument("--angle-precision", type=int, default=6, help="decimals of A and C degrees (default 6)")
    p.add_argument("--pivot-length", type=float, help="pivot point to spindle gauge line, mm (default 150)")
    p.add_argument("--tool-length", type=float, help="spindle gauge line to tool tip, mm (default 100)")
    p.add_argument("--c-min", type=float, help="tilt limit, degrees (default 0)")
    p.add_argument("--c-max", type=float, help="tilt limit, degrees (default 45)")
    p.add_argument("--a-min", type=float, help="rotation limit, degrees (default -360)")
    p.add_argument("--a-max", type=float, help="rotation limit, degrees (default 360)")
    p.add_argument("--program-end", choices=("M2", "M30"), default="M2", help="program end word")
    p.add_argument("--tip-tolerance", type=float, default=0.005,
                   help="joint mode: largest tip deviation from the straight line, mm (default 0.005)")
    p.add_argument("--axis-tolerance", type=float, default=0.05,
                   help="joint mode: largest tool axis deviation from its interpolation, degrees (default 0.05)")
    p.add_argument("--a-continuous", action="store_true",
                   help="A turns without limits (default: --a-min -360 --a-max 360)")
    return p


def parse_args(argstring: Optional[str]) -> tuple[TarusMachine, TarusOptions]:
    """Machine settings and options from a post argument string (TmmError for bad arguments)."""
    a = argument_parser().parse_post_args(argstring)
    base = TarusMachine()
    kw: dict[str, Any] = {}
    if a.pivot_length is not None:
        kw["pivot_length"] = a.pivot_length
    if a.tool_length is not None:
        kw["tool_length"] = a.tool_length
    c_lo = math.radians(a.c_min) if a.c_min is not None else base.c_limits[0]
    c_hi = math.radians(a.c_max) if a.c_max is not None else base.c_limits[1]
    kw["c_limits"] = (c_lo, c_hi)
    if (a.a_min is None) != (a.a_max is None):
        raise TmmError("tarus post arguments: give both --a-min and --a-max, or neither")
    if a.a_min is not None:
        kw["a_limits"] = (math.radians(a.a_min), math.radians(a.a_max))
    if a.a_continuous:
        if a.a_min is not None:
            raise TmmError("tarus post arguments: --a-continuous and --a-min/--a-max exclude each other")
        kw["a_limits"] = None
    if not (a.tip_tolerance > 0 and 0 < a.axis_tolerance < 90):
        raise TmmError("tarus post arguments: --tip-tolerance must be > 0 mm and --axis-tolerance in (0, 90) deg")
    if not (0 <= a.precision <= 12 and 0 <= a.angle_precision <= 12):
        raise TmmError("tarus post arguments: --precision and --angle-precision must be 0..12")
    machine = TarusMachine(**kw)
    options = TarusOptions(tcp=a.tcp, inches=a.inches, precision=a.precision, angle_precision=a.angle_precision,
                           comments=not a.no_comments, line_numbers=a.line_numbers, program_end=a.program_end,
                           tip_tolerance=a.tip_tolerance, axis_tolerance=math.radians(a.axis_tolerance))
    return machine, options


TOOLTIP_ARGS = argument_parser().format_help()
