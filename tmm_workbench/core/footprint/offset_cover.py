"""Ridge points of the 3D offset's arrival field covered (core.footprint.offset_field): where fronts meet (a corner's
bisector, a strip's middle, a hilltop, a valley of T across a slope) a point between two passes may lie more than half
a local step from both; the levels between the passes are checked on T's ridges against the passes as cut, and the
uncovered runs are cut too (field_loops cuts them at the level below)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

_RIDGE_DEG = 45.0        # a half-level point lies on a ridge of T where grad T turns by more than this across
                         # _RIDGE_CELLS either side (a corner's bisector, fronts meeting, a hilltop)
_RIDGE_CELLS = 1.5
_COVER_SLACK = 1.04      # a ridge point is uncovered beyond this x half the aimed step (on a plane: a cusp of
                         # 0.92 x 1.04^2 = 0.995 x the tolerance)
_COVER_SLOPE = 10.0      # deg: ridge points checked on CL slopes up to this (corners on flats, hilltops); on a
                         # relief the check flagged a thousand short pieces that barely moved the simulated cusp
COVER_LEVELS = (0.5, 0.25, 0.75)   # the levels between two passes (k - these) whose ridge points are checked: the
                         # point farthest from both passes where fronts meet lies anywhere between them (a random
                         # field's 24 deg valley of T at T = k + 0.76: 0.0166 mm for 0.01 with the half level only);
                         # the quarter levels only at meet points (and contoured only where meet_nodes has some)
_MEET_SLOPE = 30.0       # deg: ridge points also checked on slopes up to this where fronts meet nearly head on (grad T
_MEET_DEG = 120.0        # turns by more than this); at 90 deg or 60 deg of slope mount_rush got 250-600 more loops
_MEET_SLACK = 1.04       # ... uncovered beyond this x half the aimed step there
_COVER_RUN = 0.25        # flat steps added at either end of an uncovered run of the half level (_uncovered)


def _ridge(field: Any, p: np.ndarray, turn_deg: float = _RIDGE_DEG) -> np.ndarray:
    """(n,) bool: the points where grad T turns by more than `turn_deg` across _RIDGE_CELLS cells either side,
    along X or Y (two fronts meet there: a corner's bisector, a strip's middle, a hilltop)."""
    h = _RIDGE_CELLS * (field.xs[1] - field.xs[0])
    out = np.zeros(len(p), dtype=bool)
    for d in (np.array([h, 0.0]), np.array([0.0, h])):
        ga, gb = field.gradient(p + d), field.gradient(p - d)
        with np.errstate(invalid="ignore", divide="ignore"):
            c = (ga * gb).sum(axis=1) / (np.hypot(*ga.T) * np.hypot(*gb.T))
        out |= ~(c >= math.cos(math.radians(turn_deg)))   # NaN (beside unreached nodes): a ridge too
    return out


def _step_across(field: Any, p: np.ndarray, passes: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(n,) each point's XY distance to the nearest pass, and the speed's step (mm) there for a front crossing
    along that distance's direction (the gap the point lies in; on a ridge grad T itself is smeared, along the
    bisector), the slope and curvature over that distance (the CL surface between the point and the pass, not
    half a flat step that may reach a slope's foot beyond it)."""
    from tmm_workbench.core.footprint.offset3d import _gaps

    gap, seg = _gaps(p, passes)
    a = np.vstack([q[:-1] for q in passes])[seg]
    ab = np.vstack([q[1:] for q in passes])[seg] - a
    t = np.clip(((p - a) * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
    u = a + t[:, None] * ab - p
    u[np.hypot(*u.T) <= 1e-12] = (1.0, 0.0)
    probe = max(float(np.median(gap)) if len(gap) else 0.0, 2 * (field.xs[1] - field.xs[0]))
    return gap, np.maximum(field.steps(p, u, probe), field.steps(p, u, field.probe))


def meet_nodes(field: Any) -> np.ndarray:
    """(ny, nx) bool: the nodes where fronts may meet head on across a slope (uncovered's meet points, read more
    widely: grad T turning by more than 0.8 x _MEET_DEG two cells either side, slopes up to _MEET_SLOPE)."""
    t = np.where(np.isfinite(field.t), field.t, np.nan)
    gy, gx = np.gradient(t)
    out = np.zeros(t.shape, dtype=bool)
    for axis in (0, 1):
        a = [np.roll(g, 2, axis=axis) for g in (gx, gy)]
        b = [np.roll(g, -2, axis=axis) for g in (gx, gy)]
        with np.errstate(invalid="ignore", divide="ignore"):
            c = (a[0] * b[0] + a[1] * b[1]) / (np.hypot(*a) * np.hypot(*b))
            out |= c < math.cos(math.radians(0.8 * _MEET_DEG))
    if field.slope is not None:
        out &= (field.slope > _COVER_SLOPE) & (field.slope <= _MEET_SLOPE)
    return out


def uncovered(field: Any, level: float, passes: list[np.ndarray], flat: float,
               meet_only: bool = False) -> list[np.ndarray]:
    """The pieces of the half level {T = level} whose points on a ridge of T lie farther than half the local step
    from every pass in `passes` (the two levels either side as cut: spikes and caps included): a corner whose
    contour was too irregular to rebuild and spike (a bisector meeting a slope's foot), the corners of a
    hilltop's last small loop, a short cap left out. Each uncovered run, _COVER_RUN flat steps longer at either
    end, is cut too: every point there then lies within half a step of a pass, which is the cusp rule itself."""
    if field.steps is None or not passes:
        return []
    out = []
    for line in field.lines(level):
        ridge = _ridge(field, line)
        slack = np.full(len(line), _COVER_SLACK)
        if field.slope is not None:   # (on steeper ground the XY distance misjudges the cusp: see _COVER_SLOPE)
            with np.errstate(invalid="ignore"):
                slope = field.at(line, field.slope)
                meet = (slope > _COVER_SLOPE) & (slope <= _MEET_SLOPE) & _ridge(field, line, _MEET_DEG)
            ridge &= meet if meet_only else (slope <= _COVER_SLOPE) | meet
            slack[meet] = _MEET_SLACK
        if not ridge.any():
            continue
        idx = np.flatnonzero(ridge)
        gap, step = _step_across(field, line[idx], passes)
        bad = np.zeros(len(line), dtype=bool)
        bad[idx] = gap > 0.5 * slack[idx] * step
        if not bad.any():
            continue
        closed = len(line) > 3 and np.allclose(line[0], line[-1])
        s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(line, axis=0).T))])
        reach = _COVER_RUN * flat
        if closed:   # arc length around the loop: runs may wrap
            total = s[-1]
            grow = np.zeros(len(line), dtype=bool)
            for i in np.flatnonzero(bad):
                d = np.abs(s - s[i])
                grow |= np.minimum(d, total - d) <= reach
            if grow.all():
                out.append(line)
                continue
            first = int(np.flatnonzero(~grow)[0])
            body, flag = np.roll(line[:-1], -first, axis=0), np.roll(grow[:-1], -first)
        else:
            grow = np.zeros(len(line), dtype=bool)
            for i in np.flatnonzero(bad):
                grow |= np.abs(s - s[i]) <= reach
            body, flag = line, grow
        edges = np.flatnonzero(np.diff(np.concatenate([[0], flag.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2]):
            lo, hi = max(a - 1, 0), min(b + 1, len(body))
            if hi - lo >= 2:
                out.append(body[lo:hi])
    return out
