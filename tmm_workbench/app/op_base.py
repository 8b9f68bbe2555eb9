"""What the TMM Path operations share: properties declared as tables, values given at creation, the ToolBit
shapes an op accepts, and the one way a computation fails (empty Path, message in the report view, op
marked invalid with that message as its status: no partial path ever)."""
from __future__ import annotations

import traceback
from typing import Any, Callable, Optional

import FreeCAD
import Path

from tmm_workbench.app import hooks
from tmm_workbench.app.compat import PathOp
from tmm_workbench.app.tools import shape_name
from tmm_workbench.core.errors import Cancelled, TmmError


class TmmOp(PathOp.ObjectOp):
    """Base of the TMM op proxies. Subclasses set PROPERTIES ((type, name, group, tooltip) rows),
    ENUMERATIONS (name -> choices), DEFAULTS (name -> value), READ_ONLY (names), SUPPORTED_SHAPES (ToolBit
    shape names) and implement opExecute through `guarded`."""

    PROPERTIES: list[tuple[str, str, str, str]] = []
    ENUMERATIONS: dict[str, list[str]] = {}
    DEFAULTS: dict[str, Any] = {}
    READ_ONLY: tuple[str, ...] = ()
    SUPPORTED_SHAPES: tuple[str, ...] = ()
    progress_enabled: bool = True

    def __init__(self, obj: Any, name: str, parentJob: Any = None,
                 values: Optional[dict[str, Any]] = None) -> None:
        # `values` are applied with the defaults, before ObjectOp's first recompute
        self._initial_values = dict(values or {})
        super().__init__(obj, name, parentJob)

    def initOperation(self, obj: Any) -> None:
        self.ensure_properties(obj, restoring=False)

    def ensure_properties(self, obj: Any, restoring: bool) -> None:
        """Adds missing properties; on restoring, documents from older versions get them with defaults."""
        for typ, name, group, tip in self.PROPERTIES:
            if not hasattr(obj, name):
                obj.addProperty(typ, name, group, tip)
                if name in self.ENUMERATIONS:
                    setattr(obj, name, self.ENUMERATIONS[name])
                if restoring and name in self.DEFAULTS:
                    setattr(obj, name, self.DEFAULTS[name])
        for name in self.READ_ONLY:
            obj.setEditorMode(name, 1)

    def opSetDefaultValues(self, obj: Any, job: Any) -> None:
        for name, value in self.DEFAULTS.items():
            setattr(obj, name, value)
        for name, value in getattr(self, "_initial_values", {}).items():
            obj.setExpression(name, None)  # a given value replaces the SetupSheet's expression
            setattr(obj, name, value)
        self._initial_values = {}

    def isToolSupported(self, obj: Any, tool: Any) -> bool:
        return shape_name(tool) in self.SUPPORTED_SHAPES

    def guarded(self, obj: Any, compute: Callable[[], None]) -> None:
        """Runs the op's computation; a TmmError, a cancel or anything unexpected (a kernel failure, a
        bug) fails the op cleanly instead of crashing or leaving a partial path."""
        try:
            compute()
        except Cancelled:
            self.fail(obj, "tool path computation cancelled")
        except TmmError as exc:
            self.fail(obj, str(exc))
        except Exception as exc:
            FreeCAD.Console.PrintLog(traceback.format_exc())
            self.fail(obj, f"unexpected {type(exc).__name__}: {exc}")

    def fail(self, obj: Any, message: str) -> None:
        """Empty Path, message in the report view, and an exception: FreeCAD marks the op invalid
        and keeps the message as its status (tree tooltip, `obj.getStatusString()`)."""
        self.commandlist = []
        obj.Path = Path.Path()
        self.on_fail(obj)
        FreeCAD.Console.PrintError(f"{obj.Label}: {message}\n")
        raise TmmError(message) from None

    def on_fail(self, obj: Any) -> None:
        """Clears what a subclass shows of its last result."""


def create(proxy_class: type, view_kind: str, name: str, obj: Any = None, parentJob: Any = None,
           values: Optional[dict[str, Any]] = None) -> Any:
    """A new op in `parentJob` (or the only Job of the active document), with property `values`; in the
    GUI it gets the view provider `view_kind` (hooks.attach_view)."""
    if obj is None:
        doc = parentJob.Document if parentJob is not None else FreeCAD.ActiveDocument
        obj = doc.addObject("Path::FeaturePython", name)
    obj.Proxy = proxy_class(obj, name, parentJob, values)
    if obj.Proxy is not None:  # not for the SetupSheet's prototypes
        hooks.attach_view(view_kind, obj)
    return obj
