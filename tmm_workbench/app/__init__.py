"""TMM's FreeCAD App layer: imports FreeCAD and Path, never FreeCADGui, PySide or Gui modules.

geometry (FreeCAD objects -> core meshes), tools (ToolBits -> cutters), model_proxy (stand-in solids
for meshes in a Job), op_surface (the Path operation), job (Job glue), posts, progress, api (macros).
"""
