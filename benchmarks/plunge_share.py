"""Cycle time spent plunging: the share of PLUNGE moves (fed at the vertical feed) in an op's cycle time, "before":
as main linked them (every entry fed from the safe height, every waterline loop lifted and entered), "after": the
rapid down ends core.linking's entry clearance above what is left (the stock simulation of the earlier ops kept
up to date as the op cuts, core.linking.StockHeights; the verification's partial passes from its own simulation)
and waterline loops starting near the end of the one above are reached with the tool down.
Each case also simulates the op on the stock the earlier ops left and counts rapids that cut (must be none).

    .venv/bin/python benchmarks/plunge_share.py            # the three cases at benchmark size
    .venv/bin/python benchmarks/plunge_share.py --quick    # the sizes tests/core/test_plunge_share.py runs

Cases: a spherical cavity in a block, roughed (flat D6) then waterlined (ball D4); a random height field (fixed
seed) roughed then waterlined; the sphere cavity finished by the adaptive raster with VerifyCusp (ball D4).
Feeds: 1000 mm/min horizontal, 300 mm/min vertical, rapids at core.sim.cycle_time's default.
"""
from __future__ import annotations

import argparse
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Optional

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry.mesh import TriMesh  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, StockHeights, link  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights  # noqa: E402
from tmm_workbench.core.strategies import raster_drop, waterline  # noqa: E402
from tmm_workbench.core.strategies import zlevel_rough as zr  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind, Toolpath  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

HORIZ, VERT = 1000.0 / 60.0, 300.0 / 60.0   # mm/s
SIM_CELL = 0.2                               # mm: the simulation that checks the rapids
KNOWN_CELL = 0.25                            # mm: the stock heights the linker is given (as the App's)


def grid_mesh(f: Callable[[np.ndarray, np.ndarray], np.ndarray], size: float, cells: int, name: str) -> TriMesh:
    """z = f(x, y) over [0, size]^2 as 2 cells^2 triangles."""
    g = np.linspace(0.0, size, cells + 1)
    x, y = np.meshgrid(g, g, indexing="ij")
    v = np.column_stack([x.ravel(), y.ravel(), f(x, y).ravel()])
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    a = (i * (cells + 1) + j).ravel()
    b, c, d = a + cells + 1, a + 1, a + cells + 2
    tri = np.vstack([np.column_stack([a, b, c]), np.column_stack([c, b, d])]).astype(np.int32)
    return TriMesh(v, tri, name)


def sphere_cavity(size: float = 40.0, cells: int = 80) -> TriMesh:
    """A block's top at z 0 with a spherical cavity (radius 0.45 size, centre 0.2 size above the top)."""
    r, c = 0.45 * size, 0.2 * size
    def f(x, y):
        d2 = (x - size / 2) ** 2 + (y - size / 2) ** 2
        return np.minimum(0.0, c - np.sqrt(np.maximum(r * r - d2, 0.0)))
    return grid_mesh(f, size, cells, "sphere cavity")


def random_field(size: float = 40.0, cells: int = 80, bumps: int = 12, seed: int = 7) -> TriMesh:
    """Gaussian bumps and dents of random place, width and height (numpy seed `seed`)."""
    rng = np.random.default_rng(seed)
    cx, cy = rng.uniform(0.1 * size, 0.9 * size, (2, bumps))
    w = rng.uniform(0.06 * size, 0.15 * size, bumps)
    h = rng.uniform(-6.0, 8.0, bumps)
    def f(x, y):
        return sum(h[k] * np.exp(-((x - cx[k]) ** 2 + (y - cy[k]) ** 2) / (2 * w[k] ** 2)) for k in range(bumps))
    return grid_mesh(f, size, cells, f"random field (seed {seed})")


def plunge_share(tp: Toolpath) -> tuple[float, float]:
    """(seconds of PLUNGE moves, seconds of the whole path) at HORIZ / VERT (core.sim.cycle_time)."""
    pts = tp.points()
    total = three_axis_time(pts, toolpath_feeds(tp, HORIZ, VERT)).seconds
    plunge = sum(three_axis_time(pts[k - 1:k + 1], [None, VERT]).seconds
                 for k, m in enumerate(tp.moves) if k and m.kind is MoveKind.PLUNGE)
    return plunge, total


@dataclass
class Row:
    case: str
    known: bool
    plunges: int
    plunge_s: float
    total_s: float
    rapid_hits: int
    seconds: float      # computing and linking

    @property
    def share(self) -> float:
        return self.plunge_s / self.total_s if self.total_s > 0 else 0.0

    def text(self) -> str:
        return (f"{self.case:<34} {'after' if self.known else 'before':<6} {self.plunges:>6} plunges "
                f"{self.plunge_s / 60:7.2f} of {self.total_s / 60:7.2f} min = {100 * self.share:5.1f} %  "
                f"rapids into stock {self.rapid_hits}  ({self.seconds:.1f} s)")


