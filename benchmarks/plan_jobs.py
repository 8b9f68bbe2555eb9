"""The automatic planner on every job file of benchmarks/jobs (one per shared STL): runs
`python3 -m tmm_workbench.plan <job> --quiet` for each and prints a table from its report.json.

    /usr/bin/python3 benchmarks/plan_jobs.py [job.yaml ...]     # default: every job of benchmarks/jobs
    /usr/bin/python3 benchmarks/plan_jobs.py --decisions [job.yaml ...]   # the decisions alone, wall and CPU s

benchmarks/jobs/sign.yaml plans seed 003's wooden sign: its model is made here first (core.geometry.sign, SIGN).

Columns: exit code (0 verified, 1 verification failed, 2 bad input), the deepest gouge and the most material left
(mm, vertical, from the simulation), the 95th percentile of what is left, the simulated cycle time, the ops, the
planning time (the decisions, core only) and the whole run's wall time (FreeCAD included). Then what is left
where the library's most reaching tool reaches (core.plan.left_check, along the normal): the area above the
tolerance (and above the finish's cusp when that is larger), the most, and the area out of that tool's reach from
above; each rest and pencil op's own report.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))


SIGN_STL = REPO / "out" / "plan" / "sign_model" / "sign.stl"   # benchmarks/jobs/sign.yaml's model


def make_sign_model() -> None:
    """Seed 003's sign (section 1.4: a border, raised text) for sign.yaml, written once."""
    if SIGN_STL.is_file():
        return
    from tmm_workbench.core.geometry.mesh import save_stl
    from tmm_workbench.core.geometry.sign import SignSpec, make_sign

    SIGN_STL.parent.mkdir(parents=True, exist_ok=True)
    save_stl(make_sign(SignSpec("TMM 2026", width=120, height=60, relief=3, cell=0.25)).mesh, SIGN_STL)


def jobs(args: list[str]) -> list[Path]:
    if args:
        return [Path(a) for a in args]
    return sorted(p for p in (REPO / "benchmarks" / "jobs").glob("*.yaml") if "format:" in p.read_text())


def planning_seconds(job: Path) -> float:
    from tmm_workbench.core.plan.job_file import read_job
    from tmm_workbench.core.plan.launch import make_plan

    t0 = time.perf_counter()
    make_plan(read_job(job))
    return time.perf_counter() - t0


def decisions(paths: list[Path]) -> None:
    """The decisions alone (core only, no FreeCAD), each job planned twice: the better wall and CPU seconds."""
    from tmm_workbench.core.plan.job_file import read_job
    from tmm_workbench.core.plan.launch import make_plan

    print(f"{'job':<24} {'wall s':>7} {'CPU s':>7}")
    for job in paths:
        runs = []
        for _ in range(2):
            w, c = time.perf_counter(), time.process_time()
            make_plan(read_job(job))
            runs.append((time.perf_counter() - w, time.process_time() - c))
        print(f"{job.stem:<24} {min(r[0] for r in runs):>7.1f} {min(r[1] for r in runs):>7.1f}", flush=True)


def main() -> None:
    from tmm_workbench.core.plan.job_file import read_job

    if sys.argv[1:2] in (["--help"], ["-h"]):   # (a job path that is not there is refused by name below)
        print(__doc__)
        return
    make_sign_model()
    if sys.argv[1:2] == ["--decisions"]:
        decisions(jobs(sys.argv[2:]))
        return
    head = (f"{'job':<16} {'exit':>4} {'gouge mm':>9} {'left mm':>8} {'p95 mm':>7} {'cycle min':>9} "
            f"{'plan s':>6} {'wall s':>7}  ops")
    print(head)
    print("-" * len(head))
    for job in jobs(sys.argv[1:]):
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "tmm_workbench.plan", str(job), "--quiet"], cwd=str(REPO),
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode == 2:
            print(f"{job.stem:<16} {2:>4}  {proc.stderr.strip()[:150]}")
            continue
        spec = read_job(job)
        report = spec.outputs.dir / "report.json"
        if not report.is_file() or report.stat().st_mtime < time.time() - wall:   # none, or an earlier run's
            print(f"{job.stem:<16} {proc.returncode:>4}  {proc.stderr.strip().splitlines()[-1][:150]}")
            continue
        v = json.loads(report.read_text())["verification"]
        ops = ", ".join(f"{o['label']} {o['cycle_seconds'] / 60:.1f}" for o in v["ops"])
        print(f"{job.stem:<16} {proc.returncode:>4} {v['deepest_gouge_mm']:>9.4f} {v['most_material_left_mm']:>8.3f} "
              f"{v['left_percentiles_mm']['95']:>7.3f} {v['cycle_seconds'] / 60:>9.1f} {planning_seconds(job):>6.1f} "
              f"{wall:>7.0f}  {ops}", flush=True)
        reach = v.get("left_in_reach")
        if reach:
            cusp = (f" ({reach['left_above_allowance_mm2']:g} mm2 above the cusp asked, {reach['allowance_mm']:g} mm)"
                    if reach.get("allowance_mm", 0) > v["tolerance_mm"] else "")
            print(f"{'':<16} where {reach['tool']} reaches: {reach['left_above_tolerance_mm2']:g} mm2 left above the "
                  f"tolerance{cusp}, most {reach['most_left_mm']:g} mm (99 %: {reach['left_99_percentile_mm']:g} mm); "
                  "out "
                  f"of its reach {reach['out_of_reach_mm2']:g} of {reach['reached_mm2'] + reach['out_of_reach_mm2']:g}"
                  " mm2", flush=True)
        for op in v["ops"]:
            if op.get("rest"):
                print(f"{'':<16} {op['label']}: {op['rest'][:200]}", flush=True)
        for change in v.get("replanned", []):
            print(f"{'':<16} plan changed: {change[:200]}", flush=True)
        if v["problems"]:
            print(f"{'':<16} problems: {'; '.join(v['problems'])[:300]}", flush=True)


if __name__ == "__main__":
    main()
