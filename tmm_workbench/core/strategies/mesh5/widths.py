"""How wide a strip the tilted tool finishes at a CC point (the adaptive step-over's measure: stepover).

Half-widths. At each CC point, the posture's effective cutting profile (the tool swept along the feed LX,
seen in the LY-LZ plane: top_bound.lower_profile, lifted by delta along the axis) stands over the surface's
cross-section S(y) (the mesh's height along LZ at LX = 0, LY = y); the remaining height is their difference.
The left (+LY) half-width is the largest d with the remaining height <= the tolerance on all of [0, d], the
right one the same on [-d, 0] (the seed's eq. 3.29-3.32 for one rim point of the flat end mill, here the
whole profile, for the bull-nose too). Where the mesh ends first, that side is covered to the edge (inf) when
the tool is there beyond the last section sample on the mesh too; else it ends at that sample.

The curving pass. The profile at lateral y is formed by the tool's point that lies x(y) along the feed from
the CC point (behind it for a forward tilt, up to R cos(lambda)): the section is swept there by the tool
when it has gone -x further along the pass. Straight, that tool is the same one moved along LX; along a
pass that bends (the normal turning along the feed by kappa per mm, LX turning within the tangent plane by
kappa_g, LY turning about LX by the twist t) it stands, in the CC point's LCS and to second order in x,
raised by kappa x^2 / 2 - t x y (bent_profile; a raise below 0 not taken: the tool that would sweep lower is
lifted clear there by its own C-space; moved across by -kappa_g x^2 / 2 + t x z too, not taken), and its flat
bottom's lowest raised point along its chord can lie nearer the CC point than the profile's (bottom_low). Where the
posture turns between CC points it is not counted (the widest postures are chosen before it is known). A bend
of 1/40 mm along the feed raises a flat end's flank at 0.7 R by 0.045 mm at lambda 3 deg, of a 0.1 mm
tolerance: the straight profile read the finished strip too wide there.
"""
from __future__ import annotations

from typing import List, Optional

import numpy as np

from tmm_workbench.core.strategies.mesh5.cc_paths import CCPath
from tmm_workbench.core.strategies.mesh5.cspace import CSpace
from tmm_workbench.core.strategies.mesh5.lift import MeshReach
from tmm_workbench.core.strategies.mesh5.posture import require_plain, tool_rotation, touch_tip
from tmm_workbench.core.strategies.mesh5.top_bound import lower_profile, surface_heights
from tmm_workbench.core.tools.cutter import Cutter

WIDTH_SAMPLES = 97      # lateral samples per side out to 2 R (the section is linear between them)


def _neighbours(paths: List[CCPath]) -> tuple[np.ndarray, np.ndarray]:
    """(n,) each CC point's neighbours before and after along its own path (itself at an end), all paths in
    order."""
    i0, i1, start = [], [], 0
    for p in paths:
        k = np.arange(len(p))
        i0.append(start + np.maximum(k - 1, 0))
        i1.append(start + np.minimum(k + 1, len(p) - 1))
        start += len(p)
    return np.concatenate(i0), np.concatenate(i1)


def path_bending(paths: List[CCPath]) -> np.ndarray:
    """(n, 5) per CC point (all paths in order): per mm along the pass kappa (the normal LZ turning towards
    LX: convex along the feed > 0), kappa_g (LX turning towards LY) and the twist t (LY turning towards LZ),
    from its neighbours' frames (central differences; one-sided at the ends, 0 on a single point); and the
    mm along the path to its last and to its first CC point (beyond them the tool goes on straight along
    LX, the overrun, or not at all)."""
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    i0, i1 = _neighbours(paths)
    ds = np.linalg.norm(pts[i1] - pts[i0], axis=1)
    inv = np.where(ds > 1e-9, 1.0 / np.maximum(ds, 1e-9), 0.0)
    d = frm[i1] - frm[i0]
    dot = lambda u, v: np.einsum("ij,ij->i", u, v)  # noqa: E731
    rates = np.column_stack([dot(d[:, 2], frm[:, 0]), dot(d[:, 0], frm[:, 1]), dot(d[:, 1], frm[:, 2])])
    along = []
    for p in paths:
        s = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p.points, axis=0), axis=1))]
        along.append(np.column_stack([s[-1] - s, s]))
    return np.column_stack([rates * inv[:, None], np.concatenate(along)])


