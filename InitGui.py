# TMM add-on, GUI start-up: registers the TMM workbench (tmm_workbench/gui/workbench.py) and the hooks
# that give Jobs and ops made from Python their view providers and TMM computations a progress dialog
# (tmm_workbench/gui/startup.py; Gui modules are imported on first use, not here).
import FreeCAD
import FreeCADGui

try:
    from tmm_workbench.app.compat import support_problem

    _problem = support_problem()
    if _problem:  # an unsupported FreeCAD: one clear line, no workbench, no traceback later in a command
        FreeCAD.Console.PrintError(f"TMM: workbench not loaded: {_problem}\n")
    else:
        from tmm_workbench.gui.startup import install_hooks
        from tmm_workbench.gui.workbench import TMMWorkbench

        FreeCADGui.addWorkbench(TMMWorkbench())
        install_hooks()
except Exception as _exc:  # a broken add-on must not break FreeCAD's start-up
    FreeCAD.Console.PrintError(f"TMM: workbench not loaded: {_exc}\n")
