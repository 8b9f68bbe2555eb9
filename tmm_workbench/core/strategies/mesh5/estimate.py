"""The work of a 5-axis mesh finish told before it runs (core.work): the passes from the tilted cutter's effective
width at the tolerance over the surface's slopes and curvatures, the CC points they hold, and the simulation of
what the finish leaves (the op's SimulateLeft).

Width. Where the tool's bottom stands on the surface at a lead tilt lambda (from the normal, along the feed), its
effective cutting profile across the feed is the bottom's ellipse, curving up as sin(lambda) / R; the surface's
section across curves up (concave) or down (convex) as kappa. The remaining height at y across is about
(sin(lambda) / R - kappa) y^2 / 2 (seed 000 eq. 3.22-3.33 for the flat end mill, to second order), so the half
width within the tolerance is sqrt(2 tau / (sin(lambda) / R - kappa)), at most R (the profile's end). The lead
tilt is the least one that keeps the bottom's heel (2 R behind its lowest point) off a surface curving up along
the feed (sin(lambda) >= R kappa_f) and its sides off one curving up across (sin(lambda) >= R kappa), within the
tilt limits. Where the surface's normal tilts near or past the machine's tilt limit C (the axis cannot follow it),
the tool leans back from the normal across the feed and the flat bottom finishes far less: there the half width is
the best of the op's postures the machine reaches over a parabola of that curvature (steep_halves). The width
across, seen from above, is the width on the surface x cos(slope across).

Passes. The planes are placed across the model as the step-over places them (step_replay.replay_planes: each next
plane half the GAP_QUANTILE of the widths the last pass finished beyond the least level it finished), on these
widths from a coarse needle sample of the model (core.query.height_sample.HeightSample, NaN off the model), per
node step along the feed (the step-over keeps a finished level per bin of the feed coordinate).
"""
from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np

from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.query.height_sample import CELLS, HeightSample
from tmm_workbench.core.machine.tarus import TarusMachine
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.stock import mesh_heights
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid, tool_rotation
from tmm_workbench.core.strategies.mesh5.step_replay import WidthField, replay_planes
from tmm_workbench.core.strategies.mesh5.stepover import MARGIN
from tmm_workbench.core.strategies.mesh5.top_bound import lower_profile
from tmm_workbench.core.tools.cutter import Cutter

STEEP_DEG = 3.0     # nodes whose normal tilts within this of the machine's tilt limit C or past it: steep_halves


def surface_sample(mesh: TriMesh, cells: int = CELLS) -> HeightSample:
    """The model's heights on a grid of `cells` nodes along its box's longer side (a needle drop: NaN off it)."""
    lo, hi = mesh.bounds
    step = max(float(hi[0] - lo[0]), float(hi[1] - lo[1]), 1e-6) / max(cells - 1, 1)
    grid = Grid.covering(float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]), step)
    return HeightSample(grid.xs(), grid.ys(), mesh_heights(mesh, grid))


def lead_tilt(cutter: Cutter, along: np.ndarray, across: np.ndarray, tilt_deg: tuple[float, float]) -> np.ndarray:
    """sin of the least lead tilt at each node: the bottom's heel clear of the section along the feed curving up
    (curvature `along`, 1/mm, > 0 concave) and its sides of the one across (`across`), within `tilt_deg`."""
    lo, hi = (math.sin(math.radians(t)) for t in tilt_deg)
    need = cutter.radius * np.maximum(along, across)
    return np.clip(need, lo, hi)


def pass_widths(sample: HeightSample, cutter: Cutter, tolerance: float, feed_angle_deg: float,
                tilt_deg: tuple[float, float]) -> np.ndarray:
    """(ny, nx) the width across the feed, seen from above, that one pass finishes within `tolerance` at each
    node (module doc; NaN off the model and at its rim)."""
    along_slope, slope = sample.slopes(feed_angle_deg)
    across = sample.curvature(feed_angle_deg)            # the section across the passes
    along = sample.curvature(feed_angle_deg - 90.0)      # the section along the feed
    sin_lead = lead_tilt(cutter, along, across, tilt_deg)
    bend = sin_lead / cutter.radius - across             # the profile over the section, per y^2 / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        wide = np.where(np.isnan(bend), np.nan, np.inf)       # off the model / no curvature left to bound it
        half = np.where(bend > 0, np.sqrt(2.0 * MARGIN * tolerance / bend), wide)
    half = np.minimum(half, cutter.radius)
    theta = np.arctan(np.hypot(along_slope, slope))
    steep = np.isfinite(half) & np.isfinite(across) & (theta > TarusMachine().c_limits[1] - math.radians(STEEP_DEG))
    if steep.any():
        half[steep] = np.minimum(half[steep], steep_halves(cutter, MARGIN * tolerance, tilt_deg, across[steep],
                                                           along[steep], _vertical(sample, feed_angle_deg)[steep]))
    return 2.0 * half / np.sqrt(1.0 + slope * slope)


def _vertical(sample: HeightSample, feed_angle_deg: float) -> np.ndarray:
    """(ny, nx, 3) the world's Z in each node's LCS (LX along the feed on the surface, LZ its normal; LY's sign
    left out: the posture grid's yaw is symmetric)."""
    gy, gx = np.gradient(sample.z, max(sample.step, 1e-9))
    a = math.radians(feed_angle_deg)
    g_along = gx * math.cos(a) + gy * math.sin(a)
    lx = g_along / np.sqrt(1.0 + g_along ** 2)
    lz = 1.0 / np.sqrt(1.0 + gx ** 2 + gy ** 2)
    return np.stack([lx, np.sqrt(np.clip(1.0 - lx ** 2 - lz ** 2, 0.0, 1.0)), lz], axis=-1)


