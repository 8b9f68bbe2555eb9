"""What the TMM Path operations share: properties declared as one table that names the strategy's params
fields (so properties map to params generically and defaults live in the params dataclass), values given at
creation, the checks of the op's inputs before FreeCAD's own, and the one way a computation fails (empty
Path, message in the report view, op marked invalid with that message as its status: no partial path and
no stale path ever)."""
from __future__ import annotations

import math
import traceback
from contextlib import contextmanager
from dataclasses import MISSING, fields
from typing import Any, Callable, Iterator, NamedTuple, Optional

import FreeCAD
import numpy as np
import Path

from tmm_workbench.app import hooks, path_build, work_estimate
from tmm_workbench.app.compat import PathOp
from tmm_workbench.app.tools import TOOLBIT_SHAPES, cutter_from_tool, label_of, shape_name
from tmm_workbench.core import kernel
from tmm_workbench.core.errors import Cancelled, TmmError, WorkLimitError
from tmm_workbench.core.tools.cutter import Cutter


CANCELLED = "computation cancelled: no tool path (recompute the operation to compute it)"
MAX_WORD = 1e9  # mm, mm/min, deg: any G-code word beyond it is a computation gone wrong, not a move
class Prop(NamedTuple):
    """One row of an op's property table. `field`: the params dataclass field it sets ("" for none)."""
    type: str
    name: str
    group: str
    tooltip: str
    field: str = ""


def _plain(value: Any) -> Any:
    """A property value as the core takes it: Quantities in mm / deg, booleans as bool."""
    if hasattr(value, "Value"):
        return float(value.Value)
    return value


