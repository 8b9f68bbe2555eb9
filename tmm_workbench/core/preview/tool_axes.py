"""The tool axes a 5-axis op's 3D view draws, numpy only: every n-th cutting position as
a line from the tip up its axis, coloured by contact status (two contacts green, one contact orange) or by
tilt (blue vertical -> red at the tilt limit)."""
from __future__ import annotations

from typing import Optional

import numpy as np

COLOURINGS = ("Contact", "Tilt")
CONTACT_RGB = {0: (0.10, 0.70, 0.20), 1: (1.00, 0.55, 0.00), 2: (0.85, 0.00, 0.00)}  # two / one / failed
VERTICAL_RGB, TILTED_RGB = np.array((0.15, 0.35, 1.0)), np.array((1.0, 0.15, 0.10))


def axis_lines(tips: np.ndarray, axes: np.ndarray, every: int, length: float, colouring: str = "Contact",
               status: Optional[np.ndarray] = None, tilt_limit_deg: float = 45.0
               ) -> tuple[np.ndarray, np.ndarray]:
    """(points (2k, 3): tip, tip + length * axis for each drawn position; colours (k, 3) RGB in 0..1) for
    every `every`-th of the (n, 3) tips and unit axes. colouring 'Contact' needs `status` (the kernel's
    0 two, 1 one, 2 failed; without it the tilt is used), 'Tilt' maps 0..tilt_limit_deg blue -> red."""
    if every < 1:
        raise ValueError(f"every must be >= 1, got {every}")
    if colouring not in COLOURINGS:
        raise ValueError(f"colouring must be one of {', '.join(COLOURINGS)}, got {colouring!r}")
    tips, axes = np.asarray(tips, float).reshape(-1, 3), np.asarray(axes, float).reshape(-1, 3)
    idx = np.arange(0, len(tips), int(every))
    t, a = tips[idx], axes[idx]
    points = np.empty((2 * len(idx), 3))
    points[0::2], points[1::2] = t, t + float(length) * a
    if colouring == "Contact" and status is not None:
        s = np.asarray(status)[idx]
        colours = np.array([CONTACT_RGB.get(int(k), CONTACT_RGB[2]) for k in s]).reshape(-1, 3)
    else:
        tilt = np.degrees(np.arccos(np.clip(a[:, 2], -1.0, 1.0)))
        f = np.clip(tilt / max(float(tilt_limit_deg), 1e-9), 0.0, 1.0)[:, None]
        colours = VERTICAL_RGB * (1 - f) + TILTED_RGB * f
    return points, colours


def legend(colouring: str, status_known: bool, tilt_limit_deg: float = 45.0) -> list[tuple[str, tuple]]:
    """(text, RGB) lines telling what the axes' colours of `colouring` mean (without the kernel's status the
    contact colouring falls back to the tilt's, as axis_lines does)."""
    if colouring == "Contact" and status_known:
        return [("tool axes: contact", (0.0, 0.0, 0.0)), ("green: two contacts", CONTACT_RGB[0]),
                ("orange: one contact", CONTACT_RGB[1])]
    return [(f"tool axes: tilt{'' if colouring == 'Tilt' else ' (no contact data)'}", (0.0, 0.0, 0.0)),
            ("blue: vertical", tuple(VERTICAL_RGB)), (f"red: {tilt_limit_deg:g} deg (the limit)", tuple(TILTED_RGB))]
