"""The whole tool on a multipoint path (core.tools.assembly): the neck, shank and holder kept their clearance
from the face at every position and along the moves between (the tip on its line, the axis by slerp, as
core.verify.holder_clearance samples a 5-axis path), by the exact distance from a point sample of the face to
each tilted frustum (core.verify.body_distance). The sample's error (its spacing / sqrt(3), plus the chord
error of the face's tessellation, measured) is added to every clearance: a position passed here keeps the
clearance from the face itself.

Where a body comes too close:
  tilt       the axis is turned away from the face point nearest the body (the axis' top moves away from it,
             straight or up to 90 degrees aside), in steps of TILT_STEP_DEG, within the machine's tilt range
             (the tilt limit and the Tarus C limits), and the tool is put down on the face along Z with that
             axis (the kernel's signed clearance of the face from the torus brought to 0..tol/2): one contact,
             no gouge. The smallest turn that clears wins. A move between two positions that still comes too
             close, or gouges deeper than the tolerance between positions, gets the interpolated pose halfway
             (its axis by slerp, put down the same way, tilted in turn if it collides) inserted, up to
             MAX_ROUNDS times;
  leave_out  nothing is tilted.
What no tilt within the limits clears is not cut: the position is unreachable (failed, reason HOLDER), the
pass split there; a move that stays too close is split too (never cut through). The report lists both.
A tilted position keeps its footprint point and first contact P of before the tilt (its reason says so).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.geometry.bezier import grid_triangles
from tmm_workbench.core.geometry.face import BezierFace
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.drop_assembly import body_pieces
from tmm_workbench.core.report_text import within
from tmm_workbench.core.strategies.multipoint_status import STATUS_FAILED, STATUS_ONE
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.verify.body_distance import SurfacePoints
from tmm_workbench.core.verify.holder_clearance import CHECKED, sample_moves

TILT, LEAVE_OUT = "tilt", "leave_out"
MODES = (TILT, LEAVE_OUT)
TILTED = "tilted away from the shank or holder: one contact (P: the contact before the tilt)"
INSERTED = "inserted on a move for the shank or holder: one contact on the interpolated axis"
HOLDER = "the shank or holder comes closer to the face than its clearance at every tilt within the limits: not cut"
TILT_STEP_DEG = 2.5          # turns tried, this far apart
ASIDE_DEG = (0.0, 30.0, -30.0, 60.0, -60.0, 90.0, -90.0)   # directions tried, from straight away from the face
SURFACE_STEP_MM = 0.25       # the face's point sample (error 0.14 mm)
MESH_EDGE_MM = 1.0           # the face's tessellation, about this fine
MOVE_STEP_MM = 0.5           # samples along a move, at most this far apart (tip and the bodies' reach)
MAX_ROUNDS = 6               # halvings of a move that stays too close
DROP_ITERATIONS = 40
_BRACKET_MM = 1e-7       # a put-down bracket this narrow ends it
_MAX_MESH_CELLS = 400_000


def face_mesh(face: BezierFace, edge: float = MESH_EDGE_MM) -> tuple[TriMesh, float]:
    """The face tessellated on a parameter grid about `edge` mm fine, and its chord error (mm): the largest
    distance measured between a triangle's centre and the face at the centre's parameters."""
    u0, u1, v0, v1 = face.domain
    n = 33
    U, V = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, n), indexing="ij")
    S = face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"].reshape(n, n, 3)
    lu = float(np.linalg.norm(np.diff(S, axis=0), axis=2).sum(axis=0).max())
    lv = float(np.linalg.norm(np.diff(S, axis=1), axis=2).sum(axis=1).max())
    nu, nv = max(2, math.ceil(lu / edge)), max(2, math.ceil(lv / edge))
    scale = math.sqrt(_MAX_MESH_CELLS / (nu * nv))
    if scale < 1:
        nu, nv = max(2, int(nu * scale)), max(2, int(nv * scale))
    us, vs = np.linspace(u0, u1, nu + 1), np.linspace(v0, v1, nv + 1)
    U, V = np.meshgrid(us, vs, indexing="ij")
    pts = face.evaluate(np.column_stack([U.ravel(), V.ravel()]))["S"]
    tri = grid_triangles(nu, nv)
    uv = np.column_stack([U.ravel(), V.ravel()])
    centre_uv = uv[tri].mean(axis=1)
    error = float(np.linalg.norm(pts[tri].mean(axis=1) - face.evaluate(centre_uv)["S"], axis=1).max())
    return TriMesh(pts, tri, name=face.name), error


def tilt_range(beta_max_deg: float, machine: Any = None) -> tuple[float, float]:
    """(lowest, highest) tilt of the axis from the vertical (rad): the tilt limit, narrowed by a Tarus
    machine's C limits (C and -C reach the same tilts on the other branch)."""
    hi = math.radians(beta_max_deg)
    lo = 0.0
    if machine is not None:
        c0, c1 = machine.c_limits
        if c0 <= 0 <= c1:
            hi = min(hi, max(c1, -c0))
        else:
            a, b = sorted((abs(c0), abs(c1)))
            lo, hi = a, min(hi, b)
    return lo, hi