class TmmOp(PathOp.ObjectOp):
    """Base of the TMM op proxies. Subclasses set PARAMS (the strategy's params dataclass), PROPERTIES
    (Prop rows), CHOICES (enumeration property -> {property value: core value}), DEFAULTS (values of
    properties that name no params field), READ_ONLY, RESTORED_DEFAULTS (what a property added later gets
    in a document saved before it: the behaviour the document was computed with), and implement
    `compute(obj)` (opExecute runs it through `guarded`)."""

    PARAMS: Optional[type] = None
    PROPERTIES: list[Prop] = []
    CHOICES: dict[str, dict[str, Any]] = {}
    DEFAULTS: dict[str, Any] = {}
    READ_ONLY: tuple[str, ...] = ()
    RESTORED_DEFAULTS: dict[str, Any] = {}
    SPECS: dict[str, Any] = {}   # the ranges of properties that name no params field (app.stages), by property
    ESTIMATE: Optional[Callable[..., Any]] = None   # the strategy's inputs from the properties (app.work_estimate)
    STRATEGY: Any = None         # the core strategy module: its estimate_work(params, cutter, bounds) (core.work)
    progress_enabled: bool = True
    path_record: Optional[path_build.PathRecord] = None   # the current Path as rows (None: read the Path)
    cancelled: bool = False   # the last compute was cancelled by the user: no path, no failure
    path_counts: Optional[tuple[int, int]] = None   # the status line's (moves, cuts) of a Path read once

    def __init__(self, obj: Any, name: str, parentJob: Any = None,
                 values: Optional[dict[str, Any]] = None) -> None:
        # `values` are applied with the defaults, before ObjectOp's first recompute
        self._initial_values = dict(values or {})
        super().__init__(obj, name, parentJob)

    # --- the property table -------------------------------------------------------------------
    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Every property's default: from the params dataclass for rows that name a field, else DEFAULTS."""
        out = dict(cls.DEFAULTS)
        by_name = {f.name: f for f in fields(cls.PARAMS)} if cls.PARAMS else {}
        for row in cls.PROPERTIES:
            f = by_name.get(row.field)
            if f is None or f.default is MISSING or f.default is None:
                continue
            value = f.default
            if row.name in cls.CHOICES:
                value = {core: prop for prop, core in cls.CHOICES[row.name].items()}[value]
            out[row.name] = value
        return out

    def params_from(self, obj: Any, **extra: Any) -> Any:
        """The strategy's params from the op's properties (rows naming a field) and `extra`."""
        values: dict[str, Any] = {}
        for row in self.PROPERTIES:
            if not row.field:
                continue
            value = _plain(getattr(obj, row.name))
            if row.name in self.CHOICES:
                value = self.CHOICES[row.name][value]
            elif row.type == "App::PropertyBool":
                value = bool(value)
            values[row.field] = value
        values.update(extra)
        return self.PARAMS(**values)  # validated by the strategy's compute

    def initOperation(self, obj: Any) -> None:
        self.ensure_properties(obj, restoring=False)

    def ensure_properties(self, obj: Any, restoring: bool) -> None:
        """Adds missing properties; on restoring, documents from older versions get them with defaults."""
        defaults = self.defaults()
        for row in self.PROPERTIES:
            if not hasattr(obj, row.name):
                obj.addProperty(row.type, row.name, row.group, row.tooltip)
                if row.name in self.CHOICES:
                    setattr(obj, row.name, list(self.CHOICES[row.name]))
                if restoring and row.name in defaults:  # an older document: what it computed then
                    setattr(obj, row.name, self.RESTORED_DEFAULTS.get(row.name, defaults[row.name]))
            elif restoring and row.name in self.CHOICES:  # choices added since it was saved: offered, value kept
                known = obj.getEnumerationsOfProperty(row.name) or []
                if set(self.CHOICES[row.name]) - set(known):
                    value = getattr(obj, row.name)
                    setattr(obj, row.name, list(self.CHOICES[row.name]))
                    if value in self.CHOICES[row.name]:
                        setattr(obj, row.name, value)
        for name in self.READ_ONLY:
            obj.setEditorMode(name, 1)
        self.ensure_path_version(obj, restoring)

    # --- a saved path from an older version (what changed is said when it recomputes differently) -----
    def ensure_path_version(self, obj: Any, restoring: bool) -> None:
        """PathVersion: the TMM path version that computed the op's Path (0: before TMM recorded it);
        PathNote: what the last recompute changed against a path an older version saved."""
        from tmm_workbench.app import path_versions

        now = path_versions.current(type(self).__name__)
        if not hasattr(obj, "PathVersion"):
            obj.addProperty("App::PropertyInteger", "PathVersion", "TMM",
                            "The TMM tool-path version that computed this op's path (0: older than the record)")
            obj.PathVersion = 0 if restoring else now
        if not hasattr(obj, "PathNote"):
            obj.addProperty("App::PropertyString", "PathNote", "TMM",
                            "What changed when a path saved by an older TMM version was recomputed")
        for name in ("PathVersion", "PathNote"):
            obj.setEditorMode(name, 1)
        self._saved_path = None
        if restoring and obj.PathVersion < now and len(obj.Path.Commands):
            self._saved_path = (int(obj.PathVersion), obj.Path.toGCode())

    def note_path_change(self, obj: Any) -> None:
        """After a good compute: the op's path version, and a note when it differs from an older version's."""
        from tmm_workbench.app import path_versions

        name = type(self).__name__
        saved, self._saved_path = getattr(self, "_saved_path", None), None
        obj.PathNote = ""
        if saved is not None and obj.Path.toGCode() != saved[1]:
            obj.PathNote = path_versions.note(name, saved[0])
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {obj.PathNote}\n")
        obj.PathVersion = path_versions.current(name)

    def opSetDefaultValues(self, obj: Any, job: Any) -> None:
        for name, value in self.defaults().items():
            setattr(obj, name, value)
        for name, value in getattr(self, "_initial_values", {}).items():
            obj.setExpression(name, None)  # a given value replaces the SetupSheet's expression
            setattr(obj, name, value)
        self._initial_values = {}
        self.new_op_state(obj, job)
        tc = getattr(obj, "ToolController", None)
        if hasattr(obj, "Holder") and tc is not None:  # the holder may be set on the tool controller
            from tmm_workbench.app import tool_assembly

            tool_assembly.ensure_tool_controller(tc)

    # --- a new op tells the truth before its first compute ----------------------
    def new_op_state(self, obj: Any, job: Any) -> None:
        """The heights' expressions (OpStockZMax + the SetupSheet's offsets) are evaluated when ObjectOp
        creates the op, before a compute sets OpStockZMax: a new op showed 3 / 5 mm. The stock's top goes in
        first. The Job's post follows its first op (jobs.post_for_first_op)."""
        from tmm_workbench.app import job as jobs
        from tmm_workbench.app import registry

        stock = getattr(job, "Stock", None)
        if stock is not None and not stock.Shape.isNull() and hasattr(obj, "OpStockZMax"):
            bb = stock.Shape.BoundBox
            obj.OpStockZMin, obj.OpStockZMax = bb.ZMin, bb.ZMax
        op_type = next((e.name for e in registry.OPS if e.app_module == type(self).__module__), "")
        jobs.post_for_first_op(job, obj, op_type)

    def isToolSupported(self, obj: Any, tool: Any) -> bool:
        # every shape TMM maps is offered; the strategy refuses the cutters it cannot use with its reason
        return shape_name(tool) in TOOLBIT_SHAPES

    # --- computation --------------------------------------------------------------------------
    def execute(self, obj: Any) -> None:
        """FreeCAD's ObjectOp.execute returns early, keeping the old Path and leaving the op valid, when the
        tool controller is missing or the tool's diameter is 0; these and a missing kernel are checked
        first here and fail the op. If ObjectOp still returns before computing, the op fails too."""
        self._rows: Optional[tuple[int, path_build.MoveRows]] = None   # set by add_rows
        if not obj.Active:
            super().execute(obj)
            return
        work_estimate.apply_work_limits()
        problem = self.input_problem(obj)
        if problem:
            self.fail(obj, problem)
        self.check_work(obj)
        self._computed = False
        self._cancel_pending = False
        super().execute(obj)
        self.cancelled = self._cancel_pending   # after obj.Path was set (its change clears the flag)
        if not self._computed:
            self.fail(obj, "FreeCAD did not compute the operation (its Job, model or stock is missing; "
                           "see the report view)")
        self.keep_record()
        self.note_path_change(obj)
        self.set_cycle_time(obj)

    def keep_record(self) -> None:
        """The record of the Path just set from the command list (after obj.Path was set: its change forgets
        the previous record)."""
        if self._rows is not None and self.path_record is None:
            self.path_record = path_build.record(self.commandlist, *self._rows)

    def getCycleTimeEstimate(self, obj: Any) -> str:
        """ObjectOp's estimate reads the Path back (a copy of every command): TMM's from the rows instead
        (set_cycle_time replaces ObjectOp's anyway)."""
        from tmm_workbench.core.sim.cycle_time import hms

        if getattr(self, "_rows", None) is not None:
            self.keep_record()
            try:
                seconds = self.record_cycle_seconds(obj)
            except TmmError:
                seconds = None
            if seconds is not None:
                return hms(seconds)
        return super().getCycleTimeEstimate(obj)

    def opOnChanged(self, obj: Any, prop: str) -> None:
        if prop == "Path":   # a new Path (a compute, an undo, a paste): what was known of the old one is void
            self.path_record, self.path_counts, self.cancelled = None, None, False

    @contextmanager
    def reporting(self, obj: Any) -> Iterator[Callable[[float], bool]]:
        """The op's progress (the GUI's dialog with Cancel) from the kernel's start to the last command made,
        watched (core.cancel.poll) so the Python loops between the kernel's calls (linking, the rows) are heard."""
        from tmm_workbench.app import progress
        from tmm_workbench.core import cancel

        with progress.reporter(obj.Label, self.progress_enabled) as cb, cancel.watching(cb):
            yield cb

    def add_rows(self, rows: path_build.MoveRows, progress: Optional[Callable[[float], bool]] = None) -> None:
        """The commands of `rows` at the end of the op's command list, made in chunks (`progress` between
        them); the rows are kept as the record of the Path they go into."""
        bad = path_build.unusable_row(rows, MAX_WORD)
        if bad is not None:
            raise TmmError(unusable_word(len(self.commandlist) + bad[0], *bad[1:]))
        start = len(self.commandlist)
        self.commandlist.extend(path_build.path_commands(rows, progress))
        self._rows = (start, rows)

    def set_cycle_time(self, obj: Any) -> None:
        """FreeCAD's CycleTime counts no rotary axis and no joint speed: TMM's estimate replaces it
        (app.simulation.op_cycle_seconds), and the Job's total is summed again."""
        from tmm_workbench.app.simulation import op_cycle_seconds
        from tmm_workbench.core.sim.cycle_time import hms

        try:
            seconds = self.record_cycle_seconds(obj)
            if seconds is None:
                seconds = op_cycle_seconds(obj)
        except TmmError as exc:  # the op's own estimate stays; say why ours is missing
            FreeCAD.Console.PrintWarning(f"{obj.Label}: no cycle time estimate ({exc})\n")
            return
        obj.CycleTime = hms(seconds)
        job = getattr(self, "job", None)
        if job is not None and hasattr(getattr(job, "Proxy", None), "getCycleTime"):
            job.Proxy.getCycleTime()

    def record_cycle_seconds(self, obj: Any) -> Optional[float]:
        """The 3-axis cycle time from the record of the Path (no command read back), or None without one."""
        from tmm_workbench.core.sim.cycle_time import three_axis_time

        rec = self.path_record
        if rec is not None and rec.cycle_s is None:
            moves = path_build.line_moves(rec)
            if moves is not None:
                tc = obj.ToolController
                rec.cycle_s = three_axis_time(moves[0], moves[1], tc.HorizRapid.Value, tc.VertRapid.Value).seconds
        return rec.cycle_s if rec is not None else None

    def input_problem(self, obj: Any) -> str:
        """What makes computing impossible, in the user's terms ('' when nothing)."""
        from tmm_workbench.app.compat import PathUtils

        if PathUtils.findParentJob(obj) is None:
            return "the operation is not in a Job"
        tc = getattr(obj, "ToolController", None)
        if tc is None or getattr(tc, "ToolNumber", 0) == 0:
            return "no tool controller: choose one in the operation's panel (ToolController)"
        tool = getattr(tc, "Tool", None)
        if tool is None:
            return f"tool controller '{tc.Label}' has no tool"
        try:
            d = float(_plain(tool.Diameter))
        except (AttributeError, TypeError, ValueError):
            return f"tool '{label_of(tool)}' has no diameter"
        if not (math.isfinite(d) and d > 0):
            return f"tool '{label_of(tool)}': diameter must be a length > 0 mm, got {d:g} mm"
        problem = feed_problem(tc)
        if problem:
            return problem
        try:
            kernel.require()
        except kernel.KernelMissing as exc:
            return str(exc)
        return ""

    def check_work(self, obj: Any) -> None:
        """The work estimated from the properties and bounding boxes before anything is tessellated or allocated
        (app.work_estimate; an STL file is read for its bounds, once: the op then computes from the same read),
        a computation of more than LONG_COMPUTE_S announced; the chosen post's need of a spindle speed
        reported."""
        try:
            work_estimate.check_ranges(obj)
        except TmmError as exc:
            self.fail(obj, str(exc))
        try:
            est = work_estimate.estimate(obj)
        except WorkLimitError as exc:
            self.fail(obj, str(exc))
        except TmmError:  # other bad input: the computation names it with what it reads
            est = None
        if est is not None and est.long:  # minutes of computing are announced, not a surprise
            FreeCAD.Console.PrintMessage(f"{obj.Label}: {est.text()}; Cancel (the progress dialog, Esc) stops "
                                         "it\n")
        spindle = spindle_problem(obj)
        if spindle:
            FreeCAD.Console.PrintWarning(f"{obj.Label}: {spindle}\n")

    def opExecute(self, obj: Any) -> None:
        self._computed = True
        self.clear_results()
        self.guarded(obj, lambda: self.compute(obj))
        self.check_finite(obj)

    def check_finite(self, obj: Any) -> None:
        """The last look before FreeCAD makes the Path: a NaN or infinite word would reach the G-code and the
        machine (0.20 writes NaN as Z-922337203685.477581). Every cause is refused at its input; this
        catches one not yet found."""
        start, n = (self._rows[0], len(self._rows[1])) if getattr(self, "_rows", None) else (0, 0)
        others = self.commandlist[:start] + self.commandlist[start + n:]   # the rows are checked as arrays
        values = np.fromiter((v for c in others for v in c.Parameters.values()), float)
        if (np.abs(values) <= MAX_WORD).all():
            return
        for k, c in enumerate(self.commandlist):  # only on failure: name the first bad word
            bad = [(w, v) for w, v in c.Parameters.items() if not abs(v) <= MAX_WORD]
            if bad:
                self.fail(obj, unusable_word(k, c.Name, bad[0][0], bad[0][1]))

    def compute(self, obj: Any) -> None:
        raise NotImplementedError

    def clear_results(self) -> None:
        """Forgets the transient results of the last run (subclasses name theirs)."""

    def cutter(self) -> Cutter:
        """The op's tool as the core's cutter (the one ToolBit map)."""
        return cutter_from_tool(self.tool)

    def guarded(self, obj: Any, compute: Callable[[], None]) -> None:
        """Runs the op's computation; a TmmError, a cancel or anything unexpected (a kernel failure, a
        bug) fails the op cleanly instead of crashing or leaving a partial path."""
        try:
            compute()
        except Cancelled:
            self.cancel(obj)
        except TmmError as exc:
            self.fail(obj, str(exc))
        except Exception as exc:
            FreeCAD.Console.PrintLog(traceback.format_exc())
            self.fail(obj, f"unexpected {type(exc).__name__}: {exc}")

    def cancel(self, obj: Any) -> None:
        """The user's Cancel: an ordinary outcome, not a failure (no error, no box, the op stays valid). The op is
        left without a path (its properties may have changed since the last one: an old path would not be
        theirs) and says so in its status line and the report view; a recompute computes it."""
        self.commandlist = []
        self._rows = None
        self.clear_results()
        self._cancel_pending = True
        FreeCAD.Console.PrintMessage(f"{obj.Label}: {CANCELLED}\n")

    def fail(self, obj: Any, message: str) -> None:
        """Empty Path, message in the report view, and an exception: FreeCAD marks the op invalid
        and keeps the message as its status (tree tooltip, `obj.getStatusString()`)."""
        self.commandlist = []
        self.clear_results()
        obj.Path = Path.Path()
        self.on_fail(obj)
        FreeCAD.Console.PrintError(f"{obj.Label}: {message}\n")
        hooks.report_failure(obj, message)  # the GUI's message box; headless nothing
        raise TmmError(message) from None

    def on_fail(self, obj: Any) -> None:
        """Clears what a subclass shows of its last result."""


