"""The Job's view provider for Jobs made by App code (InitGui.py registers it in app.hooks, lazily; each op's
view provider comes from its GUI module, through the op registry)."""
from __future__ import annotations

from typing import Any

from tmm_workbench.app.compat import import_gui


def attach_job(job: Any) -> None:
    """What PathJobGui.Create gives a Job (its view provider with the group extension)."""
    vo = job.ViewObject
    if getattr(vo, "Proxy", None) is None:
        PathJobGui = import_gui("job_gui")
        vo.Proxy = PathJobGui.ViewProvider(vo)
        vo.addExtension("Gui::ViewProviderGroupExtensionPython")
        vo.Proxy.deleteOnReject = False
