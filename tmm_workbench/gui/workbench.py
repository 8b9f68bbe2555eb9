"""The TMM workbench: TMM's commands beside FreeCAD's Path Job tools, so a whole job (Job, tool
bits, op, simulation, post) is done without switching workbenches."""
from __future__ import annotations

import FreeCADGui

from tmm_workbench.gui import resources

PATH_JOB_TOOLS = ["Path_Job", "Path_Post", "Path_Inspect", "Path_Simulator"]
PATH_TOOL_TOOLS = ["Path_ToolBitLibraryOpen", "Path_ToolBitDock", "Path_ToolBitCreate", "Path_ToolBitLoad",
                   "Path_ToolController"]


class TMMWorkbench(FreeCADGui.Workbench):
    MenuText = "TMM"
    ToolTip = "Sculptured-surface CAM (TMM kernel) with FreeCAD's Path Jobs"
    Icon = resources.icon("TMM_Workbench")

    def Initialize(self) -> None:
        from tmm_workbench.app.compat import import_gui
        from tmm_workbench.app import posts

        import PathGui  # noqa: F401  (loads Path's icons and panels into Qt resources)
        FreeCADGui.addIconPath(":/icons")
        import_gui("gui_init").Startup()  # registers the Path commands (ops, inspect, simulator, ...)
        import_gui("job_cmd")
        import_gui("tool_bit_cmd")
        import_gui("tool_bit_library_cmd")
        import_gui("commands")
        from tmm_workbench.app import registry
        from tmm_workbench.gui import job_cmd

        posts.install_post_dir()
        for entry in registry.OPS:
            entry.gui()  # registers the op's command
        tmm = [job_cmd.COMMAND_NAME] + [entry.command_name for entry in registry.OPS]
        self.appendToolbar("TMM", tmm)
        self.appendToolbar("TMM Path", PATH_JOB_TOOLS)
        self.appendToolbar("TMM Tools", PATH_TOOL_TOOLS)
        self.appendMenu("&TMM", tmm + ["Separator"] + PATH_JOB_TOOLS + ["Separator"] + PATH_TOOL_TOOLS)

    def Activated(self) -> None:
        pass

    def Deactivated(self) -> None:
        pass

    def ContextMenu(self, recipient: str) -> None:
        sel = FreeCADGui.Selection.getSelection()
        if len(sel) == 1 and sel[0].isDerivedFrom("Path::Feature"):
            self.appendContextMenu("", ["Separator", "Path_Inspect"])

    def GetClassName(self) -> str:
        return "Gui::PythonWorkbench"
