"""View providers for objects made by App code (InitGui.py registers these in app.hooks, lazily)."""
from __future__ import annotations

from typing import Any

from tmm_workbench.app.compat import import_gui


def attach_op(obj: Any) -> None:
    from tmm_workbench.gui import op_surface_gui

    op_surface_gui.attach_view_provider(obj)


def attach_job(job: Any) -> None:
    """What PathJobGui.Create gives a Job (its view provider with the group extension)."""
    vo = job.ViewObject
    if getattr(vo, "Proxy", None) is None:
        PathJobGui = import_gui("job_gui")
        vo.Proxy = PathJobGui.ViewProvider(vo)
        vo.addExtension("Gui::ViewProviderGroupExtensionPython")
        vo.Proxy.deleteOnReject = False
