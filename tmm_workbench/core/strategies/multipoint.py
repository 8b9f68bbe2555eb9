"""Multipoint 5-axis positioning of a toroidal cutter on a Bézier/B-spline face (seed 001, Singh 2020).

The face is taken exactly (Bézier patches, B-splines split by knot insertion); the footprint is XY parallel
passes (side step across, forward step along, any feed direction); at each footprint point the kernel
drops the tool vertically to a first contact P, then tilts it about the pseudo-insert's axis until it
touches a second point Q (methods "vcrf" and "drd" of the seed). Every position is checked for gouging.

    face = BezierFace.from_net(net)                   # or from_bspline(...), from_patches(...)
    path, res = compute_multipoint_toolpath(face, Ro=6.7, Ri=6.0, params=MultipointParams(side_step=18))

`res` holds per footprint point: status ("two" / "one" / "failed"), the reason, P, nP, Q, nQ, the tilt beta,
tip, axis, centre. The Toolpath's moves carry the tip and the unit tool axis (tip -> spindle).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional, Sequence

import numpy as np

from tmm_workbench.core.geometry.bspline import BezierPieces, bspline_to_bezier
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.footprint.raster import EVEN, Rect, raster_lines, sample_segment
from tmm_workbench.core.kernel import native
from tmm_workbench.core.toolpath import MoveKind, Toolpath

Progress = Callable[[float], bool]

STATUS_TWO, STATUS_ONE, STATUS_FAILED = 0, 1, 2
STATUS_NAMES = ("two", "one", "failed")
METHODS = ("vcrf", "drd")
SHAPES = ("round_insert", "bull_nose")
ROTATIONS = ("pseudo_insert", "global_x")
ANCHORS = ("axis", "tip")


class BezierFace:
    """A face of nu x nv Bézier patches (any degree) in the kernel, evaluated exactly."""

    def __init__(self, nets: Sequence[np.ndarray], nu: int = 1, nv: int = 1,
                 breaks_u: Optional[Sequence[float]] = None, breaks_v: Optional[Sequence[float]] = None,
                 name: str = "face") -> None:
        arrs = [np.ascontiguousarray(n, dtype=np.float64) for n in nets]
        for a in arrs:
            if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] < 2 or a.shape[1] < 2:
                raise TmmError(f"{name}: a Bézier control net must have shape (p+1, q+1, 3), p, q >= 1; got {a.shape}")
            if not np.isfinite(a).all():
                raise TmmError(f"{name}: Bézier control net has a non-finite coordinate")
        bu = list(map(float, breaks_u)) if breaks_u is not None else list(np.linspace(0.0, float(nu), nu + 1))
        bv = list(map(float, breaks_v)) if breaks_v is not None else list(np.linspace(0.0, float(nv), nv + 1))
        self.name = name
        try:
            self._surface = native.PatchSurface(arrs, int(nu), int(nv), bu, bv)
        except ValueError as exc:
            raise TmmError(f"{name}: {exc}") from exc

    @classmethod
    def from_net(cls, net: np.ndarray, name: str = "face") -> "BezierFace":
        return cls([net], 1, 1, [0.0, 1.0], [0.0, 1.0], name=name)

    @classmethod
    def from_pieces(cls, pieces: BezierPieces, name: str = "face") -> "BezierFace":
        return cls(pieces.nets, pieces.nu, pieces.nv, pieces.breaks_u, pieces.breaks_v, name=name)

    @classmethod
    def from_bspline(cls, poles, degree_u: int, degree_v: int, knots_u, mults_u, knots_v, mults_v,
                     weights=None, periodic_u: bool = False, periodic_v: bool = False,
                     name: str = "face") -> "BezierFace":
        """Exact: the B-spline split into its Bézier patches by knot insertion (see core.bspline)."""
        return cls.from_pieces(bspline_to_bezier(poles, degree_u, degree_v, knots_u, mults_u, knots_v, mults_v,
                                                 weights, periodic_u, periodic_v), name=name)

    @classmethod
    def from_freecad_surface(cls, surface, name: str = "face") -> "BezierFace":
        """A Part.BSplineSurface or Part.BezierSurface, exactly (duck-typed: the core never imports FreeCAD).
        Periodic B-splines are made non-periodic on a copy first (same geometry); rational ones are refused
        unless all weights are 1."""
        def weights_of(srf):
            # OCC answers zeros for the weights of a non-rational surface made non-periodic: ask first.
            rational = getattr(srf, "isURational", lambda: True)() or getattr(srf, "isVRational", lambda: True)()
            return np.array(srf.getWeights(), dtype=float) if rational and hasattr(srf, "getWeights") else None

        poles = np.array([[tuple(p) for p in row] for row in surface.getPoles()], dtype=float)
        weights = weights_of(surface)
        if hasattr(surface, "getUKnots"):  # B-spline
            if surface.isUPeriodic() or surface.isVPeriodic():
                surface = surface.copy()
                if surface.isUPeriodic():
                    surface.setUNotPeriodic()
                if surface.isVPeriodic():
                    surface.setVNotPeriodic()
                poles = np.array([[tuple(p) for p in row] for row in surface.getPoles()], dtype=float)
                weights = weights_of(surface)
            return cls.from_bspline(poles, surface.UDegree, surface.VDegree, surface.getUKnots(),
                                    surface.getUMultiplicities(), surface.getVKnots(), surface.getVMultiplicities(),
                                    weights, name=name)
        if weights is not None and np.max(np.abs(weights - 1.0)) > 1e-12:
            raise TmmError(f"{name}: rational Bézier surface (weights not all 1) is not supported")
        return cls.from_net(poles, name=name)

    @property
    def native(self):
        return self._surface

    @property
    def domain(self) -> tuple[float, float, float, float]:
        return self._surface.domain

    @property
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Box of the control nets (it holds the face)."""
        return self._surface.bounds

    def evaluate(self, uv: np.ndarray) -> dict[str, np.ndarray]:
        """S, Su, Sv, Suu, Suv, Svv at (n, 2) global parameters."""
        return self._surface.evaluate(np.ascontiguousarray(uv, dtype=np.float64).reshape(-1, 2))

    def xy_extent(self, samples: int = 64) -> Rect:
        """XY extent of the face itself (sampled densely, not the control hull)."""
        u0, u1, v0, v1 = self.domain
        u = np.linspace(u0, u1, samples + 1)
        v = np.linspace(v0, v1, samples + 1)
        U, V = np.meshgrid(u, v, indexing="ij")
        S = self.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
        return float(S[:, 0].min()), float(S[:, 1].min()), float(S[:, 0].max()), float(S[:, 1].max())