def steep_halves(cutter: Cutter, tolerance: float, tilt_deg: tuple[float, float], kappa: np.ndarray,
                 kappa_along: np.ndarray, vertical: np.ndarray) -> np.ndarray:
    """(n,) half-widths within `tolerance` at n nodes whose normal tilts near or past the machine's tilt limit C:
    the best narrower side of the op's postures (the default grid within `tilt_deg`) whose axis the machine
    reaches (`vertical` (n, 3): the world's Z in the node's LCS) and whose lead along the feed keeps the bottom's
    heel off the section along it (curving as `kappa_along`), over the section across (a parabola curving as
    `kappa`; the bottom's profile lifted clear of it; linear between 17 curvatures)."""
    lam, omg = (g.ravel() for g in PostureGrid.degrees(tilt_deg).mesh())
    py, pz = lower_profile(cutter, lam, omg, 401)
    axis = tool_rotation(lam, omg)[:, 2, :]
    ys = np.linspace(0.0, 2.0 * cutter.radius, 101)
    lateral = np.concatenate([ys, -ys[1:]])
    Z = np.array([np.interp(lateral, py[p], pz[p], left=np.inf, right=np.inf) for p in range(len(lam))])
    ks = np.linspace(float(kappa.min()), float(kappa.max()) + 1e-12, 17)
    table = np.zeros((len(ks), len(lam)))
    for i, k in enumerate(ks):
        s = 0.5 * k * lateral ** 2
        h = Z + np.maximum(np.max(np.where(np.isfinite(Z), s - Z, -np.inf), axis=1), 0.0)[:, None] - s
        sides = []
        for sl in (slice(0, len(ys)), np.r_[0, len(ys):len(lateral)]):
            over = ~(h[:, sl] <= tolerance)
            first = np.where(over.any(axis=1), over.argmax(axis=1), len(ys))
            sides.append(np.where(first > 0, ys[np.maximum(first - 1, 0)], 0.0))
        table[i] = np.minimum(*sides)
    u = np.clip((kappa - ks[0]) / (ks[1] - ks[0]), 0, len(ks) - 1.001)
    i = u.astype(np.int64)
    half = (1 - (u - i))[:, None] * table[i] + (u - i)[:, None] * table[i + 1]          # (n, P)
    reached = (vertical @ axis.T >= math.cos(TarusMachine().c_limits[1]) - 1e-9) & \
        (axis[None, :, 0] >= cutter.radius * kappa_along[:, None] - 1e-9)
    return np.where(reached, half, 0.0).max(axis=1)


def width_field(sample: HeightSample, cutter: Cutter, tolerance: float, feed_angle_deg: float,
                tilt_deg: tuple[float, float]) -> Optional[WidthField]:
    """The half-widths one pass finishes (pass_widths / 2, both sides alike) on the model's nodes, binned a node
    step apart along the drive planes' normal and the feed (WidthField.binned: the model's rim, with no
    curvature, the nearest inner width across). None where the sample holds no width."""
    w = pass_widths(sample, cutter, tolerance, feed_angle_deg, tilt_deg)
    model = np.isfinite(sample.z)
    if not np.isfinite(w[model]).any():
        return None
    a = math.radians(feed_angle_deg)
    X, Y = np.meshgrid(sample.xs, sample.ys)
    m, f = -X * math.sin(a) + Y * math.cos(a), X * math.cos(a) + Y * math.sin(a)
    step = max(sample.step, 1e-9)
    return WidthField.binned(m[model], f[model], 0.5 * w[model], step, step)


def predict_passes(sample: HeightSample, cutter: Cutter, tolerance: float, feed_angle_deg: float,
                   tilt_deg: tuple[float, float], forward_step: float = 2.0) -> Optional[int]:
    """The passes across the sampled model, None when the sample holds no width (a model smaller than its
    nodes): the step-over's step control (step_replay.replay_planes) on the widths of width_field.
    `forward_step`: the op's (Mesh5Params.forward_step)."""
    field = width_field(sample, cutter, tolerance, feed_angle_deg, tilt_deg)
    if field is None:
        return None
    lo, hi = field.extent()
    return len(replay_planes(field, lo, hi, cutter.radius, field.dm, forward_step)) or None


def climb(sample: HeightSample, feed_angle_deg: float) -> float:
    """How much longer the passes are on the model than seen from above (the mean of 1 / cos(slope along))."""
    along, _ = sample.slopes(feed_angle_deg)
    ok = np.isfinite(along)
    return float(np.mean(np.sqrt(1.0 + along[ok] ** 2))) if ok.any() else 1.0


def left_cells(bounds: Any, cell: float) -> float:
    """The cells of the simulation of what the finish leaves (mesh5.cleanup.cleanup_grid: the box and 1 mm)."""
    return (float(bounds[3] - bounds[0]) + 2.0) * (float(bounds[4] - bounds[1]) + 2.0) / (cell * cell)


def left_paces(bounds: Any, cell: float, cut_length: float, cutter: Cutter) -> tuple[tuple[str, float], ...]:
    """The compute of the simulation of what the finish leaves (mesh5.cleanup.left_above) as pace rows
    (core.work): the design's heights per cell, and the cut per mm travelled over the cells under the tool."""
    return (("mesh5_left_cells", left_cells(bounds, cell)),
            ("mesh5_left_cut", cut_length * (cutter.diameter / cell) ** 2))
