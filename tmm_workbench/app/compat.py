"""FreeCAD 0.20, 1.0 and 1.1 differences for the Path (CAM) workbench, in one place.

0.20 keeps everything in `PathScripts.Path*`; from 0.21 the same code lives in `Path.Op.Base`,
`Path.Main.Job`, ... (and from 1.0 under the CAM module, with the same `Path.*` package names).
App-level modules are imported here; Gui-level ones are only named here and imported by
`tmm_workbench.gui` through `import_gui()` (the App layer never imports Gui code).
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
from types import ModuleType
from typing import Any, Callable, Optional

# role -> (0.20 module, 0.21+ module[, 1.1 module])
_APP_MODULES: dict[str, tuple[str, ...]] = {
    "op": ("PathScripts.PathOp", "Path.Op.Base"),
    "job": ("PathScripts.PathJob", "Path.Main.Job"),
    "stock": ("PathScripts.PathStock", "Path.Main.Stock"),
    "tool_controller": ("PathScripts.PathToolController", "Path.Tool.Controller"),
    "tool_bit": ("PathScripts.PathToolBit", "Path.Tool.Bit"),
    "post_processor": ("PathScripts.PathPostProcessor", "Path.Post.Processor"),
    "preferences": ("PathScripts.PathPreferences", "Path.Preferences"),
    "utils": ("PathScripts.PathUtils", "PathScripts.PathUtils"),
    "setup_sheet": ("PathScripts.PathSetupSheet", "Path.Base.SetupSheet"),
    "geom": ("PathScripts.PathGeom", "Path.Geom"),
}
_GUI_MODULES: dict[str, tuple[str, ...]] = {
    "op_gui": ("PathScripts.PathOpGui", "Path.Op.Gui.Base"),
    "gui_init": ("PathScripts.PathGuiInit", "Path.GuiInit"),
    "job_cmd": ("PathScripts.PathJobCmd", "Path.Main.Gui.JobCmd"),
    "tool_bit_cmd": ("PathScripts.PathToolBitCmd", "Path.Tool.Gui.BitCmd", "Path.Tool.toolbit.ui.cmd"),
    "tool_bit_library_cmd": ("PathScripts.PathToolBitLibraryCmd", "Path.Tool.Gui.BitLibraryCmd",
                             "Path.Tool.library.ui.cmd"),
    "commands": ("PathCommands", "PathCommands"),
    "path_gui": ("PathScripts.PathGui", "Path.Base.Gui.Util"),
    "job_gui": ("PathScripts.PathJobGui", "Path.Main.Gui.Job"),
    "icon_view_provider": ("PathScripts.PathIconViewProvider", "Path.Base.Gui.IconViewProvider"),
}


def _import(names: tuple[str, ...]) -> ModuleType:
    """The first of `names` that imports (FreeCAD versions moved the modules); the last one's error if none."""
    for i, name in enumerate(names):
        try:
            return importlib.import_module(name)
        except ImportError as exc:
            if "Gui module in console" in str(exc) or i == len(names) - 1:
                raise
    raise ImportError(f"none of {names}")


def import_app(role: str) -> ModuleType:
    return _import(_APP_MODULES[role])


def import_gui(role: str) -> ModuleType:
    """Gui modules by role; only for tmm_workbench.gui (raises ImportError headless)."""
    return _import(_GUI_MODULES[role])


# Module attributes are imported on first use: Init.py runs before FreeCAD.GuiUp exists, which some
# Path modules read at import time.
_NAMES = {"PathOp": "op", "PathJob": "job", "PathStock": "stock", "PathToolController": "tool_controller",
          "PathToolBit": "tool_bit", "PathPostProcessor": "post_processor", "PathPreferences": "preferences",
          "PathUtils": "utils", "PathSetupSheet": "setup_sheet"}


def __getattr__(name: str) -> ModuleType:
    role = _NAMES.get(name)
    if role is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = import_app(role)
    globals()[name] = module
    return module


def freecad_version() -> tuple[int, int]:
    import FreeCAD

    major, minor = FreeCAD.Version()[:2]
    return int(major), int(minor)


MIN_VERSION = (0, 20)
# Path modules TMM cannot work without, by role (the rest are looked up where used)
REQUIRED_ROLES = ("op", "job", "tool_controller", "tool_bit", "preferences", "utils", "setup_sheet")


