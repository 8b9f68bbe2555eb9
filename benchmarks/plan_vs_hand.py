"""Hand-made stock-to-part Jobs on sphere_on_plate simulated as the planner's jobs are (cell 0.2 mm, tolerance
0.01 mm), for docs/planner.md's comparison with benchmarks/jobs/sphere_on_plate_hand_feeds.yaml (the planner at the
same feeds: 1000 mm/min, the API's default):
- the main job's rough_finish (scripts/demo.py: bull-nose D10 r1 roughing, 3 mm layers, 45 % step-over, 0.5 mm
  left; ball D6 waterline every 0.5 mm): it does not finish the shallow areas, so it is not the same finish;
- the same finish by hand (cusp 0.01 mm, tolerance 0.01 mm): that roughing, then what a person sets for the cusp
  with the ball D6 (seed 000's scallop formula at the 45 deg split: 0.346 mm), a raster over 0-45 deg and a
  waterline 0.346 mm apart, and a ball D3 rest (region 'rest') for the sphere's foot, the cusp's step-over.
Each with what is left where the ball D3 reaches (core.plan.left_check, the planner's judging).

    HOME=/tmp/home-x freecadcmd benchmarks/plan_vs_hand.py
"""
import sys
import time
from pathlib import Path

REPO = Path(globals().get("__file__") or sys.argv[0]).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tmm_workbench.app.api import run_roughing, run_surface, run_waterline, simulate  # noqa: E402
from tmm_workbench.core.footprint.cusp import stepover_for_cusp  # noqa: E402
from tmm_workbench.core.geometry.mesh import load_stl  # noqa: E402
from tmm_workbench.core.plan.left_check import left_in_reach  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

CUSP, TOLERANCE = 0.01, 0.01
STL = str(benchmark_file("stl", "sphere_on_plate.stl"))


def rough(name: str):
    return run_roughing(STL, tool="bullnose", diameter=10.0, corner_radius=1.0, step_down=3.0,
                        stepover_percent=45.0, stock_to_leave=0.5, entry="helix", progress=False, doc_name=name)


def report(title: str, last, t0: float) -> None:
    r = simulate(last, cell=0.2, tolerance=TOLERANCE, progress=False)
    js = r.simulation
    reach = left_in_reach(load_stl(STL), js.grid, js.design, js.comparison.deviation, "ball D3", Cutter.ball(3.0),
                          TOLERANCE, CUSP)
    print(f"{title}: cycle {r.cycle_seconds / 60:.1f} min ("
          + ", ".join(f"{o.label} {o.cycle_seconds / 60:.1f}" for o in r.ops)
          + f"), deepest gouge {max(0.0, -r.min_deviation):.4f} mm, most left {r.max_left:.3f} mm, "
          f"p50 {r.percentiles[50]:.4f} mm, p95 {r.percentiles[95]:.4f} mm; where a ball D3 reaches: "
          f"{reach['left_above_tolerance_mm2']:g} mm2 above {TOLERANCE:g} mm, most {reach['most_left_mm']:g} mm, "
          f"99 % {reach['left_99_percentile_mm']:g} mm; {time.perf_counter() - t0:.0f} s", flush=True)


t0 = time.perf_counter()
main_job = rough("hand")
report("hand-made rough_finish", run_waterline(None, job=main_job, tool="ballend", diameter=6.0, step_down=0.5,
                                               progress=False), t0)

t0 = time.perf_counter()
step = round(stepover_for_cusp(Cutter.ball(6.0), CUSP, 45.0), 3)
same = rough("hand_same_finish")
run_surface(None, job=same, tool="ballend", diameter=6.0, stepover=step, slope_range=(0.0, 45.0), progress=False)
run_waterline(None, job=same, tool="ballend", diameter=6.0, step_down=step, progress=False)
rest = run_surface(None, job=same, tool="ballend", diameter=3.0, region="rest", rest_from="earlier_ops",
                   rest_tolerance=TOLERANCE, stepover=round(stepover_for_cusp(Cutter.ball(3.0), CUSP), 3),
                   progress=False)
report(f"hand-made, the same finish (ball D6 raster 0-45 deg and waterline {step:g} mm, ball D3 rest)", rest, t0)
raise SystemExit(0)