def unusable_word(index: int, name: str, word: str, value: float) -> str:
    """The failure of a path with a word that is no usable number (command `index`, from 0)."""
    return (f"the computed tool path has a word that is not a usable number ({name} {word}{value:g} in command "
            f"{index + 1}): nothing was written. Please report this with the document")


def feed_problem(tc: Any) -> str:
    """Why the tool controller's cutting feeds cannot run ('' when they can)."""
    for name in ("HorizFeed", "VertFeed"):
        v = float(_plain(getattr(tc, name, 0.0)))  # mm/s
        if not (math.isfinite(v) and v > 0):
            # tool controllers from FreeCAD's tool library start with no feeds: G1 F0 would stall the machine
            return (f"tool controller '{tc.Label}': {name} must be a feed > 0 mm/min, got {v * 60:g} mm/min "
                    "(set the cutting feeds in the tool controller)")
    return ""


# posts that write no spindle words (cutter location data): a spindle speed of 0 is no problem for them
NO_SPINDLE_POSTS = ("apt_cl",)


def spindle_problem(obj: Any) -> str:
    """'' unless the op's tool controller turns the spindle at 0 rpm and its Job's post writes spindle words
    (the program would cut with the spindle stopped)."""
    from tmm_workbench.app.compat import PathUtils

    tc = getattr(obj, "ToolController", None)
    job = PathUtils.findParentJob(obj)
    if tc is None or job is None or getattr(tc, "SpindleDir", "Forward") == "None":
        return ""
    post = str(getattr(job, "PostProcessor", "") or "")
    speed = float(_plain(getattr(tc, "SpindleSpeed", 0.0)))
    if post and post not in NO_SPINDLE_POSTS and not (math.isfinite(speed) and speed > 0):
        return (f"tool controller '{tc.Label}': SpindleSpeed is {speed:g} rpm with the spindle on, and the Job's "
                f"post '{post}' writes it (S0): set the spindle speed in the tool controller")
    return ""


def create(proxy_class: type, view_kind: str, name: str, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`; in the
    GUI it gets the view provider `view_kind` (hooks.attach_view)."""
    if obj is None:
        doc = parentJob.Document if parentJob is not None else FreeCAD.ActiveDocument
        from tmm_workbench.app import registry

        obj = doc.addObject("Path::FeaturePython", name)
        obj.Label = registry.user_name(name)   # the user's words, not the type name
    obj.Proxy = proxy_class(obj, name, parentJob, values)
    if obj.Proxy is not None:  # not for the SetupSheet's prototypes
        hooks.attach_view(view_kind, obj)
    return obj


def setup_properties(proxy_class: type, exclude: tuple[str, ...] = ()) -> list[str]:
    """Properties the Job's SetupSheet may hold defaults for."""
    return [row.name for row in proxy_class.PROPERTIES if row.name not in exclude]