def restore_tool_controllers() -> None:
    """FreeCAD 0.20 on Python 3.11: a tool controller's proxy has no attributes, so Python's default __getstate__
    gives None, saved as "null"; on reopening, 0.20 restores a proxy without __setstate__ by setting its __dict__
    to that None, which fails: a red "setAttr failed" per tool controller on every reopen (also for a Job made by
    FreeCAD alone). A __setstate__ that takes the saved state (None or a dict) ends it, for documents saved before
    too. FreeCAD 0.21+ saves proxies through dumps/loads and needs nothing."""
    if freecad_version() >= (0, 21):
        return
    cls = import_app("tool_controller").ToolController
    if "__setstate__" in vars(cls) or hasattr(cls, "loads"):
        return

    def __setstate__(self: Any, state: Any) -> None:
        if isinstance(state, dict):
            self.__dict__.update(state)

    cls.__setstate__ = __setstate__


def mend_tool_controller_restore() -> None:
    """restore_tool_controllers as soon as FreeCAD 0.20's tool controller module is imported (Init.py cannot
    import it: the module reads FreeCAD.GuiUp, which does not exist yet), before any document restores one."""
    if freecad_version() < (0, 21):
        after_import(_APP_MODULES["tool_controller"][0], restore_tool_controllers)


def after_import(name: str, action: Callable[[], None]) -> None:
    """Runs `action` once the module `name` has been imported (at once if it is already)."""
    if name in sys.modules:
        action()
        return

    class Finder:
        def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
            if fullname != name:
                return None
            sys.meta_path.remove(self)
            spec = importlib.util.find_spec(fullname)
            if spec is None or spec.loader is None:
                return spec
            load = spec.loader.exec_module

            def load_then_act(module: ModuleType) -> None:
                load(module)
                action()
            spec.loader.exec_module = load_then_act  # type: ignore[method-assign]
            return spec

    sys.meta_path.insert(0, Finder())


def support_problem(version: Optional[tuple[int, int]] = None,
                    modules: Optional[dict[str, tuple[str, ...]]] = None) -> str:
    """Why this FreeCAD cannot run TMM ('' when it can): too old, or a Path module of a required role that
    does not import (a newer FreeCAD whose CAM API moved). Says the version and what failed."""
    major, minor = version or freecad_version()
    if (major, minor) < MIN_VERSION:
        return (f"FreeCAD {major}.{minor} is not supported: TMM needs FreeCAD {MIN_VERSION[0]}.{MIN_VERSION[1]} "
                "or later (tested on 0.20, 1.0 and 1.1)")
    table = _APP_MODULES if modules is None else modules
    for role in REQUIRED_ROLES:
        names = table.get(role, ())
        try:
            _import(names)
        except ImportError as exc:
            return (f"FreeCAD {major}.{minor} is not supported: its CAM module for '{role}' "
                    f"({' / '.join(names)}) does not import ({exc}); TMM is tested on 0.20, 1.0 and 1.1")
    return ""


def command_prefix() -> str:
    """PathOpGui.SetupOperation registers 'Path_<op>' on 0.20 and 'CAM_<op>' from 1.0 (the workbench was
    renamed); FreeCAD's own commands follow the same rule (Path_Job / CAM_Job)."""
    return "Path_" if freecad_version() < (1, 0) else "CAM_"


def load_post(name: str) -> ModuleType:
    """The script post `<name>_post.py` (a module with `export(objects, filename, args)`) from the post
    search path, TMM's folder included. 0.20 has PostProcessor.load for this, 1.0 removed it (its factory
    wraps a script post to export the Job's whole list); 1.1 renamed the stock script posts
    `<name>_legacy_post.py` and made the plain names classes, so a module without `export` is looked up
    again as the legacy script. ImportError when no script post of that name exists."""
    import importlib.util
    import os

    preferences = import_app("preferences")
    paths = list(preferences.searchPathsPost())
    for module_name in (f"{name}_post", f"{name}_legacy_post"):
        for folder in paths:
            path = os.path.join(folder, module_name + ".py")
            if not os.path.isfile(path):
                continue
            spec = importlib.util.spec_from_file_location(module_name, path)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)  # type: ignore[union-attr]
            if callable(getattr(module, "export", None)):
                return module
    raise ImportError(f"no script post '{name}' on the post search path ({', '.join(paths)})")


def stock_bit_file(file_name: str) -> str:
    """A ToolBit file FreeCAD ships ('5mm_Endmill.fctb'): Mod/Path/Tools/Bit on 0.20, Mod/CAM/Tools/Bit from
    1.0 (searchPathsTool("Bit") on both; 1.1 removed it)."""
    import os

    import FreeCAD

    preferences = import_app("preferences")
    folders = list(preferences.searchPathsTool("Bit")) if hasattr(preferences, "searchPathsTool") else []
    folders.append(os.path.join(FreeCAD.getHomePath(), "Mod", "CAM", "Tools", "Bit"))
    for folder in folders:
        path = os.path.join(folder, file_name)
        if os.path.isfile(path):
            return path
    raise FileNotFoundError(f"FreeCAD ships no ToolBit '{file_name}' (looked in {', '.join(folders)})")


