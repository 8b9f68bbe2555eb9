"""The hand-made stock-to-part Job of the main job (scripts/demo.py's rough_finish: bull-nose D10 r1 roughing, 3 mm
layers, 45 % step-over, 0.5 mm left; ball D6 waterline every 0.5 mm; the API's feeds 1000 / 300 mm/min) simulated
as the planner's jobs are (cell 0.2 mm, tolerance 0.01 mm), for docs/results.md's comparison with
benchmarks/jobs/sphere_on_plate_hand_feeds.yaml (the planner at the same feeds).

    HOME=/tmp/home-x freecadcmd benchmarks/plan_vs_hand.py
"""
import sys
import time
from pathlib import Path

REPO = Path(globals().get("__file__") or sys.argv[0]).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tmm_workbench.app.api import run_roughing, run_waterline, simulate  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402

t0 = time.perf_counter()
stl = str(benchmark_file("stl", "sphere_on_plate.stl"))
rough = run_roughing(stl, tool="bullnose", diameter=10.0, corner_radius=1.0, step_down=3.0, stepover_percent=45.0,
                     stock_to_leave=0.5, entry="helix", progress=False, doc_name="hand")
water = run_waterline(None, job=rough, tool="ballend", diameter=6.0, step_down=0.5, progress=False)
r = simulate(water, cell=0.2, tolerance=0.01, progress=False)
print(f"hand-made rough_finish: cycle {r.cycle_seconds / 60:.1f} min ("
      + ", ".join(f"{o.label} {o.cycle_seconds / 60:.1f}" for o in r.ops)
      + f"), deepest gouge {max(0.0, -r.min_deviation):.4f} mm, most left {r.max_left:.3f} mm, "
      f"p50 {r.percentiles[50]:.4f} mm, p95 {r.percentiles[95]:.4f} mm; {time.perf_counter() - t0:.0f} s", flush=True)
raise SystemExit(0)
