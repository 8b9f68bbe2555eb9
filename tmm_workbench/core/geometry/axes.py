"""Tool axes: the one interpolation between two unit axes that the verification, the posts and the
machine model share."""
from __future__ import annotations

import math

import numpy as np


def slerp(a0: np.ndarray, a1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Unit axes (m, 3) between unit a0 and a1 at the fractions s (m,): constant angular rate about a0 x a1;
    a0 itself (normalised) when the two are closer than 1e-9 rad."""
    a0 = np.asarray(a0, dtype=float)
    a1 = np.asarray(a1, dtype=float)
    s = np.asarray(s, dtype=float).reshape(-1, 1)
    th = math.acos(float(np.clip(np.dot(a0, a1), -1.0, 1.0)))
    if th < 1e-9:
        return np.repeat(a0[None, :] / np.linalg.norm(a0), len(s), axis=0)
    v = (np.sin((1.0 - s) * th) * a0 + np.sin(s * th) * a1) / math.sin(th)
    return v / np.linalg.norm(v, axis=1, keepdims=True)
