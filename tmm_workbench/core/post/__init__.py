"""Post-processor writers, free of FreeCAD: a program is a list of `ToolInfo` (tool changes) and `Operation`
(one Path's commands as (name, parameters) pairs in FreeCAD units: mm, mm/s), in the order of the Job.
`tarus_writer.write_tarus` makes Tarus G-code, `apt_writer.write_apt` an APT CL file. The FreeCAD post
modules (tmm_workbench/app/posts/*_post.py) only turn FreeCAD objects into this program."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Optional, Union

MM_PER_INCH = 25.4


@dataclass
class ToolInfo:
    """A tool change: tool number, spindle (rpm; direction 'CW', 'CCW' or 'OFF') and what is known of the
    cutter (mm; None when unknown)."""
    number: int
    label: str = ""
    shape: str = ""
    diameter: Optional[float] = None
    corner_radius: Optional[float] = None
    cutting_height: Optional[float] = None
    spindle_rpm: float = 0.0
    spindle_dir: str = "CW"


@dataclass
class Operation:
    """One op's Path: label, commands [(name, {word: value})], coolant ('None', 'Flood', 'Mist')."""
    label: str
    commands: list[tuple[str, Mapping[str, Any]]] = field(default_factory=list)
    coolant: str = "None"


Program = list[Union[ToolInfo, Operation]]


def number(value: float, decimals: int) -> str:
    """Fixed-point text without a negative zero."""
    text = f"{value:.{decimals}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return text


def comment_text(text: str) -> str:
    """Text that is safe inside a G-code '( ... )' comment."""
    return str(text).replace("(", "[").replace(")", "]").replace("\n", " ").strip()


def is_comment(name: str) -> bool:
    return name.startswith("(") or name.startswith(";")


def strip_comment(name: str) -> str:
    name = name.strip()
    if name.startswith("(") and name.endswith(")"):
        return name[1:-1].strip()
    return name.lstrip(";").strip()


def arc_points(start: tuple[float, float, float], end: tuple[float, float, float], params: Mapping[str, Any],
               clockwise: bool, tolerance: float = 0.001) -> list[tuple[float, float, float]]:
    """Points (after `start`, ending exactly at `end`) of a G17 arc with centre offsets I, J (helical in Z
    when Z changes), with chord deviation at most `tolerance` mm. A full circle when end == start."""
    cx, cy = start[0] + float(params.get("I", 0.0)), start[1] + float(params.get("J", 0.0))
    r = math.hypot(start[0] - cx, start[1] - cy)
    a0 = math.atan2(start[1] - cy, start[0] - cx)
    a1 = math.atan2(end[1] - cy, end[0] - cx)
    sweep = a1 - a0
    if clockwise:
        sweep = sweep - 2 * math.pi if sweep >= -1e-12 else sweep
    else:
        sweep = sweep + 2 * math.pi if sweep <= 1e-12 else sweep
    if r < 1e-12:
        return [end]
    step = 2 * math.acos(max(-1.0, 1 - tolerance / r)) if tolerance < r else math.pi / 2
    n = max(1, int(math.ceil(abs(sweep) / max(step, 1e-6))))
    pts = []
    for k in range(1, n):
        a = a0 + sweep * k / n
        pts.append((cx + r * math.cos(a), cy + r * math.sin(a), start[2] + (end[2] - start[2]) * k / n))
    pts.append(tuple(end))
    return pts


class ArgumentParser(__import__("argparse").ArgumentParser):
    """argparse for post arguments: errors raise TmmError instead of exiting FreeCAD."""

    def error(self, message: str) -> None:  # type: ignore[override]
        from tmm_workbench.core.errors import TmmError
        raise TmmError(f"{self.prog} post arguments: {message}")

    def parse_post_args(self, argstring: str | None):
        import shlex
        return self.parse_args(shlex.split(argstring or ""))


def post_argument_parser(prog: str, inches_help: str, comments_help: str) -> ArgumentParser:
    """A post's parser with the arguments every TMM post takes (units, FreeCAD's editor flags, comments)."""
    p = ArgumentParser(prog=prog, add_help=False)
    p.add_argument("--inches", action="store_true", help=inches_help)
    p.add_argument("--show-editor", action="store_true", help="accepted; TMM posts never open an editor")
    p.add_argument("--no-show-editor", action="store_true", help="do not show the output in an editor")
    p.add_argument("--no-comments", action="store_true", help=comments_help)
    return p


def write_program(writer: Any, program: Program) -> None:
    """The walk every writer makes: header, the tool changes and operations in order, footer."""
    from tmm_workbench.core.errors import TmmError
    writer.header()
    for item in program:
        if isinstance(item, ToolInfo):
            writer.tool_change(item)
        elif isinstance(item, Operation):
            writer.operation(item)
        else:
            raise TmmError(f"unexpected program item {type(item).__name__}")
    writer.footer()
