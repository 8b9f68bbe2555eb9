"""One waterline level, our side only: waterline_loops on a shared STL as waterline_bench.py --quick --all-tools
--chord-tol 0.003 --step 0.5 --min-step 0.05 calls it (62 % of the height), best of N calls, for comparing builds
in the same conditions on a shared machine (OpenCAMLib is not run).

    .venv/bin/python benchmarks/waterline_single_level.py [reps=30] [threads=2] [model=sphere_on_plate.stl]
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from drop_cutter_bench import STL_DIR  # noqa: E402

from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.query.waterline import waterline_loops  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402


def main() -> None:
    reps = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    model = sys.argv[3] if len(sys.argv) > 3 else "sphere_on_plate.stl"
    mesh = load_stl(STL_DIR / model)
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    z = float(lo[2] + 0.62 * (hi[2] - lo[2]))
    for name, cutter in (("ball d6", Cutter.ball(6.0)), ("flat d6", Cutter.flat(6.0)),
                         ("bull d10 r2", Cutter.bull(10.0, 2.0))):
        g = cutter.radius + 1.0
        bounds = (lo[0] - g, lo[1] - g, hi[0] + g, hi[1] + g)
        best = float("inf")
        for _ in range(reps):
            t = time.perf_counter()
            loops = waterline_loops(surface, cutter, [z], bounds, sample_step=0.5, chord_tol=0.003, threads=threads,
                                    min_step=0.05)[0]
            best = min(best, time.perf_counter() - t)
        # The same loops give the same point count and sum of coordinates.
        points = sum(len(lp.xy) for lp in loops)
        checksum = sum(float(np.abs(lp.xy).sum()) for lp in loops)
        print(f"{model} {name}: best {best * 1e3:.2f} ms of {reps} on {threads} threads, {len(loops)} loops, "
              f"{points} points, checksum {checksum:.9f}")


if __name__ == "__main__":
    main()
