"""Many parts a day: the planner on Dask distributed (run.py), one part per task (part.py), the summary
(summary.py). No FreeCAD here: each part's planner starts its own headless FreeCAD."""
