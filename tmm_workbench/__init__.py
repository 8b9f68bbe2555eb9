"""TMM: sculptured-surface CAM for FreeCAD (core in `core`, FreeCAD App layer in `app`, GUI in `gui`)."""
__version__ = "0.1.0"