def _stock(mesh: TriMesh, above: float = 1.0) -> tuple:
    lo, hi = mesh.bounds
    return (float(lo[0]), float(lo[1]), float(lo[2]), float(hi[0]), float(hi[1]), float(hi[2]) + above)


def _rough(mesh: TriMesh, surface: DropSurface, box: tuple, grid: Grid) -> np.ndarray:
    """The stock after roughing (flat D6, step-down 2, 0.5 mm left): the heights the finishing op starts on."""
    tool = Cutter.flat(6)
    params = zr.RoughingParams(stock_box=box, step_down=2.0, stock_to_leave=0.5)
    tp = zr.compute_roughing_toolpath(mesh, tool, params, LinkPolicy(box[5] + 5, box[5] + 10), surface=surface)
    return simulate(tp, tool, grid, box_heights(grid, box[5])).heights


def roughed_then_waterlined(name: str, mesh: TriMesh, step_down: float = 0.5) -> list[Row]:
    """The waterline op's plunge share after roughing: entries blind and with the roughed stock known."""
    surface = DropSurface(mesh)
    box = _stock(mesh)
    grid = Grid.covering(box[0], box[1], box[3], box[4], SIM_CELL)
    roughed = _rough(mesh, surface, box, grid)
    tool = Cutter.ball(4)
    params = waterline.WaterlineParams(boundary=(box[0], box[1], box[3], box[4]), step_down=step_down,
                                       stock_z=(box[2], box[5]))
    t0 = time.perf_counter()
    result = waterline.compute(mesh, tool, params, surface=surface)
    t_compute = time.perf_counter() - t0
    rows = []
    for known in (False, True):
        t0 = time.perf_counter()
        material, segs = None, [replace(s, joined=False) for s in result.segments]   # before: every loop lifted
        if known:
            coarse = Grid.covering(box[0], box[1], box[3], box[4], KNOWN_CELL)
            material, segs = StockHeights(coarse, _rough(mesh, surface, box, coarse), tool), result.segments
        tp = link(segs, LinkPolicy(box[5] + 5, box[5] + 10, material_top=material))
        seconds = t_compute + time.perf_counter() - t0
        rows.append(_row(name, known, tp, tool, grid, roughed, seconds))
    return rows


def adaptive_verify(name: str, mesh: TriMesh) -> list[Row]:
    """The adaptive raster with VerifyCusp over the stock box (ball D4, cusp 0.01): its partial passes entered
    blind (entry_z dropped) and as the verification gives them (the surface it simulated)."""
    surface = DropSurface(mesh)
    box = _stock(mesh)
    tool = Cutter.ball(4)
    params = raster_drop.SurfaceParams(boundary=(box[0], box[1], box[3], box[4]), stepover_mode=raster_drop.ADAPTIVE,
                                       cusp=0.01, verify_cusp=True, off_model=raster_drop.OFF_MODEL_SKIP)
    t0 = time.perf_counter()
    result = raster_drop.compute(mesh, tool, params, surface=surface)
    seconds = time.perf_counter() - t0
    grid = Grid.covering(box[0], box[1], box[3], box[4], SIM_CELL)
    # the finishing starts on the model plus 0.5 mm (what a roughing and a semi-finish would leave)
    start = np.nan_to_num(surface.drop(Cutter.ball(1.0), grid.centres(), float(mesh.bounds[0][2]) - 1.0),
                          nan=box[2]).reshape(grid.ny, grid.nx) + 0.5
    rows = []
    for known in (False, True):
        segs = result.segments if known else [replace(s, entry_z=None) for s in result.segments]
        tp = link(segs, LinkPolicy(box[5] + 5, box[5] + 10))
        rows.append(_row(name, known, tp, tool, grid, start, seconds))
    return rows


def _row(name: str, known: bool, tp: Toolpath, tool: Cutter, grid: Grid, stock: np.ndarray,
         seconds: float) -> Row:
    plunge, total = plunge_share(tp)
    hits = len(simulate(tp, tool, grid, stock).collisions)
    plunges = sum(1 for m in tp.moves if m.kind is MoveKind.PLUNGE)
    return Row(name, known, plunges, plunge, total, hits, seconds)


def cases(quick: bool) -> list[Callable[[], list[Row]]]:
    size, cells = (30.0, 60) if quick else (60.0, 160)
    return [lambda: roughed_then_waterlined("sphere cavity, roughed + waterline", sphere_cavity(size, cells)),
            lambda: roughed_then_waterlined("random field, roughed + waterline", random_field(size, cells)),
            lambda: adaptive_verify("sphere cavity, adaptive + verify", sphere_cavity(size, cells))]


def main(argv: Optional[list[str]] = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="the test sizes")
    args = ap.parse_args(argv)
    for run in cases(args.quick):
        for row in run():
            print(row.text(), flush=True)


if __name__ == "__main__":
    main()
