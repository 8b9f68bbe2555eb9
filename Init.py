# TMM add-on, App start-up (runs in freecadcmd and in the GUI). FreeCAD puts this folder on sys.path,
# so `import tmm_workbench` works from here on.
# FreeCAD 0.20 has no hook for an add-on's post-processors: TMM wraps PathPreferences.searchPathsPost
# so tmm_workbench/app/posts/ is searched too (its posts then show in a Job and load like stock ones).
import FreeCAD

try:
    from tmm_workbench.app import posts as _tmm_posts

    _tmm_posts.install_post_dir()
except Exception as _exc:  # never break FreeCAD's start-up because of the add-on
    FreeCAD.Console.PrintWarning(f"TMM: post-processor folder not registered: {_exc}\n")

try:
    from tmm_workbench.app import compat as _tmm_compat

    _tmm_compat.mend_tool_controller_restore()
except Exception as _exc:  # never break FreeCAD's start-up because of the add-on
    FreeCAD.Console.PrintWarning(f"TMM: tool controllers' restore not mended: {_exc}\n")
