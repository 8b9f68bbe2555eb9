"""Does the work estimate tell the compute time? Each case runs through the headless API (what a user waits for:
from the call to G-code) and the op's estimate is read afterwards (app.work_estimate: the count from boxes and
spacing, the compute seconds from the strategy's pace per counted unit). Printed per case: the count, the estimated
and the measured seconds and their ratio; a case over 30 s must be estimated over 30 s (the op warns then).

    freecadcmd -c "exec(open('benchmarks/compute_estimate.py').read())"             # all cases
    TMM_ESTIMATE_CASES=cusp,flat_cusp freecadcmd -c "exec(open('benchmarks/compute_estimate.py').read())"
"""
from __future__ import annotations

import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, ROOT)

SOP, RUSH = "stl/sphere_on_plate.stl", "stl/mount_rush.stl"
# case -> (API function, model, keyword arguments)
CASES = {
    "stepover": ("run_surface", SOP, dict(stepover=0.5, sample_step=0.25)),
    "stepover_fine": ("run_surface", SOP, dict(stepover=0.1, sample_step=0.1)),
    "sample": ("run_surface", RUSH, dict(stepover=0.3, sample_step=0.1, forward_step="sample")),
    "cusp": ("run_surface", SOP, dict(stepover_mode="cusp", cusp=0.01)),
    "flat_cusp": ("run_surface", SOP, dict(tool="endmill", stepover_mode="cusp", cusp=0.01)),
    "bull_cusp": ("run_surface", RUSH, dict(tool="bullnose", diameter=10, corner_radius=2, stepover_mode="cusp",
                                            cusp=0.01)),
    "adaptive": ("run_surface", SOP, dict(stepover_mode="adaptive", cusp=0.01)),
    "offset3d": ("run_surface", SOP, dict(stepover_mode="offset3d", cusp=0.01)),
    "verify": ("run_surface", SOP, dict(stepover_mode="adaptive", cusp=0.01, verify_cusp=True)),
    "waterline": ("run_waterline", SOP, dict(step_down=0.5)),
    "waterline_fine": ("run_waterline", RUSH, dict(step_down=0.1)),
    "roughing": ("run_roughing", RUSH, dict(step_down=1.0)),
    "multipoint": ("run_multipoint", "convex", dict(scallop=0.01, forward_step=2.0)),
    "multipoint_even": ("run_multipoint", "convex", dict(pass_spacing="even", forward_step=2.0)),
}


def run_case(name: str) -> tuple[float, float, float]:
    """(count, estimated s, measured s) of one case."""
    from tmm_workbench.app import api, work_estimate
    from tmm_workbench.core.shared_data import benchmark_file

    function, model, kwargs = CASES[name]
    t0 = time.monotonic()
    if function == "run_multipoint":
        from tmm_workbench.core.geometry import bezier

        net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), model)
        result = api.run_multipoint(net, progress=False, posts=(), doc_name=name, **kwargs)
    else:
        result = getattr(api, function)(str(benchmark_file(model)), progress=False, doc_name=name, **kwargs)
    took = time.monotonic() - t0
    est = work_estimate.estimate(result.op)
    return est.count, est.compute_seconds or 0.0, took


def main() -> None:
    import FreeCAD

    names = [c for c in os.environ.get("TMM_ESTIMATE_CASES", ",".join(CASES)).split(",") if c]
    print(f"{'case':<15} {'count':>10} {'estimated s':>12} {'measured s':>11} {'ratio':>6}  over 30 s told")
    for name in names:
        count, estimated, measured = run_case(name)
        told = "yes" if measured <= 30 or estimated > 30 else "NO"
        print(f"\n{name:<15} {count:>10.3g} {estimated:>12.1f} {measured:>11.1f} {measured / max(estimated, 1e-9):>6.2f}"
              f"  {told}", flush=True)
        for doc in list(FreeCAD.listDocuments()):
            FreeCAD.closeDocument(doc)


main()
