"""TMM's operations inside FreeCAD's own CAM workbench (1.0 and later), so users need not switch
workbenches: a workbench manipulator (FreeCADGui.addWorkbenchManipulator, FreeCAD's documented way for an
add-on to add commands to another workbench) appends TMM's commands to the CAM workbench's "New
Operations" toolbar when that workbench is set up. Its commands are registered on first use (the CAM
workbench has loaded Path's Gui modules by then)."""
from __future__ import annotations

from typing import Any

import FreeCADGui

CAM_WORKBENCH = "CAMWorkbench"
CAM_TOOLBAR = "New Operations"


def tmm_commands() -> list[str]:
    """TMM's command names, registering them first (the TMM workbench does the same on Initialize)."""
    from tmm_workbench.app import registry
    from tmm_workbench.gui import job_cmd, simulate_cmd

    for entry in registry.OPS:
        entry.gui()
    return [job_cmd.COMMAND_NAME] + [entry.command_name for entry in registry.OPS] + [simulate_cmd.COMMAND_NAME]


def active_workbench_name() -> str:
    """The active workbench's name. FreeCAD 1.x asks manipulators while a workbench is being set up, before
    its Python object has its `__Workbench__` (name() then raises AttributeError): its class name is its name."""
    wb = FreeCADGui.activeWorkbench()
    if wb is None:
        return ""
    try:
        return wb.name()
    except AttributeError:
        return type(wb).__name__


class CamManipulator:
    def modifyToolBars(self) -> list[dict[str, Any]]:
        if active_workbench_name() != CAM_WORKBENCH:
            return []
        try:
            commands = tmm_commands()
        except Exception as exc:  # the CAM workbench must come up whatever happens to TMM
            import FreeCAD

            FreeCAD.Console.PrintWarning(f"TMM: operations not added to the CAM workbench: {exc}\n")
            return []
        return [{"append": name, "toolBar": CAM_TOOLBAR} for name in commands]


_manipulator = CamManipulator()


def install() -> bool:
    """Adds the manipulator once (FreeCAD 1.0 and later); False where FreeCAD has no manipulators (0.20)."""
    if not hasattr(FreeCADGui, "addWorkbenchManipulator"):
        return False
    if not getattr(FreeCADGui, "_tmm_cam_manipulator", None):
        FreeCADGui.addWorkbenchManipulator(_manipulator)
        FreeCADGui._tmm_cam_manipulator = _manipulator
    return True
