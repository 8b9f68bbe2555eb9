"""APT CL file (cutter location data) from TMM's 5-axis Path representation, in the style of seed 000
Appendix B: GOTO/x,y,z,i,j,k (tool tip and unit tool axis, tip -> spindle), CUTTER, LOADTL, FEDRAT,
SPINDL, RAPID, COOLNT records. Machine-independent: no kinematics, no limits. Arcs (G2/G3, XY plane) are
written as GOTO points within `arc_tolerance`.
"""
from __future__ import annotations

import datetime
import math
from dataclasses import dataclass
from typing import Optional

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.path5 import MOTION_NAMES, Pose, decode
from tmm_workbench.core.post import (MM_PER_INCH, ArgumentParser, Operation, Program, ToolInfo, arc_points,
                                     is_comment, number, post_argument_parser, strip_comment, write_program)

_CANONICAL = {"G00": "G0", "G01": "G1", "G02": "G2", "G03": "G3"}


@dataclass
class AptOptions:
    """inches: UNITS/INCHES, lengths in inches, FEDRAT in IPM. precision: decimals of coordinates;
    axis_precision: decimals of i, j, k. partno: the PARTNO text. arc_tolerance: mm. date: header date text
    (None: now). header: the $$ block with the date (off: the same path gives the same file)."""
    inches: bool = False
    precision: int = 6
    axis_precision: int = 6
    partno: str = "PART TO BE MACHINED"
    comments: bool = True
    arc_tolerance: float = 0.001
    date: Optional[str] = None
    header: bool = True


class _AptWriter:
    def __init__(self, options: AptOptions) -> None:
        self.o = options
        self.lines: list[str] = []
        self.tip = (math.nan, math.nan, math.nan)
        self.feed: Optional[float] = None  # last FEDRAT, mm/s
        self.coolant = "None"
        self.spindle_on = False

    def length(self, v: float) -> str:
        return number(v / MM_PER_INCH if self.o.inches else v, self.o.precision)

    def remark(self, text: str) -> None:
        if self.o.comments:
            self.lines.append(f"$$ {text}")

    def header(self) -> None:
        if self.o.header:
            date = self.o.date or datetime.datetime.now().strftime("%A, %B %d, %Y %I:%M:%S %p")
            self.lines += ["$$ -----", f"$$      Generated on {date}", "$$      TMM APT CL post (FreeCAD)",
                           "$$      GOTO/x,y,z,i,j,k: tool tip and unit tool axis (tip -> spindle)", "$$ -----"]
        self.lines.append(f"PARTNO {self.o.partno}")
        self.lines.append("UNITS/INCHES" if self.o.inches else "UNITS/MM")
        self.lines.append("MULTAX/ON")

    def tool_change(self, t: ToolInfo) -> None:
        self.remark("TOOLCHANGEBEGINNING")
        if t.diameter:
            d = t.diameter
            r = t.corner_radius if t.corner_radius is not None else (d / 2 if t.shape == "ballend" else 0.0)
            h = t.cutting_height or 0.0
            vals = [d, r, d / 2 - r, r, 0.0, 0.0, h]
            self.lines.append("CUTTER/ " + ", ".join(self.length(v) if k not in (4, 5) else number(v, 6)
                                                     for k, v in enumerate(vals)))
            self.lines.append(f"TOOLNO/{int(t.number)}, {self.length(d)}")
        if t.label:
            self.lines.append(f"TPRINT/T{int(t.number)} {t.label}")
        self.lines.append(f"LOADTL/{int(t.number)}")
        self.remark("TOOLCHANGEEND")
        if t.spindle_dir != "OFF" and t.spindle_rpm > 0:
            self.lines.append(f"SPINDL/ {number(t.spindle_rpm, 4)},RPM,{'CCLW' if t.spindle_dir == 'CCW' else 'CLW'}")
            self.spindle_on = True
        self.feed = None

    def operation(self, op: Operation) -> None:
        self.remark(f"OPERATION NAME : {op.label}")
        self.remark(f"Start generation of : {op.label}")
        if op.coolant in ("Flood", "Mist") and op.coolant != self.coolant:
            self.lines.append("COOLNT/ON" if op.coolant == "Flood" else "COOLNT/MIST")
        elif op.coolant not in ("Flood", "Mist") and self.coolant != "None":
            self.lines.append("COOLNT/OFF")
        self.coolant = op.coolant if op.coolant in ("Flood", "Mist") else "None"
        pose = Pose()
        pose.tip = self.tip
        for i, (name, params) in enumerate(op.commands):
            up = str(name).upper()
            if is_comment(up):
                self.remark(strip_comment(str(name)))
                continue
            if up not in MOTION_NAMES:
                continue  # modes, stops: nothing in CL data
            try:
                start = pose.tip
                pose = decode(up, params, pose)
                kind = _CANONICAL.get(up, up)
                if any(math.isnan(c) for c in pose.tip):
                    if kind == "G0" and pose.axis == (0.0, 0.0, 1.0):
                        continue  # a partial first rapid ('G0 Z..'): no full CL point yet
                    raise TmmError(f"the tool position {pose.tip} is not fully known")
                if kind == "G0":
                    self.lines.append("RAPID")
                    self.goto(pose.tip, pose.axis)
                    continue
                if pose.feed is None or not pose.feed > 0:
                    raise TmmError(f"{kind} without a feed rate (F {pose.feed})")
                if pose.feed != self.feed:
                    per_min = pose.feed * 60.0 / (MM_PER_INCH if self.o.inches else 1.0)
                    self.lines.append(f"FEDRAT/ {number(per_min, 4)},{'IPM' if self.o.inches else 'MMPM'}")
                    self.feed = pose.feed
                if kind in ("G2", "G3"):
                    if any(math.isnan(c) for c in start):
                        raise TmmError("an arc needs a known start point")
                    for p in arc_points(start, pose.tip, params, kind == "G2", self.o.arc_tolerance):
                        self.goto(p, pose.axis)
                else:
                    self.goto(pose.tip, pose.axis)
            except TmmError as exc:
                raise TmmError(f"operation '{op.label}', command {i} ({name}): {exc}") from None
        self.tip = pose.tip
        self.remark(f"End of generation of : {op.label}")

    def goto(self, tip, axis) -> None:
        p = ",".join(self.length(v) for v in tip)
        a = ",".join(number(v, self.o.axis_precision) for v in axis)
        self.lines.append(f"GOTO/ {p},{a}")
        self.tip = tuple(tip)

    def footer(self) -> None:
        if self.coolant != "None":
            self.lines.append("COOLNT/OFF")
        self.lines.append("SPINDL/OFF")
        self.lines.append("END")
        self.lines.append("FINI")


