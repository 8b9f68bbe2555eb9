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


class BoundsViewProvider:
    """View provider of TMM's stand-in box for a mesh model (app.model_proxy): hidden, so the user sees the mesh.
    A Part::FeaturePython without a view provider proxy comes back visible when its document is reopened
    (FreeCAD 0.20: its saved Visibility is not kept); with one it stays as saved."""

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    def __getstate__(self) -> None:
        return None

    def __setstate__(self, state: Any) -> None:
        return None


def attach_bounds(obj: Any) -> None:
    """The stand-in box gets its view provider and is hidden, with the Job's clones of it (a clone saved without
    the GUI has no view provider proxy either: it gets the one the Job gives its model clones in the GUI)."""
    if not isinstance(getattr(obj.ViewObject, "Proxy", None), BoundsViewProvider):
        BoundsViewProvider(obj.ViewObject)
    obj.ViewObject.Visibility = False
    for clone in (o for o in obj.InList if obj in (getattr(o, "Objects", None) or [])):
        vo = getattr(clone, "ViewObject", None)
        if vo is None:
            continue
        if getattr(vo, "Proxy", None) is None:
            import_gui("icon_view_provider").Attach(vo, "BaseGeometry")
        vo.Visibility = False
