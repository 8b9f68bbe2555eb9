"""The linuxcnc and grbl dialects of the fast posts (app.gcode_fast): what FreeCAD's `linuxcnc_post.py` and
`grbl_post.py` write around the motion lines (preamble, per-op comments, coolant, tool change, postamble)
and the few commands they treat specially. The posts in app/posts/ call `export()`.
"""
from __future__ import annotations

from typing import Any, Iterable, Optional

from tmm_workbench.app.gcode_fast import _MC_RUN, LineFn, Options, Writer, export_with, has_path


def _check_paths(objects: list[Any]) -> None:
    """FreeCAD's posts write nothing when an object has no Path."""
    for obj in objects:
        if not has_path(obj):
            raise ValueError(f"the object {obj.Name} is not a path: select only paths and compounds")


class LinuxCNC(Writer):
    ORDER = ("X", "Y", "Z", "A", "B", "C", "I", "J", "F", "S", "T", "Q", "R", "L", "H", "D", "P")
    INTS = ("T", "H", "D", "S")
    PREAMBLE = "G17 G54 G40 G49 G80 G90\n"
    POSTAMBLE = "M05\nG17 G54 G90 G80 G40\nM2\n"

    def write(self, objects: list[Any]) -> str:
        _check_paths(objects)
        o = self.opts
        self.header()
        if o.comments:
            self.emit("(begin preamble)\n")
        for line in (self.PREAMBLE if o.preamble is None else o.preamble).splitlines(False):
            self.emit(line + "\n")
        self.emit("G20\n" if o.inches else "G21\n")
        for obj in objects:
            if not self.active(obj):
                continue
            if o.comments:
                self.emit(f"(begin operation: {obj.Label})\n")
                self.emit(f"(machine units: {'in/min' if o.inches else 'mm/min'})\n")
            mode = self.coolant(obj, True)
            self.path_lines(obj)
            if o.comments:
                self.emit(f"(finish operation: {obj.Label})\n")
            if mode != "None":
                self.coolant(obj, False)
        if o.comments:
            self.out.append("(begin postamble)\n")  # FreeCAD numbers every line but this one
        for line in (self.POSTAMBLE if o.postamble is None else o.postamble).splitlines(True):
            self.emit(line)
        return self.text()

    @staticmethod
    def active(obj: Any) -> bool:
        if hasattr(obj, "Active") and not obj.Active:
            return False
        return not (hasattr(obj, "Base") and hasattr(obj.Base, "Active") and not obj.Base.Active)

    def path_lines(self, obj: Any) -> None:
        """FreeCAD's parse(): a compound's members in turn, a Path's commands line by line."""
        if hasattr(obj, "Group"):
            for member in obj.Group:
                self.path_lines(member)
            return
        if not has_path(obj):
            return
        if self.opts.modal or self.opts.axis_modal:
            self.modal_lines(self.commands_of(obj))
        else:
            self.op_lines(obj)

    def special_function(self, name: str) -> Optional[LineFn]:
        if name.startswith("(") and not self.opts.comments:
            return lambda p: ""
        if name == "M6":
            return lambda p: self.tool_change(name, p, p, True)
        if name == "message":  # its words without the name (nothing without comments)
            return lambda p: self.plain_line(name, p, False) if self.opts.comments else ""
        return None

    def modal_lines(self, path_commands: Iterable[Any]) -> None:
        """The lines with --modal (a command word equal to the previous left out) or --axis-modal (a value equal
        to the previous left out; T H D S always written, as FreeCAD does); both restart with every Path."""
        o = self.opts
        last = None
        seen = {"X": -1.0, "Y": -1.0, "Z": -1.0, "F": 0.0}  # FreeCAD's first location
        for c in path_commands:
            name, params = c.Name, c.Parameters
            with_name = not (o.modal and name == last)
            if name.startswith("(") and not o.comments:
                continue
            words = params
            if o.axis_modal:
                words = {k: v for k, v in params.items() if k in self.INTS or seen.get(k) != v}
                seen.update(params)
            last = name
            if name == "M6":
                line = self.tool_change(name, params, words, with_name)
            else:
                line = self.plain_line(name, words, with_name and name != "message")
            if line and not (name == "message" and not o.comments):
                self.out.append(line if not o.line_numbers else self.number() + " " + line)

    def tool_change(self, name: str, params: dict[str, float], words: dict[str, float], with_name: bool) -> str:
        """M6: spindle stop before, G43 H<tool> after (on the M6 line's number, as FreeCAD)."""
        self.emit("M5\n")
        line = self.plain_line(name, words, with_name)
        if self.opts.tlo and "T" in params:
            line = line[:-1] + f"\nG43 H{int(params['T'])} \n"
        return line