def toolbits_are_assets() -> bool:
    """FreeCAD 1.1 rewrote ToolBits (an asset manager, `ShapeID`, `CornerRadius` for bull-noses; no Factory)."""
    return getattr(import_app("tool_bit"), "Factory", None) is None


def make_toolbit(doc: Any, shape: str, parameters: dict[str, str], label: str) -> Any:
    """A ToolBit object in `doc` of FreeCAD's shape `shape` ('ballend') or of the shape file `shape` (a path
    to an .fcstd: every version takes a custom shape so), with `parameters` (unit strings)."""
    import FreeCAD

    FreeCAD.setActiveDocument(doc.Name)
    custom = shape.lower().endswith(".fcstd")
    if not toolbits_are_assets():
        return import_app("tool_bit").Factory.CreateFromAttrs(
            {"name": label, "shape": shape if custom else shape + ".fcstd", "parameter": parameters,
             "attribute": {}}, name="ToolBit")
    from Path.Tool.toolbit import ToolBit  # 1.1

    attrs = {"name": label, "parameter": parameters, "attribute": {}}
    if custom:  # 1.1 looks shapes up in its asset store by name; a file outside it is read directly
        import pathlib

        from Path.Tool.shape import ToolBitShape

        bit = ToolBit.from_shape(ToolBitShape.from_file(pathlib.Path(shape)), attrs)
    else:
        bit = ToolBit.from_dict(dict(attrs, shape=shape))
    return bit.attach_to_doc(doc, label)


def settle_toolbit(tool_controller: Any) -> None:
    """Rebuilds now the shape body that FreeCAD 1.1's ToolBit rebuilds after the next document recompute when one
    of its dimensions changed (its queued visual update): that rebuild leaves the new body touched, so the
    recompute after it computes the bit, its tool controller and every op cutting with it again. Called once the
    controller's bit is set up and before an op uses it, the rebuild costs the bit's own objects only. Nothing to
    do on 0.20 and 1.0 (no queue)."""
    bit = getattr(tool_controller, "Tool", None)
    proxy = getattr(bit, "Proxy", None)
    if not getattr(proxy, "_visual_update_queued", False) or not hasattr(proxy, "_process_queued_visual_update"):
        return
    proxy._process_queued_visual_update()
    body = getattr(bit, "BitBody", None)
    parts = [body, *body.OutListRecursive] if body is not None else []
    bit.Document.recompute([*parts, bit, tool_controller])


def remove_toolbit(bit: Any) -> None:
    """Deletes a ToolBit object and its shape body (0.20/1.0: unloadBitBody; 1.1: _removeBitBody)."""
    proxy = getattr(bit, "Proxy", None)
    if getattr(bit, "BitBody", None) is not None and proxy is not None:
        if hasattr(proxy, "unloadBitBody"):
            proxy.unloadBitBody(bit)
        elif hasattr(proxy, "_removeBitBody"):
            proxy._removeBitBody()
    bit.Document.removeObject(bit.Name)


def toolbit_from_file(doc: Any, path: str) -> Any:
    """A ToolBit object in `doc` from a .fctb file (0.20 and 1.0: Factory.CreateFrom, which also finds the
    shape in the Shape folder beside the file's Bit folder; 1.1: ToolBit.from_file, and for a shape 1.1's
    asset store lacks but that folder holds, such as TMM's resources/tools, the shape file read directly)."""
    import FreeCAD

    FreeCAD.setActiveDocument(doc.Name)
    if not toolbits_are_assets():
        return import_app("tool_bit").Factory.CreateFrom(path)
    import json
    import os

    from Path.Tool.camassets import cam_assets  # 1.1
    from Path.Tool.shape import ToolBitShape
    from Path.Tool.toolbit import ToolBit

    with open(path, encoding="utf-8") as f:
        attrs = json.load(f)
    shape = os.path.basename(str(attrs.get("shape", "")))
    beside = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(path))), "Shape", shape)
    if shape and os.path.isfile(beside) and not cam_assets.exists(
            ToolBitShape.resolve_name(shape), store=("local", "builtin")):
        return make_toolbit(doc, beside, attrs.get("parameter", {}), attrs.get("name") or shape)
    return ToolBit.from_file(path).attach_to_doc(doc)
