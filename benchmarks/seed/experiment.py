"""Seed 001's experiment (Singh 2020, section 5.1), reproduced: multipoint tool paths (VCRF, DRD) on the convex
and concave bicubic Bézier patches, simulated with a z-map, deviations at the section y = 27 mm.

Footprint, as the seed describes it (5.1): XY parallel passes along Y (the feed), side step along X; the first
nine passes 18 mm apart from x = 0 (x = 0, 18, ..., 144) and the tenth at x = 150 (a 6 mm strip: the seed
keeps 18 mm and squeezes the last pass in); each pass 76 effective positions y = 0, 2, ..., 150 (the seed's 78
positions per pass less the first and last, which only lift the tool: 760 effective positions). The passes
alternate direction (zigzag; the seed's figure 2.3 is not explicit, and the direction does not change the
simulated section). `multipoint_footprint` (core.multipoint) spreads its passes evenly instead (10 passes
150 / 9 = 16.7 mm apart), so the positions are computed here at this explicit footprint with
`position_points`.

The swept tool is simulated by the Python z-map (tests/core/zmap_reference.py) on a line of needles at
y = section_y (exact line-tool solves, sub-steps halved until the section changes by less than verify_tol),
0.25 mm apart, then refined around the
local maxima above 0.05 mm (the scallop peaks are cusps) and the lowest local minima: needles 0.025 mm apart over
+-0.25 mm, then 0.001 mm apart over +-0.025 mm. Deviation = simulated height minus
the design height at the same (x, y); the seed patches have control points at x = 50 i, y = 50 j, evenly
spaced, so x(u) = 150 u and y(v) = 150 v (linear precision of the Bernstein basis) and the design height is
S_z(x / 150, y / 150), exact.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

from tmm_workbench.core.geometry.bezier import evaluate, load_seed_patch
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.strategies.multipoint import STATUS_FAILED, BezierFace, MultipointParams, MultipointResults, position_points
from tmm_workbench.core.shared_data import benchmark_file


RO, RI = 6.7, 6.0
PASSES_X = tuple([18.0 * k for k in range(9)] + [150.0])
FORWARD_STEP = 2.0
Y_RANGE = (0.0, 150.0)

# The seed's Tables 2-3 (simulated / machined, mm), at the section y = 27.
SEED_SIMULATED_MAX = {("convex", "drd"): 0.54, ("concave", "drd"): 0.92, ("saddle", "drd"): 0.79,
                      ("convex", "vcrf"): 0.53, ("concave", "vcrf"): 0.60, ("saddle", "vcrf"): 0.62}
SEED_SIMULATED_MIN = {("convex", "drd"): 2.9e-5, ("concave", "drd"): 1.4e-3, ("saddle", "drd"): 2.4e-5,
                      ("convex", "vcrf"): 1.1e-6, ("concave", "vcrf"): 1.3e-6, ("saddle", "vcrf"): 9.0e-7}
SEED_MACHINED_MAX = {("convex", "drd"): 0.57, ("concave", "drd"): 1.00, ("saddle", "drd"): 0.86,
                     ("convex", "vcrf"): 0.51, ("concave", "vcrf"): 0.70, ("saddle", "vcrf"): 0.72}
GOUGE_LIMIT = -0.01

# Kernel option sets measured by benchmarks/seed/run_experiment.py (MultipointParams fields; everything else
# default). "seed": as the seed describes it. "extend": the face continued past its edges by the tool's
# radius Ro + Ri (a pass over the boundary rests on the continued surface, not on the boundary curve).
# "extend+tip": that, and the tilted tool's tip (not its pre-tilt axis) on the footprint point, so the
# passes' tips lie exactly on x = 0, 18, ..., 144, 150.
CONFIGS = {
    "seed": {},
    "extend": {"extend": RO + RI},
    "extend+tip": {"extend": RO + RI, "anchor": "tip"},
}


def seed_json_path() -> Path:
    return benchmark_file("seed_surfaces.json")


def seed_footprint(passes_x: Sequence[float] = PASSES_X, y_range=Y_RANGE, forward_step: float = FORWARD_STEP,
                   zigzag: bool = True) -> list[np.ndarray]:
    """The seed's passes: one (k, 2) array per pass along Y at the given x."""
    y0, y1 = y_range
    k = int(round((y1 - y0) / forward_step))
    ys = np.linspace(y0, y1, k + 1)
    out = []
    for i, x in enumerate(passes_x):
        yy = ys[::-1] if (zigzag and i % 2 == 1) else ys
        out.append(np.column_stack([np.full(len(yy), float(x)), yy]))
    return out


