"""Footprints: where the cutter goes in XY before it is positioned (raster passes; contour, spiral and z-levels come next)."""
