"""Machining regions, the spiral and the slope range (issue 14 item 3) on sphere_on_plate.stl (ball D6, step-over
1 mm, sample step 0.5 mm): the box raster (today) against a region with a hole (the box minus a disc of radius
20 mm about its centre) by zig-zag, one-way and spiral, a disc (radius 35 mm) by zig-zag and spiral, and the box
with the slope range (shallow: 0..30 deg; steep: 30..75 deg). Per row: pieces, jumps (lifts between chains), CL
points, cutting and rapid length, TMM's cycle time estimate (1000 / 300 mm/min feeds, the default rapids) and
the time to compute.

    .venv/bin/python benchmarks/region_bench.py            # all rows
    .venv/bin/python benchmarks/region_bench.py --quick    # box and region zig-zag, region spiral
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core import polygons  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.linking import LinkPolicy, link  # noqa: E402
from tmm_workbench.core.shared_data import shared_dir  # noqa: E402
from tmm_workbench.core.sim.cycle_time import three_axis_time, toolpath_feeds  # noqa: E402
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

FEED, PLUNGE = 1000.0 / 60, 300.0 / 60  # mm/s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    mesh = load_stl(shared_dir() / "benchmarks" / "stl" / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
    # a region with a hole: the box minus a disc of radius 20 mm about its centre
    centre = ((box[0] + box[2]) / 2, (box[1] + box[3]) / 2)
    radius = 20.0
    ring = polygons.difference([polygons.rectangle(*box)], [polygons.circle(centre, radius, 0.01)])
    disc = [polygons.circle(centre, 35.0, 0.01)]  # a round region: what the spiral suits
    cutter = Cutter.ball(6)
    base = dict(boundary=box, stepover=1.0, sample_step=0.5)
    rows = [("box zig-zag (today)", {}),
            ("ring zig-zag", dict(region=ring, boundary=polygons.bounds(ring))),
            ("ring one-way", dict(region=ring, boundary=polygons.bounds(ring), pattern="oneway")),
            ("ring spiral", dict(region=ring, boundary=polygons.bounds(ring), pattern="spiral")),
            ("box spiral", dict(pattern="spiral")),
            ("disc zig-zag", dict(region=disc, boundary=polygons.bounds(disc))),
            ("disc spiral", dict(region=disc, boundary=polygons.bounds(disc), pattern="spiral")),
            ("box slope 0..30", dict(slope_min_deg=0.0, slope_max_deg=30.0)),
            ("box slope 30..75", dict(slope_min_deg=30.0, slope_max_deg=75.0))]
    if args.quick:
        rows = [rows[0], rows[1], rows[3]]
    policy = LinkPolicy(safe_height=float(hi[2]) + 5, clearance_height=float(hi[2]) + 10)
    print(f"sphere_on_plate.stl, ball D6, step-over 1 mm, sample step 0.5 mm; ring: the box minus a disc r "
          f"{radius:.2f} mm about ({centre[0]:.2f}, {centre[1]:.2f})")
    print(f"{'case':22} {'pieces':>7} {'jumps':>6} {'CL pts':>8} {'cut mm':>9} {'rapid mm':>9} {'cycle s':>8} "
          f"{'compute s':>9}")
    for name, change in rows:
        params = SurfaceParams(**{**base, **change})
        t0 = time.perf_counter()
        result = compute(mesh, cutter, params)
        path = link(result.segments, policy)
        seconds = time.perf_counter() - t0
        ct = three_axis_time(path.points(), toolpath_feeds(path, FEED, PLUNGE))
        d = result.diagnostics
        jumps = d.get("jumps", sum(1 for s in result.segments if not s.joined) - 1)
        print(f"{name:22} {d['passes']:7d} {jumps:6d} {d['points']:8d} {ct.cutting_length:9.0f} {ct.rapid_length:9.0f} "
              f"{ct.seconds:8.1f} {seconds:9.2f}")


if __name__ == "__main__":
    main()
