"""View-provider hooks: objects made by App code (API, macros) get the same view providers as the
ones the GUI commands make. The App layer never imports Gui code, so the GUI registers callables here
(InitGui.py, lazily) and App code calls `attach_view(kind, obj)`; headless nothing happens."""
from __future__ import annotations

import functools
from typing import Any, Callable

import FreeCAD

view_hooks: dict[str, Callable[[Any], None]] = {}  # kind ('op', 'job') -> attach(obj)


def attach_view(kind: str, obj: Any) -> None:
    hook = view_hooks.get(kind)
    if hook is None or not FreeCAD.GuiUp or getattr(obj, "ViewObject", None) is None:
        return
    try:
        hook(obj)
    except Exception as exc:  # a view problem must not fail the App-level operation
        FreeCAD.Console.PrintWarning(f"TMM: no view provider for {obj.Label}: {exc}\n")


# the GUI's report of a failed op, command or post (a message box); headless none
failure_hooks: list[Callable[[Any, str], None]] = []


def report_failure(obj: Any, message: str) -> None:
    """Tells the GUI that `obj` (an op, or None for a command or post) failed with `message`."""
    if not FreeCAD.GuiUp:
        return
    for hook in failure_hooks:
        try:
            hook(obj, message)
        except Exception as exc:  # showing the failure must not add one
            FreeCAD.Console.PrintWarning(f"TMM: cannot show the failure: {exc}\n")


def reported(what: str, run: Callable[..., Any]) -> Callable[..., Any]:
    """`run` (a post's export) whose failure the GUI also shows; the exception still reaches the caller."""
    @functools.wraps(run)
    def reporting(*args: Any, **kwargs: Any) -> Any:
        try:
            return run(*args, **kwargs)
        except Exception as exc:
            report_failure(None, f"{what}: {exc}")
            raise
    return reporting
