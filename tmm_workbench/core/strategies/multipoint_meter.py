"""Reading the scallop between multipoint 5-axis passes (multipoint_scallop places the passes by it).

The scallop of a pass next to the passes before it is read by cutting the swept tool (the kernel's 5-axis z-map
cut: tip linear, axis by slerp, sub-stepped) into rows of vertical needles laid across the strip between the
two passes, one row every `scallop_row_spacing` along the passes: the largest height above the design surface
on those needles. Needles are `NEEDLE_SPACING` apart, then `FINE_SPACING` around the highest peaks (the cusp is
a sharp ridge). The design height is the face itself (its XY parametrisation inverted by Newton).

On each row the strip runs from where the previous pass touches that row to where the new one does
(`ScallopMeter.row_contact`): a tilted torus touches the face at two points that may lie before and behind the
row (millimetres away on a small or steep face), so the contact band of its positions is not where it cuts the
row. The first strip starts at the first pass's first contact, the last ends at the last pass's last contact.

The rows stay the corner radius inside the passes' ends; `end_rows` are the rows nearer the ends, read apart:
the scallop rises there, and multipoint_scallop holds them where a smaller step can.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional, Sequence

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.footprint.raster import Rect
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.kernel import native

NEEDLE_SPACING = 0.05   # mm, needles across a strip (first reading)
FINE_SPACING = 0.002    # mm, needles around the highest peaks (second reading)
FINE_ROWS = 4           # rows whose peak is read finely
CONTACT_TOL = 1e-3      # mm: a pass touches a row where it comes this close to its nearest approach there
END_INSET = 0.5         # mm: the end rows (ScallopMeter.end_rows) this far inside the footprints' ends
_STOCK_ABOVE = 50.0     # mm: needles start this far above the face's top (an uncut needle reads huge)


@dataclass
class Frame:
    """Across (c) and along (f, the feed direction) unit vectors of the passes, orthonormal, and the boundary's
    extent in them: passes at across a in [a0, a1], advancing in +c from the start edge a0."""
    c: np.ndarray
    f: np.ndarray
    a0: float
    a1: float

    @classmethod
    def of(cls, rect: Rect, feed_angle_deg: float) -> "Frame":
        a = math.radians(feed_angle_deg)
        d = np.array([math.cos(a), math.sin(a)])
        n = np.array([-math.sin(a), math.cos(a)])
        corners = np.array([[rect[0], rect[1]], [rect[2], rect[1]], [rect[2], rect[3]], [rect[0], rect[3]]])
        across = corners @ n
        # start on the side nearest the (xmin, ymin) corner, as raster_lines' FIXED spacing does
        if abs(corners[0] @ n - across.max()) < abs(corners[0] @ n - across.min()):
            n = -n
        across = corners @ n  # (n, d) may be a reflection: the tool, a solid of revolution, is symmetric
        return cls(n, d, float(across.min()), float(across.max()))

    def to_frame(self, p: np.ndarray) -> np.ndarray:
        """(k, 2|3) world points -> frame (across, along[, z])."""
        out = np.array(p, dtype=float, copy=True)
        out[:, 0], out[:, 1] = p[:, :2] @ self.c, p[:, :2] @ self.f
        return out

    def to_world(self, q: np.ndarray) -> np.ndarray:
        out = np.array(q, dtype=float, copy=True)
        out[:, 0] = q[:, 0] * self.c[0] + q[:, 1] * self.f[0]
        out[:, 1] = q[:, 0] * self.c[1] + q[:, 1] * self.f[1]
        return out


class DesignHeights:
    """z of the face above world (x, y) points (NaN off the face): the face's XY map inverted by Newton from
    the nearest of a grid of samples."""

    def __init__(self, face: BezierFace, samples: int = 32) -> None:
        self.face = face
        u0, u1, v0, v1 = face.domain
        U, V = np.meshgrid(np.linspace(u0, u1, samples + 1), np.linspace(v0, v1, samples + 1), indexing="ij")
        self.uv = np.column_stack([U.ravel(), V.ravel()])
        self.xy = face.evaluate(self.uv)["S"][:, :2]
        self.domain = (u0, u1, v0, v1)
        from scipy.spatial import cKDTree

        self.tree = cKDTree(self.xy)   # the nearest sample: the scallop meter asks for millions of points

    def __call__(self, xy: np.ndarray, iterations: int = 12, tol: float = 1e-7) -> np.ndarray:
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        uv = np.empty_like(xy)
        for k in range(0, len(xy), 65536):  # nearest sample, in chunks (cancel stays alive)
            cancel.poll()
            uv[k:k + 65536] = self.uv[self.tree.query(xy[k:k + 65536])[1]]
        u0, u1, v0, v1 = self.domain
        for _ in range(iterations):
            cancel.poll()
            ev = self.face.evaluate(uv)
            r = ev["S"][:, :2] - xy
            a, b, c, d = ev["Su"][:, 0], ev["Sv"][:, 0], ev["Su"][:, 1], ev["Sv"][:, 1]
            det = a * d - b * c
            det = np.where(np.abs(det) < 1e-300, 1e-300, det)
            uv[:, 0] -= (d * r[:, 0] - b * r[:, 1]) / det
            uv[:, 1] -= (-c * r[:, 0] + a * r[:, 1]) / det
            uv[:, 0] = np.clip(uv[:, 0], u0, u1)
            uv[:, 1] = np.clip(uv[:, 1], v0, v1)
        ev = self.face.evaluate(uv)
        z = ev["S"][:, 2].copy()
        z[np.linalg.norm(ev["S"][:, :2] - xy, axis=1) > tol] = np.nan  # off the face (clamped at its edge)
        return z


@dataclass
class PassPositions:
    """One pass positioned: footprint across offset `a`, its footprint points (k, 2) in feed order from the
    pass's start, and the kernel's results for them (a MultipointResults)."""
    a: float
    xy: np.ndarray
    res: Any
    far: frozenset = frozenset()  # rows (row_key) where its strips end at its farther contact (row_contact)
    contacts: dict = field(default_factory=dict, repr=False)  # ScallopMeter.row_contact's, by row

    def good(self, failed: int) -> np.ndarray:
        return self.res["status"] != failed


def _runs(res: Any, failed: int) -> list[np.ndarray]:
    """Row indices of the runs of consecutive good positions."""
    good = res["status"] != failed
    out, run = [], []
    for i, g in enumerate(good):
        if g:
            run.append(i)
        elif run:
            out.append(np.array(run))
            run = []
    if run:
        out.append(np.array(run))
    return out


class ScallopMeter:
    """Reads the scallop between passes: rows of needles across the strip, cut by the kernel's z-map."""

    def __init__(self, face: BezierFace, Ro: float, Ri: float, shape: str, frame: Frame, row_spacing: float,
                 max_step: float, failed: int, threads: int = 0) -> None:
        self.face, self.Ro, self.Ri, self.shape, self.frame = face, Ro, Ri, shape, frame
        self.row_spacing, self.max_step, self.failed, self.threads = row_spacing, max_step, failed, threads
        self.design = DesignHeights(face)
        (_, _, _), (_, _, ztop) = face.bounds
        self.top = float(ztop) + _STOCK_ABOVE
        self.rows_skipped = 0
        self._design_rows: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        reach = Ro + Ri
        self.lattice = np.arange(frame.a0 - reach, frame.a1 + reach + NEEDLE_SPACING, NEEDLE_SPACING)

    def row_positions(self, t_lo: float, t_hi: float) -> np.ndarray:
        """The rows read between t_lo and t_hi: on a fixed lattice (multiples of the row spacing, so the
        design along each is computed once), at least the corner radius Ri inside the passes' ends (nearer
        the ends the placement needs not hold a row: end_rows are read apart)."""
        lo, hi = t_lo + self.Ri, t_hi - self.Ri
        if hi < lo:
            lo = hi = 0.5 * (t_lo + t_hi)
        k0, k1 = math.ceil(lo / self.row_spacing - 1e-9), math.floor(hi / self.row_spacing + 1e-9)
        rows = np.arange(k0, k1 + 1) * self.row_spacing
        return rows if len(rows) else np.array([0.5 * (lo + hi)])

    def end_rows(self, prev: PassPositions, new: PassPositions) -> np.ndarray:
        """The rows row_positions leaves out near the passes' ends: END_INSET inside the ends of their
        footprints and Ri inside the ends of their tips. The scallop rises there: past its last position
        the torus's round front alone cuts (seed 001's convex patch, 0.5 mm asked, 4 mm rows: 0.504 mm 5 mm
        from the end, 0.51 at 1 mm, 0.53 at 0.5 mm)."""
        ends = []
        for p in (prev, new):
            good = p.good(self.failed)
            if not good.any():
                return np.empty(0)
            ends.append((self.frame.to_frame(p.xy[good])[:, 1], self.frame.to_frame(p.res["tip"][good])[:, 1]))
        f_lo, f_hi = max(e[0].min() for e in ends), min(e[0].max() for e in ends)
        t_lo, t_hi = max(e[1].min() for e in ends), min(e[1].max() for e in ends)
        rows = np.array([f_lo + END_INSET, t_lo + self.Ri, t_hi - self.Ri, f_hi - END_INSET])
        return rows if f_hi - f_lo > 2.0 * END_INSET else np.empty(0)

    def design_row(self, t_row: float, xs: np.ndarray) -> np.ndarray:
        """The design height at (across xs, along t_row): the face inverted once per row on needles
        NEEDLE_SPACING apart, interpolated linearly between them (the error, curvature x spacing^2 / 8, is
        2e-6 mm for a 150 mm radius)."""
        key = round(float(t_row), 9)
        if key not in self._design_rows:
            world = self.frame.to_world(np.column_stack([self.lattice, np.full(len(self.lattice), t_row)]))
            self._design_rows[key] = (self.lattice, self.design(world))
        lat, z = self._design_rows[key]
        return np.interp(xs, lat, z, left=np.nan, right=np.nan)

    def _paths(self, passes: list[PassPositions], t_row: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """The good runs of `passes` near the row (frame coordinates), as (tips, axes)."""
        reach = self.Ro + self.Ri + 1e-6
        out = []
        for p in passes:
            tips = self.frame.to_frame(p.res["tip"])
            axes = self.frame.to_frame(p.res["axis"])
            for run in _runs(p.res, self.failed):
                near = run[np.abs(tips[run, 1] - t_row) <= reach + self.row_spacing]
                if len(near) == 0:
                    continue
                lo, hi = max(near[0] - 1, run[0]), min(near[-1] + 1, run[-1])  # the moves into the row too
                idx = np.arange(lo, hi + 1)
                out.append((tips[idx], axes[idx]))
        return out

    def _cut_row(self, paths, t_row: float, x0: float, n: int, cell: float) -> np.ndarray:
        zmap = native.ZMap(x0, t_row - 0.5 * cell, cell, n, 1, self.top)
        for tips, axes in paths:
            kinds = np.zeros(max(len(tips) - 1, 0), dtype=np.uint8)
            native.cut_5axis(zmap, self.Ro, self.Ri, self.shape, np.ascontiguousarray(tips),
                             np.ascontiguousarray(axes), kinds, self.max_step, 1e9, self.threads)
        return np.array(zmap.heights).reshape(-1)

    def _deviation(self, paths, t_row: float, x0: float, n: int, cell: float) -> tuple[np.ndarray, np.ndarray]:
        xs = x0 + (np.arange(n) + 0.5) * cell
        z = self._cut_row(paths, t_row, x0, n, cell)
        return xs, z - self.design_row(t_row, xs)

    def _contact_band(self, p: PassPositions) -> np.ndarray:
        """(k, 3) per position: its first contact's across coordinate, the along coordinate of its tip, its
        last contact's across coordinate (P and Q; P alone with one contact): what the pass cuts lies
        between them, the scallop between the bands of two passes."""
        P = self.frame.to_frame(p.res["P"])
        Q = self.frame.to_frame(p.res["Q"])
        qa = np.where(np.isfinite(Q[:, 0]), Q[:, 0], P[:, 0])
        tips = self.frame.to_frame(p.res["tip"])
        return np.column_stack([np.minimum(P[:, 0], qa), tips[:, 1], np.maximum(P[:, 0], qa)])

    def row_contact(self, p: PassPositions, t_row: float) -> float:
        """Where pass `p` alone touches the row: the first needle (from the start edge) within CONTACT_TOL of
        its nearest approach to the face there, the last on the rows in `p.far` (NaN where it does not cut
        the row). Not its positions' contact band: a tilted tool touches before and behind the row (on a small
        or steep face millimetres away) and cuts the row elsewhere, so the strips between passes run from one
        such needle to the next. From the first, what a pass leaves between two contacts on the row is
        measured with the passes after it, which cut there; from the last (the placement's choice where they
        do not), with the passes before it."""
        key = row_key(t_row)
        if key not in p.contacts:
            p.contacts[key] = math.nan
            paths = self._paths([p], t_row)
            if paths:
                across = np.concatenate([tips[:, 0] for tips, _ in paths])
                reach = self.Ro + self.Ri
                x0, width = float(across.min()) - reach, float(across.max() - across.min()) + 2.0 * reach
                n = max(2, int(math.ceil(width / NEEDLE_SPACING)))
                xs, dev = self._deviation(paths, t_row, x0, n, width / n)
                ok = np.isfinite(dev)
                if ok.any():
                    touch = xs[ok][dev[ok] <= dev[ok].min() + CONTACT_TOL]
                    p.contacts[key] = float(touch.max() if key in p.far else touch.min())
        return p.contacts[key]

    def scallop(self, before: list[PassPositions], prev: PassPositions, new: PassPositions,
                exclude: Sequence[tuple[float, float]] = (), at: Optional[np.ndarray] = None) -> float:
        """The largest height above the face left on the strip between `prev` and `new` (module docstring),
        the passes in `before` cut too (inf where a needle between them is not cut at all), on the rows
        outside the `exclude` intervals of the along coordinate (on the rows `at` instead of
        row_positions' if given). `self.rows` keeps each row's value,
        `self.spans` its strip and highest needle, `self.peak` where the highest is."""
        self.rows, self.spans = {}, {}
        tp, tn = self._contact_band(prev), self._contact_band(new)
        gp, gn = prev.good(self.failed), new.good(self.failed)
        gp &= np.isfinite(tp[:, 0])
        gn &= np.isfinite(tn[:, 0])
        if not gp.any() or not gn.any():
            return math.inf
        t_lo = max(tp[gp, 1].min(), tn[gn, 1].min())
        t_hi = min(tp[gp, 1].max(), tn[gn, 1].max())
        if t_hi <= t_lo:
            return math.inf
        rows = self.row_positions(t_lo, t_hi) if at is None else at
        passes = before + [prev, new]
        first, last = prev.a <= self.frame.a0 + 1e-9, new.a >= self.frame.a1 - 1e-9
        gap = 2.0 * self.row_spacing + 1e-9  # a row farther than this from a good position is not measured
        coarse = []
        for t_row in rows:
            cancel.poll()
            if any(lo <= t_row <= hi for lo, hi in exclude):
                continue
            near_p = gp & (np.abs(tp[:, 1] - t_row) <= gap)
            near_n = gn & (np.abs(tn[:, 1] - t_row) <= gap)
            if not near_p.any() or not near_n.any():
                self.rows_skipped += 1
                continue
            # the strip: from where the previous pass touches the row to where the new one does; the first
            # strip from the first pass's first contact on, the last to the last pass's last contact
            a_lo, a_hi = self.row_contact(prev, t_row), self.row_contact(new, t_row)
            if first or math.isnan(a_lo):
                a_lo = float(np.fmin(a_lo, np.interp(t_row, *_sorted(tp[gp, 1], tp[gp, 0]))))
            if last or math.isnan(a_hi):
                a_hi = float(np.fmax(a_hi, np.interp(t_row, *_sorted(tn[gn, 1], tn[gn, 2]))))
            if a_hi <= a_lo:
                continue
            n = max(2, int(math.ceil((a_hi - a_lo) / NEEDLE_SPACING)))
            cell = (a_hi - a_lo) / n
            paths = self._paths(passes, t_row)
            xs, dev = self._deviation(paths, t_row, a_lo, n, cell)
            ok = np.isfinite(dev)
            if not ok.any():
                continue
            i = int(np.flatnonzero(ok)[np.argmax(dev[ok])])
            coarse.append((float(dev[i]), float(t_row), float(xs[i]), paths, a_lo, a_hi))
            self.rows[float(t_row)] = float(dev[i])
            self.spans[float(t_row)] = (a_lo, a_hi, float(xs[i]))
        if not coarse:
            return 0.0
        coarse.sort(key=lambda r: -r[0])
        best = coarse[0][0]
        self.peak = (coarse[0][2], coarse[0][1])
        for dev0, t_row, x_peak, paths, a_lo, a_hi in coarse[:FINE_ROWS]:
            if not math.isfinite(dev0):
                return math.inf
            # inside the strip only: past its ends lie the new pass's own band and the previous strips
            lo, hi = max(a_lo, x_peak - NEEDLE_SPACING), min(a_hi, x_peak + NEEDLE_SPACING)
            n = max(2, int(math.ceil((hi - lo) / FINE_SPACING)))
            xs, dev = self._deviation(paths, t_row, lo, n, (hi - lo) / n)
            ok = np.isfinite(dev)
            if ok.any() and float(dev[ok].max()) > self.rows[t_row]:
                self.rows[t_row] = float(dev[ok].max())
                self.spans[t_row] = (a_lo, a_hi, float(xs[ok][np.argmax(dev[ok])]))
            if ok.any() and float(dev[ok].max()) > best:
                best = float(dev[ok].max())
                self.peak = (float(xs[ok][np.argmax(dev[ok])]), t_row)
        return best

    peak: tuple = (math.nan, math.nan)  # (across, along) in the frame of the last scallop's highest needle
    rows: dict = {}   # the last scallop's value per row (along coordinate)
    spans: dict = {}  # and per row: the strip's (across from, across to, across of its highest needle)


def _sorted(t: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(t)
    return t[order], a[order]


def row_key(t_row: float) -> float:
    """A row's along coordinate as a set key (rows lie on a fixed lattice)."""
    return round(float(t_row), 6)
