"""An axis-aligned rectangle in XY, the type footprints, faces and measurements share."""
from __future__ import annotations

Rect = tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