@dataclass
class MultipointParams:
    side_step: float = 18.0          # mm between passes (seed: 18)
    pass_spacing: str = EVEN         # EVEN: spread evenly, at most side_step apart; FIXED: side_step apart from
                                     # the start edge, the last pass on the far edge (the seed's footprint)
    forward_step: float = 2.0        # mm between positions along a pass (seed: 2)
    feed_angle_deg: float = 90.0     # feed direction from +X (seed: along Y, side step along X)
    margin: float = 0.0              # the boundary is the face's XY extent grown by this (mm; < 0 shrinks)
    boundary: Optional[Rect] = None  # explicit (xmin, ymin, xmax, ymax), overrides the face's extent
    zigzag: bool = True              # alternate pass directions
    clearance: float = 5.0           # rapid height above the face's top, mm
    shape: str = "round_insert"      # tool solid: the seed's torus with a hollow centre, or a bull-nose
    rotation: str = "pseudo_insert"  # exact tilt; "global_x" reproduces the seed's pseudo-code
    beta_max_deg: float = 45.0       # tilt limit (seed: pi/4)
    extend: float = 0.0              # mm: position against the face continued past its edges (0: off)
    anchor: str = "axis"             # footprint point = pre-tilt tool axis ("axis", seed) or tilted tip ("tip")
    anchor_iterations: int = 12      # "tip": at most this many positions per footprint point
    tol: float = 1e-3                # contact and gouge tolerance, mm
    sample_spacing: float = 0.0      # surface samples (0: (Ro + Ri) / 8)
    divisions: int = 6               # VCRF zoom grid (seed 32)
    refinements: int = 1             # VCRF zoom levels (seed 4)
    drd_divisions: int = 10          # DRD rays per direction (seed 10)
    drd_refinements: int = 5         # DRD zoom levels (seed 5)
    drd_bisections: int = 16         # DRD bisection steps on the tilt
    threads: int = 0                 # 0: all cores


