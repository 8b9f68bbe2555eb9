"""Tool axes: the one interpolation between two unit axes that the verification, the posts and the
machine model share."""
from __future__ import annotations

import numpy as np


def slerp(a0: np.ndarray, a1: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Unit axes (m, 3) between unit a0 and a1 at the fractions s (m,): constant angular rate about a0 x a1;
    a0 itself (normalised) when the two are closer than 1e-9 rad. a0 and a1 may also be (m, 3): row k between
    a0[k] and a1[k] at s[k]."""
    a0 = np.asarray(a0, dtype=float)
    a1 = np.asarray(a1, dtype=float)
    s = np.asarray(s, dtype=float).reshape(-1, 1)
    th = np.arccos(np.clip(np.sum(a0 * a1, axis=-1), -1.0, 1.0))[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        v = (np.sin((1.0 - s) * th) * a0 + np.sin(s * th) * a1) / np.sin(th)
    v = np.where(th >= 1e-9, v, np.broadcast_to(a0, v.shape))
    return v / np.linalg.norm(v, axis=1, keepdims=True)
