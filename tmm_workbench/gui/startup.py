"""What InitGui.py installs at FreeCAD start: hooks that bring in Gui code only when first used.

- view providers for Jobs and ops made from Python (API, macros), through app.hooks;
- the GUI progress (a dialog with Cancel) for TMM computations, through app.progress;
- from FreeCAD 1.0, TMM's operations in the CAM workbench's toolbar (gui.cam_integration).
"""
from __future__ import annotations

from typing import Any, Callable


def _job_view(obj: Any) -> None:
    from tmm_workbench.gui import view_providers  # Path's Gui modules load here, not at start-up

    view_providers.attach_job(obj)


def _bounds_view(obj: Any) -> None:
    from tmm_workbench.gui import view_providers

    view_providers.attach_bounds(obj)


def _op_view(entry: Any) -> Callable[[Any], None]:
    def attach(obj: Any) -> None:
        entry.gui().attach_view_provider(obj)  # Path's Gui modules load here, not at start-up
    return attach


def _dialog_progress(label: str) -> Any:
    from tmm_workbench.gui import progress_dialog

    return progress_dialog.factory(label)


def _failure_box(obj: Any, message: str) -> None:
    from tmm_workbench.gui import messages

    messages.on_failure(obj, message)


def install_hooks() -> None:
    from tmm_workbench.app import hooks, progress, registry

    for entry in registry.OPS:
        hooks.view_hooks.setdefault(entry.view_kind, _op_view(entry))
    hooks.view_hooks.setdefault("job", _job_view)
    hooks.view_hooks.setdefault("bounds", _bounds_view)
    progress.progress_factory = _dialog_progress
    if _failure_box not in hooks.failure_hooks:
        hooks.failure_hooks.append(_failure_box)
    from tmm_workbench.app.compat import freecad_version

    if freecad_version() >= (1, 0):
        from tmm_workbench.gui import cam_integration

        cam_integration.install()