def write_apt(program: Program, options: Optional[AptOptions] = None) -> str:
    """The APT CL text for `program`; TmmError (naming operation and command) for what it cannot write."""
    w = _AptWriter(options or AptOptions())
    write_program(w, program)
    return "\n".join(w.lines) + "\n"


def argument_parser() -> ArgumentParser:
    p = post_argument_parser("apt_cl", "UNITS/INCHES, lengths in inches, FEDRAT in IPM", "no $$ remarks")
    p.add_argument("--precision", type=int, default=6, help="decimals of coordinates (default 6)")
    p.add_argument("--axis-precision", type=int, default=6, help="decimals of i, j, k (default 6)")
    p.add_argument("--partno", default="PART TO BE MACHINED", help="PARTNO text")
    p.add_argument("--arc-tolerance", type=float, default=0.001, help="chord tolerance of arcs, mm")
    p.add_argument("--no-header", action="store_true", help="no $$ header (its export date): the same path gives "
                   "the same file")
    return p


def parse_args(argstring: Optional[str]) -> AptOptions:
    a = argument_parser().parse_post_args(argstring)
    if not (0 <= a.precision <= 12 and 0 <= a.axis_precision <= 15) or not a.arc_tolerance > 0:
        raise TmmError("apt_cl post arguments: precisions 0..12 (axis 0..15), arc tolerance > 0")
    return AptOptions(inches=a.inches, precision=a.precision, axis_precision=a.axis_precision, partno=a.partno,
                      comments=not a.no_comments, arc_tolerance=a.arc_tolerance, header=not a.no_header)


TOOLTIP_ARGS = argument_parser().format_help()