@dataclass
class MultipointResults:
    """Per footprint point (n = number of points), arrays from the kernel, plus the pass of each point."""
    xy: np.ndarray                   # (n, 2) footprint points
    passes: np.ndarray               # (n,) pass index
    data: dict = field(default_factory=dict)
    reasons: list = field(default_factory=list)

    def __getitem__(self, key: str) -> np.ndarray:
        return self.data[key]

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def status(self) -> np.ndarray:
        return self.data["status"]

    def status_names(self) -> list[str]:
        return [STATUS_NAMES[s] for s in self.data["status"]]

    def reason_texts(self) -> list[str]:
        return [self.reasons[r] for r in self.data["reason"]]

    def counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.data["status"] == k)) for k, name in enumerate(STATUS_NAMES)}

    def records(self) -> list[dict]:
        """One dict per point (for reports and tables)."""
        out = []
        for i in range(len(self)):
            rec = {"x": float(self.xy[i, 0]), "y": float(self.xy[i, 1]), "pass": int(self.passes[i]),
                   "status": STATUS_NAMES[self.data["status"][i]], "reason": self.reasons[self.data["reason"][i]]}
            for k in ("beta", "gap_P", "gap_Q", "penetration", "seed_axis_angle"):
                rec[k] = float(self.data[k][i])
            for k in ("tip", "axis", "centre", "P", "nP", "Q", "nQ"):
                rec[k] = tuple(float(c) for c in self.data[k][i])
            out.append(rec)
        return out


def _check_tool(Ro: float, Ri: float) -> None:
    for name, v in (("Ro", Ro), ("Ri", Ri)):
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise TmmError(f"{name} must be a finite number of mm, got {v!r}")
    if Ro < 0:
        raise TmmError(f"major radius Ro must be >= 0 (0 is a ball end mill), got {Ro:g}")
    if Ri <= 0:
        raise TmmError("minor radius Ri must be > 0: a flat end mill (Ri = 0) has no pseudo-insert to tilt about; "
                       f"multipoint positioning needs a toroidal or ball cutter (got Ri = {Ri:g})")


def _check_params(p: MultipointParams) -> None:
    for name in ("side_step", "forward_step"):
        v = getattr(p, name)
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise TmmError(f"{name.replace('_', ' ')} must be a positive length, got {v!r}")
    if p.shape not in SHAPES:
        raise TmmError(f"tool shape must be one of {SHAPES}, got {p.shape!r}")
    if p.rotation not in ROTATIONS:
        raise TmmError(f"rotation must be one of {ROTATIONS}, got {p.rotation!r}")
    if p.anchor not in ANCHORS:
        raise TmmError(f"footprint anchor must be one of {ANCHORS}, got {p.anchor!r}")
    if not (isinstance(p.extend, (int, float)) and math.isfinite(p.extend) and p.extend >= 0):
        raise TmmError(f"surface extension must be a length >= 0, got {p.extend!r}")
    if not (isinstance(p.anchor_iterations, int) and p.anchor_iterations >= 1):
        raise TmmError(f"anchor iterations must be an integer >= 1, got {p.anchor_iterations!r}")
    if not (0 < p.beta_max_deg < 90):
        raise TmmError(f"tilt limit must be in (0, 90) degrees, got {p.beta_max_deg!r}")
    if not (p.tol > 0):
        raise TmmError(f"tolerance must be > 0, got {p.tol!r}")


def multipoint_footprint(face: BezierFace, params: MultipointParams) -> list[np.ndarray]:
    """XY parallel passes over the boundary (the face's XY extent grown by `margin`, or `boundary`):
    passes running along `feed_angle_deg`, the first and last on the boundary, spread evenly at most
    `side_step` apart (pass_spacing EVEN) or exactly `side_step` apart from the start edge with the last
    strip narrower (FIXED: the seed keeps 18 mm and squeezes the last pass in at x = 150); points at most
    `forward_step` apart; zigzag optional. One (k, 2) array per pass, the first nearest the boundary's
    (xmin, ymin) corner."""
    _check_params(params)
    if params.boundary is not None:
        rect = tuple(map(float, params.boundary))
    else:
        x0, y0, x1, y1 = face.xy_extent()
        m = float(params.margin)
        rect = (x0 - m, y0 - m, x1 + m, y1 + m)
    lines = raster_lines(rect, params.side_step, params.feed_angle_deg, params.pass_spacing)
    # Start with the pass nearest the boundary's (xmin, ymin) corner.
    corner = np.array(rect[:2])
    if lines and np.linalg.norm(lines[-1].mean(0) - corner) < np.linalg.norm(lines[0].mean(0) - corner):
        lines = lines[::-1]
    passes = []
    for k, seg in enumerate(lines):
        pts = sample_segment(seg[0], seg[1], params.forward_step)
        if params.zigzag and k % 2 == 1:
            pts = pts[::-1]
        passes.append(pts)
    return passes


