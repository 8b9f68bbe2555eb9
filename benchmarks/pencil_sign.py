"""Seed 003's pencil experiment (section 4.5) on a sign of our own (tests/core/sign.py: a board with a raised border
and raised letters): finish with a radiused cutter, then pencil with a small ball along the letters' outlines and
the border's inner edge; against the finish alone and a finish of the whole sign with the small ball. Printed side
by side with the seed (average scallop 0.0711 -> 0.0399 mm, a ratio of 0.56; 150 -> 95 minutes): the average and
largest scallop over the board (the design cells, simulated on 0.1 mm cells), feed length and cycle time (feed
1000 mm/min, plunge 300, rapid 5000).

Run: OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/pencil_sign.py
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.core.sign import HEIGHT, RELIEF, WIDTH, outlines, sign_mesh  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.sim.grid import Grid  # noqa: E402
from tmm_workbench.core.sim.simulate import simulate  # noqa: E402
from tmm_workbench.core.sim.stock import box_heights, mesh_heights  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.surface.params import SurfaceParams  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

FEED, PLUNGE, RAPID = 1000 / 60, 300 / 60, 5000 / 60
RADIUSED, BALL = Cutter.bull(6.0, 1.5), Cutter.ball(1.5)
BOX = (0.0, 0.0, WIDTH, HEIGHT)


def experiment() -> dict:
    """The three jobs simulated: {name: (average scallop, largest, feed length, seconds)}, and the gouge."""
    mesh = sign_mesh()
    grid = Grid.covering(*BOX, 0.1)
    design = mesh_heights(mesh, grid)
    stock = box_heights(grid, RELIEF + 1.0)
    policy = LinkPolicy(RELIEF + 3, RELIEF + 6)

    def run(cutter, params, start):
        tp = link(raster_drop.compute(mesh, cutter, params).segments, policy)
        after = simulate(tp, cutter, grid, start).heights
        t = three_axis_time(tp.points(), toolpath_feeds(tp, FEED, PLUNGE), RAPID, RAPID)
        return tp, after, t

    finish = SurfaceParams(boundary=BOX, stepover=2 * math.sqrt(2 * 1.5 * 0.06), sample_step=0.25)
    _, fin, t_fin = run(RADIUSED, finish, stock)
    pencil = SurfaceParams(boundary=BOX, pattern="pencil", pencil_source="outline", pencil_curves=outlines(),
                           pencil_side="inside", pencil_passes=3, stepover=0.5, sample_step=0.25)
    _, pen, t_pen = run(BALL, pencil, fin)
    small = SurfaceParams(boundary=BOX, stepover=2 * math.sqrt(2 * 0.75 * 0.04), sample_step=0.25)
    _, whole, t_small = run(BALL, small, stock)

    def scallop(h):
        d = (h - design)[np.isfinite(design)]
        return float(np.mean(np.clip(d, 0, None))), float(d.max()), float(d.min())

    out = {}
    for name, h, t in (("finish (radiused D6 r1.5)", fin, t_fin), ("finish + pencil (ball D1.5)", pen, None),
                       ("whole sign, ball D1.5", whole, t_small)):
        mean, top, low = scallop(h)
        if t is None:
            length, seconds = t_fin.cutting_length + t_pen.cutting_length, t_fin.seconds + t_pen.seconds
        else:
            length, seconds = t.cutting_length, t.seconds
        out[name] = (mean, top, low, length, seconds)
    return out


def main() -> None:
    rows = experiment()
    print(f"{'job':30s} {'avg scallop':>11s} {'max':>8s} {'min dev':>8s} {'feed mm':>9s} {'cycle min':>9s}")
    for name, (mean, top, low, length, seconds) in rows.items():
        print(f"{name:30s} {mean:11.4f} {top:8.3f} {low:8.4f} {length:9.0f} {seconds / 60:9.1f}")
    (fin, *_), (pen, *_) = list(rows.values())[:2]
    t_pen, t_small = list(rows.values())[1][4], list(rows.values())[2][4]
    print(f"pencil's ratio of the average scallop {pen / fin:.2f} (seed 003: 0.0399 / 0.0711 = 0.56); finish + "
          f"pencil {t_pen / 60:.1f} min against the whole sign with the small ball {t_small / 60:.1f} min "
          f"(seed: 95 against 150 min)")


if __name__ == "__main__":
    main()