@dataclass
class MultipointHolderReport:
    """What the whole-tool check of a multipoint path did (app.tool_assembly.report shows `summary()`)."""
    mode: str
    points: int                      # positions checked
    samples: int = 0                 # poses checked along the moves
    tilted: int = 0                  # positions turned away
    inserted: int = 0                # positions inserted on moves
    max_turn_deg: float = 0.0        # the largest turn away
    unreachable: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))   # tips of the positions left out
    split_moves: int = 0             # moves left out (the pass split there)
    pieces: dict = field(default_factory=dict)  # piece -> positions it made collide (before any tilt)
    tilt_limits_deg: tuple[float, float] = (0.0, 0.0)
    error: float = 0.0               # mm added to every clearance for the face's sample

    @property
    def affected(self) -> int:
        """Positions and moves left uncut."""
        return len(self.unreachable) + self.split_moves

    @property
    def spots(self) -> np.ndarray:
        """Where material is left (the positions left out), for the view's marks."""
        return self.unreachable

    @property
    def region(self) -> Optional[tuple[float, float, float, float]]:
        if not len(self.unreachable):
            return None
        p = self.unreachable
        return float(p[:, 0].min()), float(p[:, 1].min()), float(p[:, 0].max()), float(p[:, 1].max())

    def summary(self) -> str:
        lo, hi = self.tilt_limits_deg
        parts = [f"{self.points} positions and {self.samples} poses along the moves checked for the shank and holder"]
        if self.pieces:
            parts.append("too close at first: " + ", ".join(f"{p} {n}" for p, n in sorted(self.pieces.items())))
        if self.tilted:
            parts.append(f"{self.tilted} positions tilted away (the axis turned up to {self.max_turn_deg:.1f} deg, "
                         f"within a tilt of {lo:g}..{hi:g} deg from the vertical)")
        if self.inserted:
            parts.append(f"{self.inserted} positions inserted on moves")
        if len(self.unreachable):
            parts.append(f"{len(self.unreachable)} positions unreachable ({'no tilt within the limits clears them' if self.mode == TILT else 'left out'}), "
                         f"{within(np.reshape(self.region, (2, 2)))}: not cut, the pass split there")
        if self.split_moves:
            parts.append(f"{self.split_moves} moves between positions left out (the pass split there)")
        if not self.pieces and not self.split_moves:
            parts.append("the shank and holder keep their clearance everywhere")
        return "; ".join(parts)