def make_positioner(face: BezierFace, Ro: float, Ri: float, params: Optional[MultipointParams] = None,
                    method: str = "vcrf"):
    """The kernel's positioner (surface samples built once per face and tool)."""
    params = params or MultipointParams()
    _check_tool(Ro, Ri)
    _check_params(params)
    if method not in METHODS:
        raise TmmError(f"method must be 'vcrf' or 'drd', got {method!r}")
    try:
        return native.MultipointPositioner(
            face.native, float(Ro), float(Ri), params.shape, method, params.rotation,
            math.radians(params.beta_max_deg), float(params.tol), float(params.sample_spacing),
            int(params.divisions), int(params.refinements), int(params.drd_divisions),
            int(params.drd_refinements), int(params.drd_bisections), float(params.extend), params.anchor,
            int(params.anchor_iterations))
    except ValueError as exc:
        raise TmmError(str(exc)) from exc


def position_points(face: BezierFace, Ro: float, Ri: float, xy: np.ndarray,
                    params: Optional[MultipointParams] = None, method: str = "vcrf",
                    progress: Optional[Progress] = None) -> MultipointResults:
    """Multipoint positions at the (n, 2) footprint points."""
    params = params or MultipointParams()
    mp = make_positioner(face, Ro, Ri, params, method)
    pts = np.ascontiguousarray(xy, dtype=np.float64).reshape(-1, 2)
    if not np.isfinite(pts).all():
        raise TmmError("footprint points contain a non-finite coordinate")
    try:
        data = mp.position_batch(pts, int(params.threads), progress)
    except native.Cancelled as exc:
        raise Cancelled("multipoint tool path computation cancelled") from exc
    return MultipointResults(pts, np.zeros(len(pts), dtype=int), data, list(native.multipoint_reasons()))


def compute_multipoint_toolpath(surface: BezierFace, Ro: float, Ri: float,
                                params: Optional[MultipointParams] = None, method: str = "vcrf",
                                progress: Optional[Progress] = None) -> tuple[Toolpath, MultipointResults]:
    """5-axis tool path over `surface` by multipoint positioning, and the per-point results.

    Each pass: a rapid above its first good position, a plunge to it, feeds through the positions (tip and
    axis), a rapid up at the end. Failed positions (no surface under the tool, gouge) are not cut: the pass
    is left and re-entered around them. progress(fraction) -> bool; False cancels (raises Cancelled).
    """
    params = params or MultipointParams()
    if not isinstance(surface, BezierFace):
        raise TmmError(f"surface must be a BezierFace, got {type(surface).__name__}")
    passes = multipoint_footprint(surface, params)
    if not passes:
        raise TmmError("the footprint is empty")
    xy = np.vstack(passes)
    pass_index = np.concatenate([np.full(len(p), k) for k, p in enumerate(passes)])
    res = position_points(surface, Ro, Ri, xy, params, method, progress)
    res.passes = pass_index
    top = surface.bounds[1][2] + Ri + float(params.clearance)
    path = Toolpath()
    tip, axis, status = res["tip"], res["axis"], res["status"]
    inside = False
    for i in range(len(xy)):
        new_pass = i > 0 and pass_index[i] != pass_index[i - 1]
        good = status[i] != STATUS_FAILED
        if inside and (new_pass or not good):
            last = path.moves[-1]
            path.add(MoveKind.RAPID, last.x, last.y, top, last.axis)
            inside = False
        if not good:
            continue
        a = tuple(axis[i])
        if not inside:
            path.add(MoveKind.RAPID, tip[i, 0], tip[i, 1], top, a)
            path.add(MoveKind.PLUNGE, *tip[i], a)
            inside = True
        else:
            path.add(MoveKind.FEED, *tip[i], a)
    if inside:
        last = path.moves[-1]
        path.add(MoveKind.RAPID, last.x, last.y, top, last.axis)
    return path, res
