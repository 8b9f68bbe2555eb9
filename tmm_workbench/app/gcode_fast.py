"""Fast G-code writers in the dialects of FreeCAD's linuxcnc and grbl script posts.

FreeCAD's posts build every word through a `Units.Quantity` and append to one growing string, 30-40 us a line
on a loaded machine (6-12 s for a 192k-line surface job, docs/posts.md). Here a TMM op's moves are read from its
record of its Path (app.path_build: rows of arrays), each run of rows of one kind written at once
(core.post.fixed_text); other objects' Paths are read once (`Commands`, one `Parameters` dict per command) and
every line is one `%` format by a function generated once per command name and parameter set. The words written
are FreeCAD's: the same order, the same dropped parameters (linuxcnc has no K), F in mm/min without F on rapids,
T/S as integers, the same rounding (`%.<n>f` of the same double FreeCAD formats), the same tool-change and
coolant lines. Only the header's post name and time differ.
Reference: FreeCAD 0.20 `linuxcnc_post.py`, `grbl_post.py` (1.0/1.1 `*_legacy_post.py` write the same motion
lines).
"""
from __future__ import annotations

import argparse
import datetime
import re
import shlex
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Iterable, Optional

import numpy as np

from tmm_workbench.app.path_build import MoveRows, record_of
from tmm_workbench.core.post import fixed_text

# Quantity(v, Length).getValueAs('in') is v / 25.4; Quantity(v, Velocity).getValueAs('mm/min') is v / (1/60):
# dividing by the same doubles keeps every rounding FreeCAD's
MM_PER_MIN = 1.0 / 60.0
IN = 25.4
IN_PER_MIN = 25.4 / 60.0
RAPIDS = ("G0", "G00")
_MC_RUN = re.compile(r"^\(MC_RUN_COMMAND: ([^)]+)\)$")


@dataclass
class Options:
    """The post arguments that change what is written (FreeCAD's names; --no-show-editor is accepted and
    ignored: these posts never open the editor, it is slow on large files)."""
    precision: int = 3
    header: bool = True
    comments: bool = True
    line_numbers: bool = False
    inches: bool = False
    modal: bool = False          # linuxcnc: a command word equal to the previous one is left out
    axis_modal: bool = False     # linuxcnc: a parameter equal to its previous value is left out
    tlo: bool = True             # linuxcnc: G43 H<tool> after M6
    tool_change: bool = False    # grbl: M6 written (else commented out)
    spindle_wait: int = 0        # grbl: G4 P<s> after M3/M4
    return_to: Optional[tuple[int, int]] = None  # grbl: G0 X Y at the end
    bcnc: bool = False           # grbl: bCNC block headers
    preamble: Optional[str] = None
    postamble: Optional[str] = None


def parser(dialect: str) -> argparse.ArgumentParser:
    """FreeCAD's argument names for `dialect` ('linuxcnc' | 'grbl')."""
    p = argparse.ArgumentParser(prog=f"tmm_{dialect}", add_help=False)
    flags = ["--no-header", "--no-comments", "--line-numbers", "--no-show-editor", "--inches"]
    if dialect == "linuxcnc":
        flags += ["--modal", "--axis-modal", "--no-tlo"]
    else:
        flags += ["--header", "--comments", "--no-line-numbers", "--show-editor", "--tool-change", "--bcnc",
                  "--no-bcnc", "--translate_drill", "--no-translate_drill"]
        p.add_argument("--wait-for-spindle", type=int, default=0, help="G4 P<s> after M3/M4")
        p.add_argument("--return-to", default="", help="G0 X,Y at the end, e.g. --return-to=0,0")
    for flag in flags:
        p.add_argument(flag, action="store_true")
    p.add_argument("--precision", default="3", help="digits after the point, default 3 (4 with --inches)")
    p.add_argument("--preamble", help="lines before the first command")
    p.add_argument("--postamble", help="lines after the last command")
    return p


def parse_args(dialect: str, argstring: str) -> Options:
    """Options from a post argument string; ValueError on a bad one (FreeCAD's posts return None then)."""
    try:
        a = parser(dialect).parse_args(shlex.split(argstring or ""))
    except SystemExit as exc:
        raise ValueError(f"tmm_{dialect}: bad post arguments {argstring!r}") from exc
    opts = Options(precision=4 if a.inches else int(a.precision), header=not a.no_header,
                   comments=not a.no_comments, line_numbers=a.line_numbers, inches=a.inches,
                   preamble=a.preamble, postamble=a.postamble)
    if dialect == "linuxcnc":
        opts.modal, opts.axis_modal, opts.tlo = a.modal, a.axis_modal, not a.no_tlo
    else:
        opts.header = a.header or not a.no_header
        opts.comments = a.comments or not a.no_comments
        opts.line_numbers = a.line_numbers  # FreeCAD applies --no-line-numbers first
        opts.tool_change, opts.spindle_wait, opts.bcnc = a.tool_change, max(a.wait_for_spindle, 0), a.bcnc
        if a.return_to:
            xy = [int(v) for v in a.return_to.split(",")]
            opts.return_to = (xy[0], xy[1]) if len(xy) == 2 else None
    return opts


