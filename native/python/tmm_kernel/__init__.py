"""TMM's geometry kernel as a Python package (built by `pip install ./native`): the compiled module
`tmm_kernel._native`, the same one the add-on builds in place as `tmm_workbench._native`. The FreeCAD add-on
(tmm_workbench) imports whichever is present (tmm_workbench/core/kernel.py)."""