def _within_path(px: np.ndarray, bend: np.ndarray) -> np.ndarray:
    """The lead px (..., S) of the profile's points kept to the path: the tool that forms a point at px has
    gone -px along the pass, at most to its end (ahead, px < 0) or back to its start."""
    return np.clip(px, -bend[..., 3:4], bend[..., 4:5])


def raise_of(px: np.ndarray, py: np.ndarray, bend: np.ndarray) -> np.ndarray:
    """How much higher than straight the tool's point at (px, py) (LX, LY; (..., S)) sweeps the section on a
    pass bending by `bend` (..., 5): kappa x^2 / 2 - t x y (x within the path), never less than 0 (the tool
    that would sweep it lower is lifted clear of the surface there by its own C-space)."""
    x = _within_path(px, bend)
    return np.maximum(0.5 * bend[..., 0:1] * x * x - bend[..., 2:3] * x * py, 0.0)


def bent_profile(py: np.ndarray, pz: np.ndarray, px: np.ndarray, bend: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The profile (LY, LZ; (..., S)) whose points are formed LX = px along the feed, as a pass bending by
    `bend` (..., 5) (path_bending) sweeps it (module doc): raised, not moved across (the widest postures are
    chosen on the lateral samples, raised alone: a measure that moved the profile across came out narrower
    than the choice, and held the bins back)."""
    return py, pz + raise_of(px, py, bend)


def bottom_low(cutter: Cutter, lam: np.ndarray, omg: np.ndarray, delta: np.ndarray, y: np.ndarray,
               bend: np.ndarray) -> np.ndarray:
    """(P, Y) the lowest LZ of the tool's flat bottom (the disc of radius R - r) across LY = y (P, Y), bent
    by `bend` (P, 5) (raise_of at its lead x; inf where the disc does not reach y). The profile's point is
    the bottom's lowest straight; bent, a point of the bottom nearer the CC point can be lower (at lambda ~0
    the bottom passes through the section itself, raised nowhere)."""
    rot = tool_rotation(lam, omg)
    tip = touch_tip(cutter, rot) + delta[:, None] * rot[:, 2, :]                     # (P, 3) LCS
    U, V = rot[:, 0, :], rot[:, 1, :]
    rp = cutter.radius - cutter.corner_radius
    q = np.hypot(U[:, 1], V[:, 1])[:, None]                                          # LY per unit across the disc
    dy = y - tip[:, 1:2]
    ok = (q > 1e-9) & (np.abs(dy) < rp * q)
    qs = np.maximum(q, 1e-9)
    fa, fb = dy * U[:, 1:2] / qs ** 2, dy * V[:, 1:2] / qs ** 2                     # the chord's foot (a, b)
    da, db = V[:, 1:2] / qs, -U[:, 1:2] / qs                                          # and direction
    hl = np.sqrt(np.maximum(rp * rp - fa * fa - fb * fb, 0.0))
    x0 = tip[:, :1] + fa * U[:, :1] + fb * V[:, :1]
    z0 = tip[:, 2:] + fa * U[:, 2:] + fb * V[:, 2:]
    xd, zd = da * U[:, :1] + db * V[:, :1], da * U[:, 2:] + db * V[:, 2:]
    k, t, ahead, back = bend[:, 0:1], bend[:, 2:3], bend[:, 3:4], bend[:, 4:5]
    xs = np.where(np.abs(xd) > 1e-12, xd, 1e-12)
    kk = np.where(np.abs(k) > 1e-12, k, 1e-12)
    # where along the chord: its ends, the path's ends, where the raise starts (raise_of) and where the
    # raised height turns (convex)
    low = np.full(y.shape, np.inf)
    for u in [(x - x0) / xs for x in (-ahead, back, 0.0 * y, 2 * t * y / kk, (t * y - zd / xs) / kk)] + [-hl, hl]:
        u = np.clip(u, -hl, hl)
        low = np.minimum(low, z0 + u * zd + raise_of(x0 + u * xd, y, bend))
    return np.where(ok, low, np.inf)


def _lifted(cutter: Cutter, lam: np.ndarray, omg: np.ndarray, delta: np.ndarray):
    """lower_profile with its lead, lifted by delta along each posture's axis."""
    py, pz, px = lower_profile(cutter, lam, omg, 2001, lead=True)
    a = tool_rotation(lam, omg)[:, 2, :]
    return py + delta[:, None] * a[:, 1:2], pz + delta[:, None] * a[:, 2:], px + delta[:, None] * a[:, :1]


