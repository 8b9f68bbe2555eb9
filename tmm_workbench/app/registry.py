"""The one op registry: every TMM operation, in toolbar order. The workbench's toolbar and menu, the view
providers, the GUI pages and the headless API iterate it; adding a strategy adds one entry here (see
docs/design.md, "Adding a strategy").

Modules are named, not imported: the App layer never imports Gui code, and nothing here needs the kernel,
so the registry loads on any machine (documents with TMM objects restore without the kernel).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Optional


@dataclass(frozen=True)
class OpEntry:
    name: str          # the op's type name (OP_NAME), its command "Path_<name>" (0.20) / "CAM_<name>" (1.x)
    menu_text: str     # toolbar / menu text
    tooltip: str
    icon: str          # resources/icons/<icon>.svg
    app_module: str    # proxy class, Create(), SetupProperties()
    gui_module: str    # task panel page, view provider, Command, attach_view_provider()
    view_kind: str     # app.hooks kind under which App code asks for the view provider
    strategy: str      # the core strategy module (params dataclass, compute, SUPPORTED_TOOLS)

    @property
    def command_name(self) -> str:
        from tmm_workbench.app.compat import command_prefix

        return command_prefix() + self.name

    def app(self) -> ModuleType:
        return importlib.import_module(self.app_module)

    def gui(self) -> ModuleType:
        return importlib.import_module(self.gui_module)

    def core(self) -> ModuleType:
        return importlib.import_module(self.strategy)


OPS: tuple[OpEntry, ...] = (
    OpEntry("TMM_Surface", "TMM 3-axis Surface",
            "3-axis raster finishing of a mesh or a Part model (drop-cutter, TMM kernel)", "TMM_Surface",
            "tmm_workbench.app.op_surface", "tmm_workbench.gui.op_surface_gui", "op",
            "tmm_workbench.core.strategies.raster_drop"),
    OpEntry("TMM_Multipoint", "TMM 5-axis Multipoint",
            "5-axis finishing of a Bézier or B-spline face with a toroidal cutter by multipoint positioning "
            "(select the face first)", "TMM_Multipoint",
            "tmm_workbench.app.op_multipoint", "tmm_workbench.gui.op_multipoint_gui", "multipoint_op",
            "tmm_workbench.core.strategies.multipoint"),
    OpEntry("TMM_Roughing", "TMM Roughing",
            "Z-level roughing of the Job's stock down to a mesh or Part model plus stock to leave (offset or "
            "zig-zag clearing, helix or ramp entries)", "TMM_Roughing",
            "tmm_workbench.app.op_roughing", "tmm_workbench.gui.op_roughing_gui", "roughing_op",
            "tmm_workbench.core.strategies.zlevel_rough"),
    OpEntry("TMM_Waterline", "TMM Waterline",
            "Waterline finishing of a mesh or Part model: closed loops at constant heights for steep walls",
            "TMM_Waterline",
            "tmm_workbench.app.op_waterline", "tmm_workbench.gui.op_waterline_gui", "waterline_op",
            "tmm_workbench.core.strategies.waterline"),
    OpEntry("TMM_Mesh5", "TMM 5-axis Mesh",
            "5-axis finishing of a mesh or a Part model with a tilted flat end mill or bull-nose by the 3D C-space "
            "(seed 000): adaptive passes within the tolerance, postures for the Tarus motion time", "TMM_Mesh5",
            "tmm_workbench.app.op_mesh5", "tmm_workbench.gui.op_mesh5_gui", "mesh5_op",
            "tmm_workbench.core.strategies.mesh5.finish"),
)


def entry(name: str) -> OpEntry:
    for e in OPS:
        if e.name == name:
            return e
    raise KeyError(f"no TMM operation '{name}' (known: {', '.join(e.name for e in OPS)})")


def user_name(name: str) -> str:
    """An op type's name in the user's words, for new ops' labels and undo steps ("TMM Surface")."""
    return name.replace("_", " ")


def create(name: str, job: Any, values: Optional[dict[str, Any]] = None) -> Any:
    """A new op of type `name` in `job` with property `values` (headless API, macros)."""
    module = entry(name).app()
    return module.Create(name, parentJob=job, values=values)
