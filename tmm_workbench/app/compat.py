"""FreeCAD 0.20 vs 0.21+ module names for the Path (CAM) workbench, in one place.

0.20 keeps everything in `PathScripts.Path*`; from 0.21 the same code lives in `Path.Op.Base`,
`Path.Main.Job`, ... (and from 1.0 under the CAM module, with the same `Path.*` package names).
App-level modules are imported here; Gui-level ones are only named here and imported by
`tmm_workbench.gui` through `import_gui()` (the App layer never imports Gui code).
"""
from __future__ import annotations

import importlib
from types import ModuleType

# role -> (0.20 module, 0.21+ module)
_APP_MODULES: dict[str, tuple[str, str]] = {
    "op": ("PathScripts.PathOp", "Path.Op.Base"),
    "job": ("PathScripts.PathJob", "Path.Main.Job"),
    "stock": ("PathScripts.PathStock", "Path.Main.Stock"),
    "tool_controller": ("PathScripts.PathToolController", "Path.Tool.Controller"),
    "tool_bit": ("PathScripts.PathToolBit", "Path.Tool.Bit"),
    "post_processor": ("PathScripts.PathPostProcessor", "Path.Post.Processor"),
    "preferences": ("PathScripts.PathPreferences", "Path.Preferences"),
    "utils": ("PathScripts.PathUtils", "PathScripts.PathUtils"),
    "setup_sheet": ("PathScripts.PathSetupSheet", "Path.Base.SetupSheet"),
}
_GUI_MODULES: dict[str, tuple[str, str]] = {
    "op_gui": ("PathScripts.PathOpGui", "Path.Op.Gui.Base"),
    "gui_init": ("PathScripts.PathGuiInit", "Path.GuiInit"),
    "job_cmd": ("PathScripts.PathJobCmd", "Path.Main.Gui.JobCmd"),
    "tool_bit_cmd": ("PathScripts.PathToolBitCmd", "Path.Tool.Gui.BitCmd"),
    "tool_bit_library_cmd": ("PathScripts.PathToolBitLibraryCmd", "Path.Tool.Gui.BitLibraryCmd"),
    "commands": ("PathCommands", "PathCommands"),
    "path_gui": ("PathScripts.PathGui", "Path.Base.Gui.Util"),
    "job_gui": ("PathScripts.PathJobGui", "Path.Main.Gui.Job"),
}


def _import(names: tuple[str, str]) -> ModuleType:
    old, new = names
    try:
        return importlib.import_module(old)
    except ImportError as exc:
        if "Gui module in console" in str(exc):
            raise
        return importlib.import_module(new)


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
