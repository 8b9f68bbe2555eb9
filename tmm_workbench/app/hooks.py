"""View-provider hooks: objects made by App code (API, macros) get the same view providers as the
ones the GUI commands make. The App layer never imports Gui code, so the GUI registers callables here
(InitGui.py, lazily) and App code calls `attach_view(kind, obj)`; headless nothing happens."""
from __future__ import annotations

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
