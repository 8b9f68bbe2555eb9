"""Cutter queries on a surface: the exact drop-cutter along -Z (DropSurface) and along any direction."""
