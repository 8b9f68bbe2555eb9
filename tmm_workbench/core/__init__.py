"""Pure-Python core of TMM: no FreeCAD import anywhere below this package."""