def design_height(net: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Design height at (x, y): exact for nets whose x, y control coordinates are evenly spaced along i, j
    (then x(u), y(v) are linear); other nets are refused."""
    m, n = net.shape[0] - 1, net.shape[1] - 1
    xs, ys = net[:, 0, 0], net[0, :, 1]
    lin = (np.allclose(net[:, :, 0], xs[:, None]) and np.allclose(net[:, :, 1], ys[None, :])
           and np.allclose(np.diff(xs), (xs[-1] - xs[0]) / m) and np.allclose(np.diff(ys), (ys[-1] - ys[0]) / n))
    if not lin:
        raise TmmError("design_height needs a net with x(u), y(v) linear (evenly spaced control x and y)")
    u = (np.asarray(x, float) - xs[0]) / (xs[-1] - xs[0])
    v = (np.asarray(y, float) - ys[0]) / (ys[-1] - ys[0])
    return evaluate(net, u, v)[..., 2]


@dataclass
class SectionResult:
    which: str
    method: str
    x: np.ndarray                    # needle x (sorted), at y = section_y
    deviation: np.ndarray            # simulated minus design, mm
    max_dev: float
    min_dev: float
    n_positions: int
    statuses: dict                   # {"two": n, "one": n, "failed": n}
    time_s: float                    # tool path computation (positioning), s
    sim_time_s: float = 0.0
    x_at_max: float = float("nan")
    x_at_min: float = float("nan")
    section_y: float = 27.0
    refine: int = 1                  # sub-step refinement reached by the z-map
    last_change: float = float("nan")  # its last change on the section (mm)
    max_step: float = 0.25
    spacing: float = 0.25
    interior: tuple = (float("nan"), float("nan"))   # x range between the passes whose tool stays over the
    max_dev_interior: float = float("nan")           # patch; the max deviation there (edge strips excluded)
    x_at_max_interior: float = float("nan")
    results: Optional[MultipointResults] = field(default=None, repr=False)
    label: str = "seed"              # the configuration (kernel options) the positions were computed with

    @property
    def seed_max(self) -> float:
        return SEED_SIMULATED_MAX[(self.which, self.method)]

    @property
    def target_met(self) -> bool:
        return self.max_dev <= self.seed_max + 1e-12 and self.min_dev >= GOUGE_LIMIT


def tool_paths(res: MultipointResults, passes: Sequence[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Runs of consecutive good positions within each pass (the tool leaves the material around failed
    positions and between passes: vertical lifts and plunges, and rapids above the stock, cut nothing new)."""
    tip, axis, status = res["tip"], res["axis"], res["status"]
    out = []
    i0 = 0
    for p in passes:
        idx = np.arange(i0, i0 + len(p))
        i0 += len(p)
        run: list[int] = []
        for i in idx:
            if status[i] == STATUS_FAILED:
                if run:
                    out.append((tip[run], axis[run]))
                run = []
            else:
                run.append(int(i))
        if run:
            out.append((tip[run], axis[run]))
    return out


def run_experiment(which: str = "convex", method: str = "vcrf", section_y: float = 27.0,
                   passes_x: Sequence[float] = PASSES_X, y_range=Y_RANGE, forward_step: float = FORWARD_STEP,
                   params: Optional[MultipointParams] = None, spacing: float = 0.25, max_step: float = 0.25,
                   verify_tol: float = 1e-3, peak_spacing: float = 0.001, refine_minima: int = 6,
                   peak_floor: float = 0.05,
                   interp: str = "slerp",
                   x_range: Optional[tuple[float, float]] = None, json_path: Optional[Path] = None,
                   positions: Optional[tuple[MultipointResults, list]] = None) -> SectionResult:
    """Position the tool at the seed's footprint, simulate, and measure the section y = section_y over
    x_range (default: the patch, 0..150). `positions`: (results, passes) computed elsewhere (the scallop
    placement: `passes_x` are then its pass offsets), simulated instead of positioning at the footprint."""
    if which not in ("convex", "concave", "saddle"):
        raise TmmError(f"surface must be 'convex', 'concave' or 'saddle', got {which!r}")
    if method not in ("vcrf", "drd"):
        raise TmmError(f"method must be 'vcrf' or 'drd', got {method!r}")
    net = load_seed_patch(json_path or seed_json_path(), which)
    face = BezierFace.from_net(net, name=f"seed {which}")
    params = params or MultipointParams()
    if positions is None:
        passes = seed_footprint(passes_x, y_range, forward_step)
        xy = np.vstack(passes)
        t0 = time.perf_counter()
        res = position_points(face, RO, RI, xy, params, method)
        t_pos = time.perf_counter() - t0
    else:
        res, passes = positions
        xy, t_pos = res.xy, float("nan")
    counts = res.counts()
    # imported here, not at the top: the z-map is test code, and the wheel and sanitizer runs copy only part of
    # tests/ while a test of theirs imports seed_footprint from this module
    from tests.core.zmap_reference import ZTool, simulate

    tool = ZTool(RO, RI, params.shape)
    paths = tool_paths(res, passes)
    x0, x1 = x_range if x_range is not None else (float(net[0, 0, 0]), float(net[-1, 0, 0]))
    n = max(2, int(round((x1 - x0) / spacing)) + 1)
    xs = np.linspace(x0, x1, n)
    t1 = time.perf_counter()
    zd = design_height(net, xs, np.full_like(xs, section_y))
    stock = float(zd.max()) + 5.0
    rep = simulate(tool, np.column_stack([xs, np.full_like(xs, section_y)]), stock, paths, max_step, interp,
                   verify_tol)
    dev = rep.z - zd
    change = rep.last_change
    # The scallop peaks are cusps and gouges may be narrow: refine around the local maxima (every one above
    # peak_floor, or above half the largest if that is lower) and the lowest local minima, twice: +-spacing at
    # spacing / 10, then +-spacing / 10 at peak_spacing. Needles are independent: the refined ones are
    # simulated on their own.
    for half, step in ((spacing, spacing / 10.0), (spacing / 10.0, peak_spacing)):
        order = np.argsort(xs, kind="stable")
        xs, dev = xs[order], dev[order]
        inner = (xs > x0) & (xs < x1)
        up = inner & (dev >= np.roll(dev, 1)) & (dev >= np.roll(dev, -1))
        down = inner & (dev <= np.roll(dev, 1)) & (dev <= np.roll(dev, -1))
        peaks = np.flatnonzero(up & (dev >= min(peak_floor, 0.5 * dev.max())))
        lows = np.flatnonzero(down)
        lows = lows[np.argsort(dev[lows])[:refine_minima]]
        centres = np.concatenate([xs[peaks], xs[lows], [xs[int(np.argmax(dev))], xs[int(np.argmin(dev))]]])
        xe = np.unique(np.concatenate([np.arange(c - half, c + half + 1e-12, step) for c in centres]))
        xe = xe[(xe >= x0) & (xe <= x1)]
        ze = design_height(net, xe, np.full_like(xe, section_y))
        rep2 = simulate(tool, np.column_stack([xe, np.full_like(xe, section_y)]), stock, paths, max_step,
                        interp, verify_tol)
        xs = np.concatenate([xs, xe])
        dev = np.concatenate([dev, rep2.z - ze])
        change = max(change, rep2.last_change)
    order = np.argsort(xs, kind="stable")
    xs, dev = xs[order], dev[order]
    t_sim = time.perf_counter() - t1
    i_max, i_min = int(np.argmax(dev)), int(np.argmin(dev))
    # Interior strips: between passes whose tool (radius Ro + Ri) stays over the patch in x; a pass nearer the
    # edge can rest on the patch's boundary curve (concave patch: the boundary is the highest line).
    px = sorted(float(x) for x in passes_x if x - RO - RI >= x0 - 1e-9 and x + RO + RI <= x1 + 1e-9)
    px_all = sorted(float(x) for x in passes_x)
    interior = (px[0], px[-1]) if len(px) >= 2 else (px_all[0], px_all[-1])
    inside = (xs >= interior[0]) & (xs <= interior[1])
    j = int(np.flatnonzero(inside)[np.argmax(dev[inside])]) if inside.any() else i_max
    return SectionResult(which, method, xs, dev, float(dev[i_max]), float(dev[i_min]), len(xy), counts, t_pos,
                         t_sim, float(xs[i_max]), float(xs[i_min]), section_y, rep.refine, change, max_step,
                         spacing, interior, float(dev[j]), float(xs[j]), res)


def _finish_axes(ax, title: str, legend_loc: str) -> None:
    """The zero line, the gouge limit, title, labels, grid and legend of a section panel."""
    ax.axhline(0.0, color="k", lw=0.6)
    ax.axhline(GOUGE_LIMIT, color="red", lw=0.6, ls=":", label="gouge limit -0.01 mm")
    ax.set_title(title)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("deviation (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc=legend_loc)


def _save(fig, path) -> Path:
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=130)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return out


def section_plot(results: Sequence[SectionResult], path) -> Path:
    """Deviation along x at the section for each surface (one panel each) and method, with the seed's
    published simulated maxima as reference lines."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    surfaces = [w for w in ("convex", "concave") if any(r.which == w for r in results)]
    fig, axs = plt.subplots(len(surfaces), 1, figsize=(10, 3.6 * len(surfaces)), squeeze=False)
    colours = {"vcrf": "tab:blue", "drd": "tab:orange"}
    widths = {"drd": 2.4, "vcrf": 0.9}   # DRD drawn wide underneath: where the two coincide both show
    for ax, w in zip(axs[:, 0], surfaces):
        for r in results:
            if r.which != w:
                continue
            c = colours.get(r.method, None)
            ax.plot(r.x, r.deviation, lw=widths.get(r.method, 1.0), color=c, alpha=0.9,
                    label=f"{r.method.upper()}: max {r.max_dev:.3f} mm (between x = {r.interior[0]:g} and "
                          f"{r.interior[1]:g}: {r.max_dev_interior:.3f}), min {r.min_dev:+.4f} mm")
            ax.axhline(SEED_SIMULATED_MAX[(w, r.method)], color=c, ls="--", lw=0.8,
                       label=f"seed {r.method.upper()} simulated max {SEED_SIMULATED_MAX[(w, r.method)]:.2f} mm")
        r0 = next(r for r in results if r.which == w)
        if np.isfinite(r0.interior[0]):
            for xb in r0.interior:
                ax.axvline(xb, color="grey", lw=0.6, ls="-.")
        _finish_axes(ax, f"{w} patch, section y = {results[0].section_y:g} mm: simulated (z-map) minus design "
                         f"height", "upper right")
    return _save(fig, path)


def options_plot(results: Sequence[SectionResult], path, method: str = "vcrf") -> Path:
    """Deviation along x at the section for each surface (one panel each), one line per configuration
    (SectionResult.label), for one method; the seed's simulated maximum dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sel = [r for r in results if r.method == method]
    surfaces = [w for w in ("convex", "concave") if any(r.which == w for r in sel)]
    fig, axs = plt.subplots(len(surfaces), 1, figsize=(10, 3.8 * len(surfaces)), squeeze=False)
    colours = ["tab:blue", "tab:green", "tab:red", "tab:purple", "tab:orange"]
    for ax, w in zip(axs[:, 0], surfaces):
        labels = [r.label for r in sel if r.which == w]
        for r in sel:
            if r.which != w:
                continue
            k = labels.index(r.label)
            c = colours[k % len(colours)]
            # earlier configurations drawn wider underneath: where two coincide both show
            ax.plot(r.x, r.deviation, lw=max(0.9, 2.6 - 0.8 * k), color=c, alpha=0.9, zorder=2 + k,
                    label=f"{r.label}: max {r.max_dev:.3f} mm (x {r.interior[0]:g}..{r.interior[1]:g}: "
                          f"{r.max_dev_interior:.3f}), min {r.min_dev:+.4f} mm")
        ax.axhline(SEED_SIMULATED_MAX[(w, method)], color="k", ls="--", lw=0.8,
                   label=f"seed {method.upper()} simulated max {SEED_SIMULATED_MAX[(w, method)]:.2f} mm")
        ax.set_ylim(-0.1, max(1.0, max(r.max_dev for r in sel if r.which == w) + 0.1))
        _finish_axes(ax, f"{w} patch, {method.upper()}, section y = {sel[0].section_y:g} mm: simulated minus "
                         f"design", "upper center")
    return _save(fig, path)
