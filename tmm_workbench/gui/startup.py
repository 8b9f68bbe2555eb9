"""What InitGui.py installs at FreeCAD start: hooks that bring in Gui code only when first used.

- view providers for Jobs and ops made from Python (API, macros), through app.hooks;
- the GUI progress (a dialog with Cancel) for TMM computations, through app.progress.
"""
from __future__ import annotations

from typing import Any, Callable


def _lazy_view(kind: str) -> Callable[[Any], None]:
    def attach(obj: Any) -> None:
        from tmm_workbench.gui import view_providers  # Path's Gui modules load here, not at start-up

        getattr(view_providers, "attach_" + kind)(obj)
    return attach


def _multipoint_view(obj: Any) -> None:
    from tmm_workbench.gui import op_multipoint_gui  # Path's Gui modules load here, not at start-up

    op_multipoint_gui.attach_view_provider(obj)


def _dialog_progress(label: str) -> Any:
    from tmm_workbench.gui import progress_dialog

    return progress_dialog.factory(label)


def install_hooks() -> None:
    from tmm_workbench.app import hooks, progress

    hooks.view_hooks.setdefault("op", _lazy_view("op"))
    hooks.view_hooks.setdefault("job", _lazy_view("job"))
    hooks.view_hooks.setdefault("multipoint_op", _multipoint_view)
    progress.progress_factory = _dialog_progress
