"""The machine's view of Tarus G-code: the lines read back, the motion between them as a control without
tool-centre-point mode makes it (X Y Z A C interpolated linearly), and what a machinist checks on it: A
inside its limits and never more than 180 degrees in one line, every line doable in its programmed time at
the joint speeds, the tip within a tolerance of the straight line between programmed tips, A never turning
a whole turn inside a cut with the tool tilted (A unwinds only at the transits or where the tool is
vertical), and no number that is not one. It reads only the G-code (and the machine settings), never the tool path that made it.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from tmm_workbench.core.machine.rotary import deviation
from tmm_workbench.core.machine.tarus import TarusMachine

_VERTICAL = 1e-9  # rad: C this small is the vertical
_TURN = math.pi / 2 - 1e-9  # rad: an A step this large is a turn of the head, not the path's
_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


@dataclass
class Line:
    g: str                 # G0, G1, G2, G3
    joints: np.ndarray     # (5,) x, y, z (mm), a, c (rad); NaN where not known yet
    feed: float | None     # F word as written
    mode: str              # G93 (inverse time) or G94


def read_tarus(text: str) -> list[Line]:
    """The motion lines of Tarus G-code (mm, modal words carried)."""
    state = np.full(5, np.nan)
    mode, motion, out = "G94", None, []
    scale = 25.4 if re.search(r"^G17 G20", text, re.M) else 1.0
    for raw in text.splitlines():
        line = re.sub(r"\(.*?\)", "", raw).strip()
        words = _WORD.findall(line)
        for k, v in words:
            if k == "G" and float(v) in (93, 94):
                mode = f"G{int(float(v))}"
            elif k == "G" and float(v) in (0, 1, 2, 3):
                motion = f"G{int(float(v))}"
        if not any(k in "XYZAC" for k, _ in words):
            continue
        feed = None
        for k, v in words:
            if k in "XYZ":
                state["XYZ".index(k)] = float(v) * scale
            elif k in "AC":
                state[3 + "AC".index(k)] = math.radians(float(v))
            elif k == "F":
                feed = float(v)
        out.append(Line(motion or "G0", state.copy(), feed, mode))
    return out


@dataclass
class MachineView:
    lines: int = 0
    a_min: float = math.inf                 # rad
    a_max: float = -math.inf
    a_travel: float = 0.0                   # rad, all lines
    largest_a_step: float = 0.0             # rad, one line
    largest_tip_deviation: float = 0.0      # mm, cutting lines, from the chord between programmed tips
    largest_axis_deviation: float = 0.0     # rad, from the slerp between programmed axes
    too_fast: list[int] = field(default_factory=list)  # lines the joints cannot do in the programmed time
    deepest_cut: float = 0.0                # mm into the face along every line, rapids too (with `depth`)
    cycle_time: float = 0.0                 # s, from the programmed feeds and the joint speeds
    # cutting lines that turn A by a quarter turn or more with the tool tilted: an unwinding (or a half turn
    # through the vertical) inside a cut; on the vertical, C = 0, A may turn any way (the tool does not move)
    tilted_a_turns: list[int] = field(default_factory=list)
    not_numbers: int = 0                    # words that read as NaN or infinity


def view(machine: TarusMachine, text: str, tcp: bool = False, depth=None, samples: int = 8) -> MachineView:
    """The checks of the module doc on Tarus G-code written for `machine` (joint mode, or TCP mode where the
    control keeps the tip on its line: no deviation is measured there). With `depth` (tips, axes -> mm
    inside the part, e.g. tests/core/swept.py: FaceGouge), the tool is also checked at `samples` instances
    along every line (cuts, and the approach, retract and transit rapids), moved as the control moves it
    (joints linear, or in TCP mode the tip linear and A, C linear), and at its end."""
    lines = read_tarus(text)
    if tcp:  # X Y Z are the tip: the joints move the pivot point, tip + length along the axis
        for ln in lines:
            _, axis = machine.forward(np.array([0.0, 0.0, 0.0, ln.joints[3], ln.joints[4]]))
            ln.joints[:3] = ln.joints[:3] + machine.length * axis
    v = MachineView(lines=len(lines))
    speeds = machine.speeds.as_array()
    v.not_numbers = _not_numbers(text)
    prev = None
    for k, ln in enumerate(lines):
        j = ln.joints
        if not math.isnan(j[3]):
            v.a_min, v.a_max = min(v.a_min, j[3]), max(v.a_max, j[3])
        if prev is None or np.isnan(prev).any() or np.isnan(j).any():
            prev = j
            continue
        d = np.abs(j - prev)
        joint_time = float(np.max(d / speeds))
        v.a_travel += d[3]
        v.largest_a_step = max(v.largest_a_step, d[3])
        if ln.g == "G1" and d[3] >= _TURN and min(abs(prev[4]), abs(j[4])) > _VERTICAL:
            v.tilted_a_turns.append(k)
        if ln.g == "G1":
            tip0, _ = machine.forward(prev)
            tip1, _ = machine.forward(j)
            dist = float(np.linalg.norm(tip1 - tip0))
            if ln.mode == "G93":
                seconds = 60.0 / ln.feed if ln.feed else math.inf
            else:
                seconds = dist / (ln.feed / 60.0) if ln.feed else math.inf
            # slack: the words' rounding (1e-6 deg of A or C is 6e-8 s at the C speed)
            if joint_time > seconds * (1 + 1e-6) + 1e-7:
                v.too_fast.append(k)
            v.cycle_time += max(seconds, joint_time)
            if not tcp and (d[3] > 0 or d[4] > 0):
                tip_dev, axis_dev = deviation(machine, prev, j, checks=16)
                v.largest_tip_deviation = max(v.largest_tip_deviation, tip_dev)
                v.largest_axis_deviation = max(v.largest_axis_deviation, axis_dev)
        else:
            v.cycle_time += joint_time
        if depth is not None:  # cutting lines, and the approach, retract and transit rapids too
            v.deepest_cut = max(v.deepest_cut, float(depth(*_instances(machine, prev, j, tcp, samples)).max()))
        prev = j
    return v


def _not_numbers(text: str) -> int:
    """Words whose value is NaN or infinite (a post printing 'nan' or 'inf')."""
    return len(re.findall(r"\b[XYZACF]\s*[-+]?(nan|inf)", text, re.I))


def _instances(machine: TarusMachine, j0: np.ndarray, j1: np.ndarray, tcp: bool, samples: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """(tips, axes) of the tool at `samples` points inside a line and at its end, as the control moves it:
    all joints linear, or in TCP mode the tip linear and A, C linear (a TCP control keeps the tip on its line
    and interpolates the rotary axes)."""
    s = np.arange(1, samples + 2) / (samples + 1)
    js = j0[None, :] * (1 - s[:, None]) + j1[None, :] * s[:, None]
    tips, axes = machine.forward_path(js)
    if tcp:
        t0, _ = machine.forward(j0)
        t1, _ = machine.forward(j1)
        tips = t0[None, :] * (1 - s[:, None]) + t1[None, :] * s[:, None]
    return tips, axes