class Grbl(Writer):
    ORDER = ("X", "Y", "Z", "A", "B", "C", "U", "V", "W", "I", "J", "K", "F", "S", "T", "Q", "R", "L", "P")
    INTS = ("T", "H", "S")
    RAW = ("D", "P", "L")
    ANGLES = ("A", "B", "C")
    SEP_END = ""
    FIRST_LINE = 100
    NUMBER_PAD = ""
    PREAMBLE = "G17 G90\n"
    POSTAMBLE = "M5\nG17 G90\nM2\n"

    def write(self, objects: list[Any]) -> str:
        _check_paths(objects)
        o = self.opts
        self.header()
        if o.comments:
            self.emit("(Begin preamble)\n")
        preamble = self.PREAMBLE if o.preamble is None else o.preamble
        for line in preamble.splitlines(True):
            self.emit(line)
        if "G90" not in preamble and "G91" not in preamble:
            self.emit("G90\n")
        if "G21" in preamble or "G20" in preamble:
            o.inches = "G21" not in preamble  # the preamble's units are the program's (precision unchanged)
        else:
            self.emit("G20\n" if o.inches else "G21\n")
        for obj in objects:
            if self.active(obj) is False:
                continue
            self.operation(obj)
        if o.return_to:
            self.emit("G0 X%s Y%s\n" % o.return_to)
        self.block("post_amble")
        if o.comments:
            self.emit("(Begin postamble)\n")
        for line in (self.POSTAMBLE if o.postamble is None else o.postamble).splitlines(True):
            self.emit(line)
        return self.text()

    @staticmethod
    def active(obj: Any) -> Any:
        """PathUtil.opProperty(obj, 'Active'): the op's, else its base's, else None."""
        if hasattr(obj, "Active"):
            return obj.Active
        if hasattr(obj, "Base") and hasattr(obj.Base, "Active"):
            return obj.Base.Active
        return None

    def block(self, label: str) -> None:
        if self.opts.bcnc:
            self.emit(f"(Block-name: {label})\n")
            self.emit("(Block-expand: 0)\n")
            self.emit("(Block-enable: 1)\n")

    def operation(self, obj: Any) -> None:
        self.block(obj.Label)
        if self.opts.comments:
            self.emit(f"(Begin operation: {obj.Label})\n")
        mode = self.coolant(obj, True)
        self.path_lines(obj)
        if self.opts.comments:
            self.emit(f"(Finish operation: {obj.Label})\n")
        if mode != "None":
            self.coolant(obj, False)

    def path_lines(self, obj: Any) -> None:
        """FreeCAD's parse(): a compound's members in turn, a Path's commands line by line (grbl writes the
        Path's own comments even with --no-comments, as FreeCAD's does)."""
        if hasattr(obj, "Group"):
            if self.opts.comments:
                self.emit(f"(Compound: {obj.Label})\n")
            for member in obj.Group:
                self.path_lines(member)
            return
        if not has_path(obj):
            return
        if self.opts.comments:
            self.emit(f"(Path: {obj.Label})\n")
        self.op_lines(obj)

    def special_function(self, name: str) -> Optional[LineFn]:
        if name in ("M6", "M06", "M3", "M03", "M4", "M04", "message") or name.startswith("(MC_RUN_COMMAND"):
            return lambda p: self.special(name, p)
        return None

    def special(self, name: str, params: dict[str, float]) -> str:
        """Tool change (commented out unless --tool-change), the spindle wait, a message's words, a
        MC_RUN_COMMAND comment's command after it: emitted here, '' returned."""
        o = self.opts
        line = self.plain_line(name, params, name != "message")
        if name in ("M6", "M06"):
            if o.comments:
                self.emit("(Begin toolchange)\n")
            if not o.tool_change:
                line = "( " + line[:-1] + " )\n"
        if not line or name == "message" and not o.comments:
            return ""
        self.emit(line)
        if o.spindle_wait > 0 and name in ("M3", "M03", "M4", "M04"):
            self.emit(f"G4 P{o.spindle_wait}\n")
        m = _MC_RUN.match(name)
        if m:
            self.emit(m.group(1) + "\n")
        return ""


def export(dialect: str, objects: Any, filename: str, argstring: str, post_name: str) -> str:
    """G-code for `objects` in `dialect` ('linuxcnc' | 'grbl'), written to `filename` unless it is '-'."""
    writer_class = LinuxCNC if dialect == "linuxcnc" else Grbl
    return export_with(writer_class, dialect, objects, filename, argstring, post_name)


__all__ = ["LinuxCNC", "Grbl", "Options", "export"]