def swept_profiles(cutter: Cutter, lam: np.ndarray, omg: np.ndarray, delta: np.ndarray,
                   bend: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
    """(n, S) LY, LZ of each posture's profile lifted by delta, as the pass sweeps it: straight (bend None)
    or bent by `bend` (n, 5) (path_bending)."""
    py, pz, px = _lifted(cutter, lam, omg, delta)
    if bend is not None:
        py, pz = bent_profile(py, pz, px, bend)
        c = _chord_matters(lam, bend, cutter.radius)
        if c.any():
            # on even LY (near lambda = 0 the support points crowd at the bottom's ends: the chord between
            # them would be read linear)
            u = np.linspace(0.0, 1.0, py.shape[1])[None, :]
            qy = py[c, :1] + (py[c, -1:] - py[c, :1]) * u
            qz = np.array([np.interp(a, b, z) for a, b, z in zip(qy, py[c], pz[c])])
            py, pz = py.copy(), pz.copy()
            py[c], pz[c] = qy, np.minimum(qz, bottom_low(cutter, lam[c], omg[c], delta[c], qy, bend[c]))
    return py, pz


def _chord_matters(lam: np.ndarray, bend: np.ndarray, radius: float) -> np.ndarray:
    """Where the bent bottom can be lower inside than at its rim (bottom_low): the bend turns the bottom's
    slope along the feed (tan lambda) within a radius, convex along the feed or twisted."""
    return np.tan(np.abs(lam)) < 1.5 * radius * (np.maximum(bend[..., 0], 0.0) + np.abs(bend[..., 2]))


def half_widths(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, lam: np.ndarray,
                omg: np.ndarray, delta: np.ndarray, tolerance: float, bend: Optional[np.ndarray] = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """For n CC points with their postures (lam, omg rad, delta mm, each (n,)): the half-widths (n, 2) (left
    +LY, right -LY; inf where the mesh ends first) within which the remaining height stays <= `tolerance`,
    and the world points of the section at those widths (n, 2, 3) (NaN where inf). `bend` (n, 5): the
    profile as the curving pass sweeps it (swept_profiles); None: swept straight along LX."""
    require_plain(cutter)
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    frm = np.asarray(frames, dtype=float).reshape(-1, 3, 3)
    lam, omg, delta = (np.asarray(v, dtype=float).reshape(-1) for v in (lam, omg, delta))
    n = len(pts)
    ys = np.linspace(0.0, 2.0 * cutter.radius, WIDTH_SAMPLES)
    lateral = np.concatenate([ys, -ys[1:]])
    S = surface_heights(reach, pts, frm, np.tile(lateral, (n, 1)), 3.0 * cutter.radius)
    py, pz = swept_profiles(cutter, lam, omg, delta, bend)
    widths = np.zeros((n, 2))
    ends = np.full((n, 2, 3), np.nan)
    for i in range(n):
        z = np.interp(lateral, py[i], pz[i], left=np.inf, right=np.inf)
        h = z - S[i]
        for side, sl in ((0, slice(0, len(ys))), (1, np.r_[0, len(ys):len(lateral)])):
            y, hs = np.abs(lateral[sl]), h[sl]
            over = np.flatnonzero(~(hs <= tolerance))                       # NaN (mesh ended) counts too
            if over.size == 0:
                widths[i, side] = np.inf if np.isnan(hs).any() else y[-1]
                continue
            k = int(over[0])
            sgn = 1.0 if side == 0 else -1.0
            if np.isnan(hs[k]) and _past_edge(py[i], pz[i], y, S[i][sl], sgn, k, tolerance):
                widths[i, side] = np.inf
                continue
            d = 0.0 if k == 0 else y[k - 1] if np.isnan(hs[k]) else _crossing(py[i], pz[i], y, S[i][sl], sgn, y[k - 1], y[k], tolerance)
            widths[i, side] = d
            s_d = S[i][sl][k - 1] if np.isnan(hs[k]) else np.interp(d, y, S[i][sl])
            ends[i, side] = pts[i] + sgn * d * frm[i, 1] + s_d * frm[i, 2]
    return widths, ends


def _past_edge(py: np.ndarray, pz: np.ndarray, y: np.ndarray, s: np.ndarray, sgn: float, k: int,
               tolerance: float) -> bool:
    """Whether the profile covers the section beyond its last sample on the mesh (k - 1): at sample k (off
    the mesh, the section extrapolated from the two before) the tool is there within the tolerance. Else the
    side ends at that sample, short of the mesh's edge (a sliver the next pass or the clean-up takes)."""
    if k == 0:
        return True                                                         # the CC point itself: as before
    z = np.interp(sgn * y[k], py, pz, left=np.inf, right=np.inf)
    return bool(z - (s[0] if k == 1 else 2 * s[k - 1] - s[k - 2]) <= tolerance)


def _crossing(py: np.ndarray, pz: np.ndarray, y: np.ndarray, s: np.ndarray, sgn: float, a: float, b: float,
              tolerance: float) -> float:
    """The lateral distance in [a, b] where the remaining height (profile over the section, linear between
    the section's samples) reaches the tolerance, by bisection (the profile curves between samples)."""
    for _ in range(30):
        mid = 0.5 * (a + b)
        # beyond the profile's ends the tool is not there (its side wall): never within the tolerance
        if np.interp(sgn * mid, py, pz, left=np.inf, right=np.inf) - np.interp(mid, y, s) <= tolerance:
            a = mid
        else:
            b = mid
    return 0.5 * (a + b)


def reach_widths(reach: MeshReach, cutter: Cutter, points: np.ndarray, frames: np.ndarray, cs: CSpace,
                 tolerance: float, m: np.ndarray, bend: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
    """(n, P) how far along the plane normal m each available posture of the C-space at its lift S2
    finishes on the left (+m) and back on the right (-m) (the half-widths as half_widths, to the section's
    samples, the crossing linear between two, and their section points' share of m; inf where the mesh ends
    first, NaN where the posture is not available): what each posture would finish, to choose from."""
    n = len(points)
    lam, omg = (g.ravel() for g in cs.grid.mesh())
    ys = np.linspace(0.0, 2.0 * cutter.radius, WIDTH_SAMPLES)
    lateral = np.concatenate([ys, -ys[1:]])
    S = surface_heights(reach, points, frames, np.tile(lateral, (n, 1)), 3.0 * cutter.radius)
    py, pz, px = lower_profile(cutter, lam, omg, 2001, lead=True)
    h = 0.01 * cutter.radius
    g = np.arange(-3.0 * cutter.radius, 3.0 * cutter.radius + h, h)
    # the profile on a uniform grid (far above beyond its ends: the side wall is no cutting edge)
    Z = np.array([np.interp(g, py[p], pz[p], left=1e9, right=1e9) for p in range(len(lam))])
    X = np.array([np.interp(g, py[p], px[p]) for p in range(len(lam))]) if bend is not None else None
    ax = tool_rotation(lam, omg)[:, 2, :]
    a = ax[:, 1:]
    avail = cs.available.reshape(n, -1)
    lift = cs.lift.reshape(n, -1)
    out = np.full((2, n, len(lam)), np.nan)
    sides = (np.arange(len(ys)), np.r_[0, len(ys):len(lateral)])
    ly, lz = frames[:, 1] @ m, frames[:, 2] @ m
    for i in range(n):
        ps = np.flatnonzero(avail[i])
        if ps.size == 0:
            continue
        d = lift[i, ps][:, None]
        u = np.clip((lateral[None, :] - d * a[ps, :1] - g[0]) / h, 0.0, len(g) - 1.001)
        k = u.astype(np.int64)
        t = u - k
        z = Z[ps[:, None], k] * (1 - t) + Z[ps[:, None], k + 1] * t + d * a[ps, 1:]
        if X is not None:
            x = X[ps[:, None], k] * (1 - t) + X[ps[:, None], k + 1] * t + d * ax[ps, :1]
            z = np.where(z < 1e8, z + raise_of(x, lateral[None, :], bend[i]), z)
            c = _chord_matters(lam[ps], bend[i], cutter.radius)
            if c.any():
                q = ps[c]
                z[c] = np.minimum(z[c], bottom_low(cutter, lam[q], omg[q], d[c, 0], np.tile(lateral, (len(q), 1)),
                                                   np.tile(bend[i], (len(q), 1))))
        rem = z - S[i][None, :]
        for side, sl in enumerate(sides):
            r = rem[:, sl]
            over = ~(r <= tolerance)
            first = np.where(over.any(axis=1), over.argmax(axis=1), len(ys))
            rows = np.arange(len(ps))
            k1 = np.minimum(first, len(ys) - 1)
            k0 = np.maximum(first - 1, 0)
            r0, r1 = r[rows, k0], r[rows, k1]
            frac = np.clip((tolerance - r0) / np.where(r1 > r0, r1 - r0, np.inf), 0.0, 1.0)
            w = np.where(first == 0, 0.0, ys[k0] + frac * (ys[k1] - ys[k0]))
            w = np.where(first >= len(ys), ys[-1], w)
            # the mesh ended first: the whole side when the tool is there beyond the last sample on the mesh
            # too (the section there extrapolated), else only up to that sample (the edge left a sliver)
            k2 = np.maximum(first - 2, 0)
            s_sl = S[i][sl]
            ext = 2 * s_sl[k0] - s_sl[k2]
            zk = z[rows, sl[k1]]
            covered = (zk < 1e8) & (zk - ext <= tolerance)
            w = np.where((first < len(ys)) & np.isnan(r1), np.where(covered, np.inf, ys[k0]), w)
            s0, s1 = s_sl[k0], s_sl[k1]
            s_w = np.where(first >= len(ys), s_sl[-1], np.where(np.isnan(s1), s0, s0 + frac * (s1 - s0)))
            sgn = 1.0 if side == 0 else -1.0
            out[side, i, ps] = np.where(np.isinf(w), w, w * ly[i] + sgn * s_w * lz[i])
    return out[0], out[1]


def edge_by_tools(reach: MeshReach, cutter: Cutter, paths: List[CCPath], tips: np.ndarray, axes: np.ndarray,
                  widths: np.ndarray, ends: np.ndarray, tolerance: float, sides: tuple[int, ...] = (0, 1),
                  sub: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The `sides` (0 left, 1 right) found covered to the mesh's edge (inf in `widths` (n, 2), half_widths)
    measured again under the pass's own tool positions (`tips`, `axes` (n, 3), all paths in order; `sub` - 1
    between each two, tip linear, axis lerp; beyond a path's end its last tool straight along LX a radius on):
    the flat end's bottom disc at each, cut by the CC point's section. The profile there is formed by the rim
    up to a radius along the pass, where the posture has turned (on seed 000's concave upper edge omega swings
    4 deg between CC points: the profile covered the edge, the tools stopped 0.2-0.5 mm short of it). A side
    the tools do not cover to the edge gets the width they do (and its end point). The bull-nose's torus is
    not modelled: its widths are returned as they are. Also (n,) how far (mm, along LY) the tools stop short
    of the mesh's edge where they do (0 elsewhere)."""
    pts = np.concatenate([p.points for p in paths])
    frm = np.concatenate([p.frames for p in paths])
    idx = np.flatnonzero(np.isinf(widths[:, list(sides)]).any(axis=1))
    short = np.zeros(len(widths))
    if idx.size == 0 or cutter.corner_radius > 0:
        return widths, ends, short
    widths, ends = widths.copy(), ends.copy()
    R = cutter.radius
    ys = np.linspace(0.0, 2.0 * R, WIDTH_SAMPLES)
    first = np.cumsum([0] + [len(p) for p in paths])
    along = np.concatenate([np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(p.points, axis=0), axis=1))] for p in paths])
    for i in idx:
        q = int(np.searchsorted(first, i, side="right")) - 1
        a, b = first[q], first[q + 1]
        near = np.flatnonzero(np.abs(along[a:b] - along[i]) <= 1.5 * R) + a
        lo, hi = max(int(near.min()) - 1, a), min(int(near.max()) + 1, b - 1)
        T, A = _sub_positions(tips[lo:hi + 1], axes[lo:hi + 1], sub)
        for k, sgn in ((a, -1.0), (b - 1, 1.0)):
            if k in (lo, hi):                      # the path's end within reach: the tool goes on along LX
                s = np.linspace(0.0, R, sub + 1)[1:, None]
                T, A = np.vstack([T, tips[k] + sgn * s * frm[k, 0]]), np.vstack([A, np.repeat(axes[k][None], sub, 0)])
        for side, (d, s_d, S) in enumerate(_sides_covered(reach, pts[i], frm[i], T, A, R, ys, tolerance)):
            if side not in sides or not np.isinf(widths[i, side]):
                continue
            if np.isfinite(d):
                sgn = 1.0 if side == 0 else -1.0
                widths[i, side] = d
                ends[i, side] = pts[i] + sgn * d * frm[i, 1] + s_d * frm[i, 2]
                on = np.flatnonzero(~np.isnan(S))
                short[i] = max(short[i], float(ys[on.max()]) - d if on.size else 0.0)
    return widths, ends, short


def _sides_covered(reach: MeshReach, point: np.ndarray, frame: np.ndarray, T: np.ndarray, A: np.ndarray,
                   radius: float, ys: np.ndarray, tolerance: float) -> list[tuple[float, float, np.ndarray]]:
    """Per side (0 left along LY, 1 right) of `point`'s section (`frame`: LX, LY, normal) cut by the flat
    bottoms of radius at the tool positions `T`, `A`: how far they finish it within `tolerance` and the height
    there (_covered_to), and the surface's heights at `ys` along that side (NaN off the mesh)."""
    lateral = np.concatenate([ys, -ys[1:]])
    z = _disc_heights(point, frame, T, A, radius, lateral)
    S = surface_heights(reach, point[None], frame[None], lateral[None], 3.0 * radius)[0]
    return [(*_covered_to(ys, z[sl], S[sl], tolerance), S[sl])
            for sl in (slice(0, len(ys)), np.r_[0, len(ys):2 * len(ys) - 1])]


def _sub_positions(tips: np.ndarray, axes: np.ndarray, sub: int) -> tuple[np.ndarray, np.ndarray]:
    """The tool positions with `sub` - 1 between each two (tip linear, axis lerp normalised)."""
    if len(tips) < 2:
        return tips.copy(), axes.copy()
    t = (np.arange(sub) / sub)[None, :, None]
    T = (tips[:-1, None] + t * (tips[1:, None] - tips[:-1, None])).reshape(-1, 3)
    A = (axes[:-1, None] + t * (axes[1:, None] - axes[:-1, None])).reshape(-1, 3)
    A /= np.linalg.norm(A, axis=1, keepdims=True)
    return np.vstack([T, tips[-1:]]), np.vstack([A, axes[-1:]])


def _disc_heights(p: np.ndarray, f: np.ndarray, tips: np.ndarray, axes: np.ndarray, radius: float,
                  lateral: np.ndarray) -> np.ndarray:
    """(L,) the lowest LZ, over the flat bottoms (discs of `radius` at `tips` normal to `axes`), of the
    CC point p's section (LX = 0, LY = lateral) in its LCS `f`; inf where no disc is there."""
    c, a = (tips - p) @ f.T, axes @ f.T
    u = np.cross(a, np.where(np.abs(a[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(a, u)
    det = u[:, :1] * v[:, 1:2] - v[:, :1] * u[:, 1:2]                       # a's LZ share: > 0 here
    ok = np.abs(det) > 1e-9
    det = np.where(ok, det, 1.0)
    rx, ry = -c[:, :1], lateral[None, :] - c[:, 1:2]
    s = (rx * v[:, 1:2] - v[:, :1] * ry) / det
    t = (u[:, :1] * ry - u[:, 1:2] * rx) / det
    z = c[:, 2:] + s * u[:, 2:] + t * v[:, 2:]
    z = np.where(ok & (s * s + t * t <= radius * radius), z, np.inf)
    return z.min(axis=0)


def _covered_to(ys: np.ndarray, z: np.ndarray, s: np.ndarray, tolerance: float) -> tuple[float, float]:
    """(how far along the lateral samples `ys` the tools' heights `z` stay within `tolerance` of the section
    `s` (inf: to the mesh's edge, the tools there beyond its last sample on it too, as _past_edge), the
    section's height there)."""
    h = z - s
    over = np.flatnonzero(~(h <= tolerance))
    if over.size == 0:
        return (np.inf, np.nan) if np.isnan(s).any() else (float(ys[-1]), float(s[-1]))
    k = int(over[0])
    if k == 0:
        return 0.0, float(s[0])
    if np.isnan(s[k]):
        ext = s[0] if k == 1 else 2 * s[k - 1] - s[k - 2]
        return (np.inf, np.nan) if z[k] - ext <= tolerance else (float(ys[k - 1]), float(s[k - 1]))
    if not np.isfinite(h[k]):
        return float(ys[k - 1]), float(s[k - 1])
    f = (tolerance - h[k - 1]) / (h[k] - h[k - 1])
    return float(ys[k - 1] + f * (ys[k] - ys[k - 1])), float(s[k - 1] + f * (s[k] - s[k - 1]))


def end_by_tools(reach: MeshReach, cutter: Cutter, path: CCPath, tips: np.ndarray, axes: np.ndarray,
                 widths: np.ndarray, tolerance: float, sections: int = 4, sub: int = 8) -> List[tuple]:
    """The stretch between each end CC point of `path` and the mesh's edge it was moved in from
    (CCPath.inset), measured under the path's own tool positions (`tips`, `axes`: its run with the overruns;
    `sub` - 1 between each two) at `sections` sections along the end's LX: where the flat bottoms there finish
    less of a side than the end CC point's half-width (`widths` (2, 2): first and last CC point, left and right;
    inf: to the mesh's edge), (end 0 / 1, side, the section's point, where the tools stop on it (3,)). The
    C-space and the half-widths are only asked at the CC points; beyond the end one the tool goes on straight at its
    posture while the surface twists under it (seed 000's complex surface: 0.8-1.7 mm left 1-2 mm from the x = 228.6
    edge between two passes). The bull-nose's torus is not modelled: none for it. An end cut short has none."""
    out: List[tuple] = []
    R = cutter.radius
    if cutter.corner_radius > 0:
        return out
    ys = np.linspace(0.0, 2.0 * R, WIDTH_SAMPLES)
    for e, (k, sgn) in enumerate(((0, -1.0), (-1, 1.0))):
        inset = path.inset[k]
        if path.cut_short[k] or inset < 0.05 * R:
            continue
        f = path.frames[k]
        t = inset * np.r_[np.arange(1, sections) / sections, 1.0 - 0.01 * R / inset]
        pts = path.points[k] + sgn * t[:, None] * f[0]
        frm = np.repeat(f[None], len(t), 0)
        h = surface_heights(reach, pts, frm, np.zeros((len(t), 1)), 3.0 * R)[:, 0]
        for p in pts[np.isfinite(h)] + h[np.isfinite(h), None] * f[2]:
            near = np.flatnonzero(np.linalg.norm(tips - p, axis=1) <= 2.0 * R)
            if near.size == 0:
                out += [(e, side, p, p.copy()) for side in (0, 1) if widths[e, side] > 0]
                continue
            lo, hi = max(int(near.min()) - 1, 0), min(int(near.max()) + 1, len(tips) - 1)
            T, A = _sub_positions(tips[lo:hi + 1], axes[lo:hi + 1], sub)
            for side, (d, s_d, _) in enumerate(_sides_covered(reach, p, f, T, A, R, ys, tolerance)):
                if d < widths[e, side] - 1e-3 * R:
                    sg = 1.0 if side == 0 else -1.0
                    out.append((e, side, p, p + sg * d * f[1] + (0.0 if np.isnan(s_d) else s_d) * f[2]))
    return out