class WholeTool:
    """The assembly's non-cutting bodies against a face's point sample."""

    def __init__(self, face: BezierFace, assembly: Any, surface_step: float = SURFACE_STEP_MM) -> None:
        names = body_pieces(assembly)
        keep = [i for i, p in enumerate(names) if p in CHECKED]
        if not keep:
            raise TmmError(f"the tool assembly ({assembly.describe()}) has no neck, shank or holder to check")
        all_bodies = assembly.bodies()
        self.bodies = [all_bodies[i] for i in keep]
        self.names = [names[i] for i in keep]
        mesh, chord = face_mesh(face)
        self.points = SurfacePoints(mesh, surface_step)
        self.slack = self.points.error + chord
        (_, _, low), (_, _, high) = face.bounds
        size = assembly.cutter.diameter + 1.0   # a tip further than this from the face's box is off it
        self.z_range = (low - size, high + size)
        self.reach = max(math.hypot(z1, max(r0, r1)) + c for z0, z1, r0, r1, c in self.bodies)

    def worst(self, tips: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per pose: (intrusion, body, contact): how much closer than its clearance a body may come to the face
        (the sample's error added: > 0 is too close), which body, and the face point (NaN where none is)."""
        if not len(tips):
            return np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros((0, 3))
        v, b, c = self.points.worst(tips, axes, self.bodies, slack=self.slack)
        return v + self.slack, b, c


def put_down(positioner: Any, xy: np.ndarray, z0: np.ndarray, axes: np.ndarray, tol: float,
             z_range: tuple[float, float], threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(tips, ok): the torus with the fixed unit `axes` moved along Z over the tips' `xy` until the face's
    signed clearance from it is within 0..tol/2 (it touches, no gouge); z0 the first guess. The clearance falls
    at most 1 mm per mm down (1-Lipschitz): from above, a step of 1.5 times it reaches the contact or passes it
    (a bracket), then regula falsi with bisections inside the bracket.
    ok False: no face under the tool, the tip out of `z_range` (it fell past the face), or no convergence."""
    n = len(xy)
    z = np.asarray(z0, float).copy()
    lo, hi = np.full(n, -np.inf), np.full(n, np.inf)     # f(lo) < 0 <= f(hi)
    flo, fhi = np.full(n, np.nan), np.full(n, np.nan)
    done, ok = np.zeros(n, bool), np.zeros(n, bool)
    goal = tol / 2
    for it in range(DROP_ITERATIONS):
        todo = np.flatnonzero(~done)
        out = (z[todo] < z_range[0]) | (z[todo] > z_range[1])
        done[todo[out]] = True
        todo = todo[~out]
        if not len(todo):
            break
        tips = np.column_stack([xy[todo], z[todo]])
        f = np.asarray(positioner.clearance(tips, axes[todo], threads), float)
        off = ~np.isfinite(f)
        done[todo[off]] = True
        good = (f >= 0) & (f <= goal)
        done[todo[good]] = ok[todo[good]] = True
        for k, i in enumerate(todo):
            if off[k] or good[k]:
                continue
            if f[k] > 0:
                hi[i], fhi[i] = z[i], f[k]
            else:
                lo[i], flo[i] = z[i], f[k]
            if np.isfinite(lo[i]) and np.isfinite(hi[i]):
                if hi[i] - lo[i] < _BRACKET_MM:  # the clearance jumps here: no contact to stand on
                    done[i] = True
                    continue
                s = (fhi[i] - flo[i]) / (hi[i] - lo[i])
                t = hi[i] - (fhi[i] - goal / 2) / s if s > 0 else lo[i]
                # regula falsi, every third step a bisection (a curved clearance stalls it on one side)
                z[i] = t if lo[i] < t < hi[i] and it % 3 != 2 else 0.5 * (lo[i] + hi[i])
            elif f[k] > 0:
                z[i] -= 1.5 * f[k]  # past the contact when the clearance falls at its fastest rate, 1 per mm
            else:
                z[i] += 2.0 * (-f[k]) + tol
        cancel.poll()
    return np.column_stack([xy, z]), ok


def _turned(axes: np.ndarray, contacts: np.ndarray, tips: np.ndarray, turn: np.ndarray, aside: np.ndarray
            ) -> np.ndarray:
    """Each axis turned by `turn` (rad) away from its face point `contacts`, `aside` (rad) off the straight way
    (rows; the way away in XY where the face point lies on the axis)."""
    def across(d: np.ndarray) -> np.ndarray:
        return d - np.einsum("ij,ij->i", d, axes)[:, None] * axes

    d = across(contacts - tips)
    flat = np.linalg.norm(d, axis=1) < 1e-9
    if flat.any():
        xy = np.column_stack([(contacts - tips)[:, :2], np.zeros(len(d))])
        d[flat] = across(xy)[flat]
    n = np.linalg.norm(d, axis=1)
    none = n < 1e-12   # no way away told: any direction across the axis
    if none.any():
        ref = np.where(np.abs(axes[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
        d[none] = np.cross(axes, ref)[none]
        n = np.linalg.norm(d, axis=1)
    d = d / n[:, None]
    m = -np.cos(aside)[:, None] * d + np.sin(aside)[:, None] * np.cross(axes, d)
    a = np.cos(turn)[:, None] * axes + np.sin(turn)[:, None] * m
    return a / np.linalg.norm(a, axis=1, keepdims=True)


def _tilt(axes: np.ndarray) -> np.ndarray:
    return np.arctan2(np.hypot(axes[:, 0], axes[:, 1]), axes[:, 2])


def _try(positioner: Any, tool: WholeTool, tips: np.ndarray, axes: np.ndarray, contacts: np.ndarray,
         rows: np.ndarray, turn: np.ndarray, aside: np.ndarray, z0: np.ndarray, limits: tuple[float, float],
         tol: float, threads: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The candidates (rows of the poses, turn, aside; z0 the tips' first guess) within the tilt limits, put down:
    (candidate index, tip, axis) of those put down, and which of them keep every body clear."""
    a = _turned(axes[rows], contacts[rows], tips[rows], turn, aside)
    t = _tilt(a)
    k = np.flatnonzero((t >= limits[0] - 1e-12) & (t <= limits[1] + 1e-12))
    if not len(k):
        return k, np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, bool)
    put, down = put_down(positioner, tips[rows[k], :2], z0[k], a[k], tol, tool.z_range, threads)
    k, put = k[down], put[down]
    v, _, _ = tool.worst(put, a[k])
    return k, put, a[k], v <= 0


def tilt_away(positioner: Any, tool: WholeTool, tips: np.ndarray, axes: np.ndarray, contacts: np.ndarray,
              limits: tuple[float, float], tol: float, threads: int = 0
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(tips, axes, ok, turn) for colliding poses: the smallest turn away (module doc, TILT_STEP_DEG apart: the
    turns that clear can be a narrow window, a coarser search misses some) whose pose, put down on the face,
    keeps every body its clearance within the tilt `limits` (rad); ok False where none does."""
    n = len(tips)
    out_t, out_a = tips.copy(), axes.copy()
    ok, turn_of = np.zeros(n, bool), np.zeros(n)
    step = math.radians(TILT_STEP_DEG)
    asides = np.radians(ASIDE_DEG)
    z_last = np.repeat(tips[:, 2:3], len(asides), axis=1)  # the put-down height at the last turn: the next's guess
    for k in range(1, math.ceil(math.pi / 2 / step) + 1):
        for group in (np.arange(1), np.arange(1, len(asides))):  # straight away first: most clear there
            todo = np.flatnonzero(~ok)
            if not len(todo):
                break
            rows, which = np.repeat(todo, len(group)), np.tile(group, len(todo))
            turn = np.full(len(rows), k * step)
            cand, put, axis, clear = _try(positioner, tool, tips, axes, contacts, rows, turn, asides[which],
                                          z_last[rows, which], limits, tol, threads)
            z_last[rows[cand], which[cand]] = put[:, 2]
            for c, t, a in zip(cand[clear], put[clear], axis[clear]):
                i = rows[c]
                if not ok[i]:  # the first clear candidate, in ASIDE_DEG's order
                    ok[i], out_t[i], out_a[i], turn_of[i] = True, t, a, turn[c]
    return out_t, out_a, ok, turn_of


def _reason(res: Any, text: str) -> int:
    """The index of `text` in the results' reasons (appended once)."""
    if text not in res.reasons:
        res.reasons.append(text)
    return res.reasons.index(text)


def _set_poses(res: Any, rows: np.ndarray, tips: np.ndarray, axes: np.ndarray, Ri: float, reason: int) -> None:
    d = res.data
    d["tip"][rows], d["axis"][rows] = tips, axes
    d["centre"][rows] = tips + Ri * axes
    d["beta"][rows] = _tilt(axes)
    d["status"][rows], d["reason"][rows] = STATUS_ONE, reason


def _append(res: Any, src: np.ndarray, xy: np.ndarray, tips: np.ndarray, axes: np.ndarray, Ri: float,
            reason: int) -> np.ndarray:
    """New rows copied from rows `src` with the poses given; their indices."""
    base = len(res.xy)
    res.xy = np.vstack([res.xy, xy])
    res.passes = np.concatenate([res.passes, res.passes[src]])
    for key, arr in res.data.items():
        res.data[key] = np.concatenate([arr, arr[src]])
    rows = np.arange(base, base + len(src))
    _set_poses(res, rows, tips, axes, Ri, reason)
    return rows


def _split(runs: list[list[int]], cut: set[tuple[int, int]], gone: set[int]) -> list[list[int]]:
    """The runs without the rows `gone`, split at them and at the moves `cut` ((row, next row) pairs); runs of
    fewer than two positions dropped (a single position cuts nothing)."""
    out: list[list[int]] = []
    for run in runs:
        piece: list[int] = []
        for row in run:
            if row in gone or (piece and (piece[-1], row) in cut):
                if len(piece) >= 2:
                    out.append(piece)
                piece = [] if row in gone else [row]
                continue
            piece.append(row)
        if len(piece) >= 2:
            out.append(piece)
    return out


def _bad_moves(positioner: Any, tool: WholeTool, res: Any, runs: list[list[int]], changed: set[int],
               gouge_tol: float, threads: int) -> tuple[list[tuple[int, int, int]], int]:
    """((run, k, -) of the moves run[k] -> run[k+1] that bring a body too close, or, next to a changed position,
    gouge deeper than `gouge_tol`), and the poses sampled."""
    from tmm_workbench.core.strategies.multipoint_refine import move_deviation

    tips, axes, owner = [], [], []
    for r, run in enumerate(runs):
        tp = Toolpath()
        for row in run:
            tp.add(MoveKind.FEED, *res["tip"][row], axis=tuple(res["axis"][row]))
        t, a, move = sample_moves(tp, MOVE_STEP_MM, tool.reach)
        inner = move > 0
        tips.append(t[inner]), axes.append(a[inner])
        owner.append(np.column_stack([np.full(int(inner.sum()), r), move[inner] - 1]))
    if not tips:
        return [], 0
    t, a, own = np.vstack(tips), np.vstack(axes), np.vstack(owner)
    v, _, _ = tool.worst(t, a)
    bad = {(int(r), int(k)) for r, k in own[v > 0]}
    for r, run in enumerate(runs):
        for k in range(len(run) - 1):
            i, j = run[k], run[k + 1]
            if (r, k) in bad or not ({i, j} & changed):
                continue
            gouge, _ = move_deviation(positioner, res["tip"][i], res["axis"][i], res["tip"][j], res["axis"][j],
                                      (0.0, 0.0), threads)
            if gouge > gouge_tol:
                bad.add((r, k))
    return sorted(bad), len(t)


def guard(face: BezierFace, positioner: Any, params: Any, res: Any, runs: list[list[int]],
          progress: Optional[Callable[[float], bool]] = None) -> tuple[list[list[int]], MultipointHolderReport]:
    """The runs (row lists of `res`, a MultipointResults changed in place) made safe for params.assembly's
    neck, shank and holder (module doc), and the report."""
    mode = params.holder_collision
    if mode not in MODES:
        raise TmmError(f"holder collision for 5-axis multipoint must be one of {', '.join(map(repr, MODES))}, "
                       f"got {mode!r}")
    tool = WholeTool(face, params.assembly)
    limits = tilt_range(params.beta_max_deg, getattr(params, "machine", None))
    threads, tol = int(params.threads), float(params.tol)
    gouge_tol = float(params.between_tol) if params.between_tol > 0 else tol
    Ri = float(positioner.options.Ri)
    rows = np.array(sorted({i for run in runs for i in run}), dtype=np.int64)
    report = MultipointHolderReport(mode, len(rows), tilt_limits_deg=tuple(math.degrees(x) for x in limits),
                                    error=tool.slack)
    gone: set[int] = set()
    changed: set[int] = set()
    turns: list[float] = []
    with cancel.watching(progress):
        v, b, c = tool.worst(res["tip"][rows], res["axis"][rows])
        hit = v > 0
        names, counts = np.unique(np.array(tool.names, dtype=object)[b[hit]], return_counts=True)
        report.pieces = {str(n): int(k) for n, k in zip(names, counts)}
        bad_rows = rows[hit]
        if len(bad_rows) and mode == TILT:
            t, a, ok, turn = tilt_away(positioner, tool, res["tip"][bad_rows], res["axis"][bad_rows], c[hit],
                                       limits, tol, threads)
            _set_poses(res, bad_rows[ok], t[ok], a[ok], Ri, _reason(res, TILTED))
            changed.update(int(i) for i in bad_rows[ok])
            turns += list(turn[ok])
            report.tilted = int(ok.sum())
            bad_rows = bad_rows[~ok]
        gone.update(int(i) for i in bad_rows)
        runs = _split(runs, set(), gone)
        cut: set[tuple[int, int]] = set()
        for round_ in range(MAX_ROUNDS + 1):
            bad, sampled = _bad_moves(positioner, tool, res, runs, changed, gouge_tol, threads)
            report.samples += sampled
            if not bad:
                break
            if mode == LEAVE_OUT or round_ == MAX_ROUNDS:
                cut.update((runs[r][k], runs[r][k + 1]) for r, k in bad)
                break
            runs = _insert_halfway(positioner, tool, res, runs, bad, limits, tol, threads, Ri, changed, cut, turns,
                                   report)
            runs = _split(runs, cut, gone)
        runs = _split(runs, cut, gone)
    report.split_moves = len(cut)
    report.max_turn_deg = math.degrees(max(turns, default=0.0))
    held = np.array(sorted(gone), dtype=np.int64)
    if len(held):
        res.data["status"][held] = STATUS_FAILED
        res.data["reason"][held] = _reason(res, HOLDER)
    report.unreachable = res["tip"][held] if len(held) else np.zeros((0, 3))
    return runs, report


def _insert_halfway(positioner: Any, tool: WholeTool, res: Any, runs: list[list[int]], bad: list[tuple[int, int]],
                    limits: tuple[float, float], tol: float, threads: int, Ri: float, changed: set[int],
                    cut: set[tuple[int, int]], turns: list[float], report: MultipointHolderReport
                    ) -> list[list[int]]:
    """The pose halfway along each bad move (tip midway, axis by slerp) put down on the face, tilted away if
    it collides, inserted; a move whose halfway pose cannot be placed is cut."""
    i = np.array([runs[r][k] for r, k in bad])
    j = np.array([runs[r][k + 1] for r, k in bad])
    axes = np.vstack([slerp(res["axis"][a], res["axis"][b], np.array([0.5]))[0] for a, b in zip(i, j)])
    mid = 0.5 * (res["tip"][i] + res["tip"][j])
    tips, ok = put_down(positioner, mid[:, :2], mid[:, 2], axes, tol, tool.z_range, threads)
    v, _, c = tool.worst(tips, axes)
    hit = ok & (v > 0)
    if hit.any():
        t, a, clear, turn = tilt_away(positioner, tool, tips[hit], axes[hit], c[hit], limits, tol, threads)
        tips[hit], axes[hit] = t, a
        ok[np.flatnonzero(hit)[~clear]] = False
        turns += list(turn[clear])
    xy = 0.5 * (res.xy[i] + res.xy[j])
    new = np.full(len(bad), -1)
    if ok.any():
        new[ok] = _append(res, i[ok], xy[ok], tips[ok], axes[ok], Ri, _reason(res, INSERTED))
        changed.update(int(n) for n in new[ok])
        report.inserted += int(ok.sum())
    for (r, k), n, a, b in sorted(zip(bad, new, i, j), key=lambda t: (t[0][0], -t[0][1])):
        if n < 0:
            cut.add((int(a), int(b)))
        else:
            runs[r].insert(k + 1, int(n))
    return runs