LineFn = Callable[[dict[str, float]], str]


def has_path(obj: Any) -> bool:
    """hasattr(obj, 'Path') without reading the Path (a copy of all its commands, 30 ms on a large op)."""
    props = getattr(obj, "PropertiesList", None)
    return "Path" in props if props is not None else hasattr(obj, "Path")


@dataclass
class Writer:
    """One export in one dialect; subclasses say what differs. Lines collect in `out` (joined once)."""
    opts: Options
    post_name: str
    out: list[str] = field(default_factory=list)
    line_nr: int = 0
    plans: dict[tuple, LineFn] = field(default_factory=dict)

    ORDER: ClassVar[tuple[str, ...]] = ()
    INTS: ClassVar[tuple[str, ...]] = ("T", "S")
    RAW: ClassVar[tuple[str, ...]] = ()     # written with str(value)
    ANGLES: ClassVar[tuple[str, ...]] = ()  # never scaled to inches
    SEP_END: ClassVar[str] = " "            # linuxcnc ends every word with a space, grbl strips the line
    FIRST_LINE: ClassVar[int] = 110         # linuxcnc counts before its first number, grbl after
    NUMBER_PAD: ClassVar[str] = " "         # linuxcnc's number is a word of its own, followed by a space

    def __post_init__(self) -> None:
        self.line_nr = self.FIRST_LINE

    # --- units and line numbers ------------------------------------------------------------------------------
    @property
    def length_unit(self) -> float:
        return IN if self.opts.inches else 1.0

    @property
    def speed_unit(self) -> float:
        return IN_PER_MIN if self.opts.inches else MM_PER_MIN

    def number(self) -> str:
        """The next line number word ('' without --line-numbers)."""
        if not self.opts.line_numbers:
            return ""
        self.line_nr += 10
        return f"N{self.line_nr - 10} "

    def emit(self, text: str) -> None:
        """`text` (one or more whole lines, newline included) behind the next line number."""
        self.out.append(self.number() + text)

    # --- the fast path ---------------------------------------------------------------------------------------
    def word_format(self, key: str) -> tuple[str, float]:
        """The `%` format of parameter `key` and its divisor."""
        if key in self.INTS:
            return key + "%d", 1.0  # %d of a float truncates as int() does
        if key in self.RAW:
            return key + "%s", 1.0
        prec = f"%.{self.opts.precision}f"
        if key == "F":
            return "F" + prec, self.speed_unit
        return key + prec, (1.0 if key in self.ANGLES else self.length_unit)

    def line_format(self, name: str, keys: Iterable[str], with_name: bool) -> tuple[str, list[str], list[float]]:
        """A line of command `name` with parameters `keys` as FreeCAD writes it: its `%` format, the words in
        the format's order and their divisors."""
        present = set(keys)
        order = [k for k in self.ORDER if k in present and not (k == "F" and name in RAPIDS)]
        words = [self.word_format(k) for k in order]
        fmt = self.join(([name.replace("%", "%%")] if with_name else []) + [w for w, _ in words])
        return fmt, order, [d for _, d in words]

    def compile_line(self, name: str, keys: Iterable[str], with_name: bool) -> LineFn:
        """The function writing a command `name` with parameters `keys`: one generated expression, one `%`
        format of the values in FreeCAD's order (divided by their unit where it is not 1), so a line costs no
        Python loop over its words. F not positive: FreeCAD writes no F, a second format."""
        fmt, order, divisors = self.line_format(name, keys, with_name)
        if not fmt:
            return lambda p: ""
        # keys come from ORDER (single letters), the divisors are passed as names: nothing user-made is evaluated
        namespace: dict[str, Any] = {"fmt": fmt}
        values = []
        for i, (k, divisor) in enumerate(zip(order, divisors)):
            namespace[f"d{i}"] = divisor
            values.append(f"p[{k!r}]" if divisor == 1.0 else f"p[{k!r}] / d{i}")
        src = f"fmt % ({', '.join(values)}{',' if values else ''})"
        if "F" in order:
            namespace["no_feed"] = self.compile_line(name, [k for k in order if k != "F"], with_name)
            src = f"({src}) if p['F'] > 0.0 else no_feed(p)"
        return eval(f"lambda p: {src}", namespace)  # noqa: S307 - see above

    def join(self, texts: list[str]) -> str:
        """A line's format; '' when it has no word (FreeCAD then writes no line)."""
        if not texts:
            return ""
        if self.SEP_END:
            return "".join(t + self.SEP_END for t in texts) + "\n"
        return " ".join(texts).strip() + "\n"

    def line_function(self, name: str, keys: tuple[str, ...], with_name: bool = True) -> LineFn:
        key = (name, keys, with_name)
        fn = self.plans.get(key)
        if fn is None:
            fn = self.plans[key] = self.compile_line(name, keys, with_name)
        return fn

    def plain_line(self, name: str, params: dict[str, float], with_name: bool = True) -> str:
        """The line FreeCAD writes for a command with no special meaning ('' for none)."""
        return self.line_function(name, tuple(params), with_name)(params)

    def special_function(self, name: str) -> Optional[LineFn]:
        """The dialect's writer of a command it treats specially (it may emit lines itself), else None."""
        return None

    def fast_lines(self, path_commands: Iterable[Any]) -> None:
        """Every command's line: one function per (name, parameter set), found by one dict look-up."""
        out, numbered, pad = self.out, self.opts.line_numbers, self.NUMBER_PAD
        functions: dict[tuple, LineFn] = {}
        for c in path_commands:
            name = c.Name
            p = c.Parameters
            key = (name, *p)
            fn = functions.get(key)
            if fn is None:
                fn = functions[key] = self.special_function(name) or self.line_function(name, tuple(p))
            line = fn(p)
            if line:
                out.append(line if not numbered else self.number() + pad + line)

    # --- an op's record of its Path (app.path_build): whole runs of rows in one format --------------------------
    def op_lines(self, obj: Any) -> None:
        """The lines of `obj`'s Path: from the op's record of it when it has one (no command read back from
        FreeCAD), else from the Path."""
        rec = record_of(obj)
        if rec is None:
            self.fast_lines(obj.Path.Commands)
            return
        self.fast_lines(rec.before)
        self.row_lines(rec.rows)
        self.fast_lines(rec.after)

    def row_lines(self, rows: MoveRows) -> None:
        """Each run of rows of one kind written at once (core.post.fixed_text: the text of the line's `%` format,
        built with numpy; the values divided by their unit as arrays: the same doubles); line numbers, a special
        command or a feed not positive: line by line."""
        if self.opts.line_numbers:
            self.fast_lines(rows.commands())
            return
        codes = rows.codes
        cuts = (np.flatnonzero(np.diff(codes)) + 1).tolist()
        for a, b in zip([0] + cuts, cuts + [len(codes)]):
            name, words = rows.kinds[int(codes[a])]
            values = rows.values[a:b, :len(words)]
            simple = self.special_function(name) is None and not set(words) & set(self.INTS + self.RAW)
            if not simple or ("F" in words and not (values[:, words.index("F")] > 0).all()):
                self.fast_lines(rows.commands(a, b))
                continue
            fmt, order, divisors = self.line_format(name, words, True)
            if fmt:
                v = values[:, [words.index(k) for k in order]]
                if any(d != 1.0 for d in divisors):
                    v = v / np.array(divisors)
                text = fixed_text.lines(fmt, v)   # numpy's bytes; else Python's % of the run
                self.out.append(text if text is not None else (fmt * (b - a)) % tuple(v.ravel().tolist()))

    def commands_of(self, obj: Any) -> Iterable[Any]:
        """`obj`'s commands (Name, Parameters): from the op's record when it has one, else from the Path."""
        rec = record_of(obj)
        return rec.commands() if rec is not None else obj.Path.Commands

    # --- programs --------------------------------------------------------------------------------------------
    def write(self, objects: list[Any]) -> str:
        raise NotImplementedError

    def text(self) -> str:
        return "".join(self.out)

    def header(self) -> None:
        if self.opts.header:
            self.emit("(Exported by FreeCAD)\n")
            self.emit(f"(Post Processor: {self.post_name})\n")
            self.emit(f"(Output Time:{datetime.datetime.now()})\n")

    def coolant(self, obj: Any, on: bool) -> str:
        """The op's coolant mode; its M7/M8 (on) or M9 (off) lines written as FreeCAD does."""
        mode = "None"
        if hasattr(obj, "CoolantMode"):
            mode = obj.CoolantMode
        elif hasattr(obj, "Base") and hasattr(obj.Base, "CoolantMode"):
            mode = obj.Base.CoolantMode
        if mode == "None":
            return mode
        if self.opts.comments:
            self.emit(f"(Coolant {'On' if on else 'Off'}:{mode})\n")
        if not on:
            self.emit("M9\n")
        elif mode in ("Flood", "Mist"):
            self.emit("M8\n" if mode == "Flood" else "M7\n")
        return mode


def export_with(writer_class: Callable[[Options, str], Writer], dialect: str, objects: list[Any], filename: str,
                argstring: str, post_name: str) -> str:
    """The post interface: G-code for `objects`, written to `filename` unless it is '-' or empty."""
    writer = writer_class(parse_args(dialect, argstring), post_name)
    text = writer.write(list(objects))
    if filename and filename != "-":
        with open(filename, "w") as f:
            f.write(text)
    return text
