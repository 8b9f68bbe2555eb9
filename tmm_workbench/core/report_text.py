"""Pieces of the messages the core and the ops write, said one way everywhere."""
from __future__ import annotations

import numpy as np


def _mm(v: float) -> str:
    """A coordinate in mm: four significant digits (a part's size to a tenth of a mm), whole mm beyond 10 m."""
    return f"{v:.4g}" if abs(v) < 1e4 else f"{v:.0f}"


def within(points) -> str:
    """'within x a..b, y c..d mm': the XY extent of `points` ((k, >= 2), or the corners of a box (x0, y0, x1, y1)
    given as [[x0, y0], [x1, y1]]), where a message says its places lie."""
    xy = np.asarray(points, dtype=float).reshape(-1, np.shape(points)[-1])[:, :2]
    (x0, y0), (x1, y1) = xy.min(0), xy.max(0)
    return f"within x {_mm(x0)}..{_mm(x1)}, y {_mm(y0)}..{_mm(y1)} mm"
