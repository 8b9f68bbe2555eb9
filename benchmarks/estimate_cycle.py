"""How close the Surface's told cutting time is to the path it then computes, per spacing mode and region.

    .venv/bin/python benchmarks/estimate_cycle.py            # mount_rush and sphere_on_plate (~20 min cold)
    .venv/bin/python benchmarks/estimate_cycle.py --cache F  # reuse the computed paths' times kept in F (JSON)

Per model, region (the box, two circles) and mode (step-over 1 mm, cusp 0.01 mm by the section rule, adaptive,
3D offset): the estimate's cutting time (core.strategies.surface.estimate with the model's coarse height sample,
as the panel tells it once the model is at hand) against the computed path's, both at 1000 mm/min with moves down
slopes steeper than 45 deg at the plunge feed 300 mm/min (as the op writes them); and the estimate from the boxes
and the region's area alone (the model not at hand: a Part model before its first computation). Ball D6, sample step 0.5 mm, lean
passes ('tolerance'). The target: ratios in 0.6-1.6.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core import polygons  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.query.drop import DropSurface  # noqa: E402
from tmm_workbench.core.query.height_sample import sample_heights  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies import raster_drop  # noqa: E402
from tmm_workbench.core.strategies.surface.estimate import estimate_work  # noqa: E402
from tmm_workbench.core.strategies.surface.params import SurfaceParams  # noqa: E402
from tmm_workbench.core.toolpath import MoveKind, Toolpath  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

FEED, PLUNGE_FEED, PLUNGE_DEG = 1000 / 60, 300 / 60, 45.0   # mm/s, deg
MODES = ("stepover", "cusp", "adaptive", "offset3d")


def path_seconds(tp: Toolpath) -> float:
    """The cutting time of a linked path: plunges and moves down steeper than PLUNGE_DEG at the plunge feed."""
    pts, t = tp.points(), 0.0
    steep = math.tan(math.radians(PLUNGE_DEG))
    for k in range(1, len(tp.moves)):
        m = tp.moves[k]
        if m.kind is MoveKind.RAPID:
            continue
        d = pts[k] - pts[k - 1]
        down = m.kind is MoveKind.PLUNGE or -d[2] > steep * math.hypot(d[0], d[1])
        t += float(np.linalg.norm(d)) / (PLUNGE_FEED if down else FEED)
    return t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", default="", help="JSON file keeping the computed paths' times")
    args = ap.parse_args()
    cache = Path(args.cache) if args.cache else None
    real = json.loads(cache.read_text()) if cache and cache.exists() else {}
    cutter = Cutter.ball(6.0)
    print(f"{'model, region, mode':44s} {'path':>8s} {'told':>8s} {'ratio':>6s} {'no model':>10s} {'ratio':>6s}")
    inside = 0
    for model in ("mount_rush.stl", "sphere_on_plate.stl"):
        mesh = load_stl(benchmark_file("stl", model))
        lo, hi = mesh.bounds
        surface = DropSurface(mesh)
        w, h = hi[0] - lo[0], hi[1] - lo[1]
        regions = {"box": None,
                   "circle A": [polygons.circle((lo[0] + 0.65 * w, lo[1] + 0.5 * h), 0.15 * min(w, h))],
                   "circle B": [polygons.circle((lo[0] + 0.3 * w, lo[1] + 0.35 * h), 0.22 * min(w, h))]}
        for rname, region in regions.items():
            box = (lo[0], lo[1], hi[0], hi[1]) if region is None else polygons.bounds(region)
            sample = sample_heights(surface, cutter, box, float(lo[2]))
            for mode in MODES:
                params = SurfaceParams(boundary=box, region=region, sample_step=0.5, forward_step="tolerance",
                                       stepover=1.0, stepover_mode=mode, cusp=0.01, cusp_check="off")
                key = f"{model}, {rname}, {mode}"
                if key not in real:
                    result = raster_drop.compute(mesh, cutter, params, surface=surface)
                    tp = link(result.segments, LinkPolicy(safe_height=hi[2] + 5, clearance_height=hi[2] + 10))
                    real[key] = path_seconds(tp)
                    if cache:
                        cache.write_text(json.dumps(real))
                bounds = (*lo, *hi)
                told = estimate_work(params, cutter, bounds, sample).cutting_seconds(FEED, PLUNGE_FEED, PLUNGE_DEG)
                boxes = estimate_work(params, cutter, bounds).cutting_seconds(FEED, PLUNGE_FEED, PLUNGE_DEG)
                ratio = told / real[key]
                inside += 0.6 <= ratio <= 1.6
                print(f"{key:44s} {real[key] / 60:7.2f}m {told / 60:7.2f}m {ratio:6.2f} {boxes / 60:9.2f}m "
                      f"{boxes / real[key]:6.2f}", flush=True)
    print(f"\n{inside} of {len(real)} told within 0.6-1.6x of the path's cutting time")


if __name__ == "__main__":
    main()
