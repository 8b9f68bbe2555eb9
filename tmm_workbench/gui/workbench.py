"""The TMM workbench: TMM's commands beside FreeCAD's Path Job tools, so a whole job (Job, tool
bits, op, simulation, post) is done without switching workbenches."""
from __future__ import annotations

import FreeCADGui

from tmm_workbench.gui import resources

from tmm_workbench.app.compat import command_prefix

# FreeCAD's own commands, without their prefix (Path_ on 0.20, CAM_ from 1.0)
JOB_TOOLS = ["Job", "Post", "Inspect", "Simulator"]
# the toolbar offers what works with a mesh Job (post, inspect, the tool bits); in the menu only: FreeCAD's Job
# (it offers only solids as its model: an empty list for an imported STL; TMM's Job from mesh / STL is the toolbar's
# first button) and FreeCAD's Simulator (it cuts the stock with X, Y, Z alone, so a 5-axis op's moves show wrong,
# and measures nothing against the mesh: TMM Simulate does both)
MENU_ONLY = ("Job", "Simulator")
JOB_TOOLBAR = [t for t in JOB_TOOLS if t not in MENU_ONLY]
TOOL_TOOLS = ["ToolBitLibraryOpen", "ToolBitDock", "ToolBitCreate", "ToolBitLoad", "ToolController"]


def path_commands(names: list[str]) -> list[str]:
    return [command_prefix() + n for n in names]


class TMMWorkbench(FreeCADGui.Workbench):
    MenuText = "TMM"
    ToolTip = "Sculptured-surface CAM (TMM kernel) with FreeCAD's Path Jobs"
    Icon = resources.icon("TMM_Workbench")

    def Initialize(self) -> None:
        from tmm_workbench.app.compat import import_gui
        from tmm_workbench.app import posts

        import PathGui  # noqa: F401 (loads Path's icons and panels into Qt resources)
        FreeCADGui.addIconPath(":/icons")
        import_gui("gui_init").Startup()  # registers the Path commands (ops, inspect, simulator, ...)
        import_gui("job_cmd")
        import_gui("tool_bit_cmd")
        import_gui("tool_bit_library_cmd")
        import_gui("commands")
        from tmm_workbench.app import registry
        from tmm_workbench.gui import auto_cmd, job_cmd, simulate_cmd, stick_out_cmd

        posts.install_post_dir()
        from tmm_workbench.core import kernel

        try:
            kernel.require()
        except kernel.KernelMissing as exc:  # the workbench works; computing needs the kernel
            import FreeCAD

            FreeCAD.Console.PrintWarning(f"TMM: {exc}\n")
        for entry in registry.OPS:
            entry.gui()  # registers the op's command
        tmm = ([job_cmd.COMMAND_NAME] + [entry.command_name for entry in registry.OPS]
               + [simulate_cmd.COMMAND_NAME, stick_out_cmd.COMMAND_NAME, auto_cmd.COMMAND_NAME])
        self.appendToolbar("TMM", tmm)
        job_tools, tool_tools = path_commands(JOB_TOOLS), path_commands(TOOL_TOOLS)
        self.appendToolbar("TMM Path", path_commands(JOB_TOOLBAR))
        self.appendToolbar("TMM Tools", tool_tools)
        self.appendMenu("&TMM", tmm + ["Separator"] + job_tools + ["Separator"] + tool_tools)

    def Activated(self) -> None:
        pass

    def Deactivated(self) -> None:
        pass

    def ContextMenu(self, recipient: str) -> None:
        sel = FreeCADGui.Selection.getSelection()
        if len(sel) == 1 and sel[0].isDerivedFrom("Path::Feature"):
            self.appendContextMenu("", ["Separator", command_prefix() + "Inspect"])

    def GetClassName(self) -> str:
        return "Gui::PythonWorkbench"
