"""`tmm batch` on 1 and on 2 local Dask workers, the same 8 parts (the planner's job files of benchmarks/jobs at a
coarser finish, two of them twice, and a sign of seed 003 made by core.geometry.sign), each run from an empty
output folder: wall time, speed-up, per-part planning time and the peak memory of a part's
planner and FreeCAD (what one worker holds at a time). Prints a table.

    python3 benchmarks/batch_speedup.py [--workers 1 2] [--keep DIR]
"""
from __future__ import annotations

import argparse
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.batch import run as batch  # noqa: E402
from tmm_workbench.core.geometry.mesh import save_stl  # noqa: E402
from tmm_workbench.core.geometry.sign import SignSpec, make_sign  # noqa: E402
from tmm_workbench.core.plan.job_file import read_job  # noqa: E402

JOBS = ROOT / "benchmarks" / "jobs"
COARSE = {"finish": {"cusp": 0.05, "tolerance": 0.01}, "planner": {"analysis_cell": 0.5, "sim_cell": 0.4}}
# 8 parts: the shared models the planner verifies (benchmarks/jobs), two of them twice at another finish, a sign
PARTS = [("beet", {}), ("demo", {}), ("mount_rush", {}), ("pycam_textbox", {}), ("sphere_on_plate", {}),
         ("beet", {"finish": {"cusp": 0.02, "tolerance": 0.01}}), ("demo", {"finish": {"cusp": 0.1, "tolerance": 0.01}})]


def make_jobs(folder: Path) -> Path:
    """The 8 job files in `folder` (models and tools files by absolute path, the coarse planner values)."""
    folder.mkdir(parents=True)
    sign = save_stl(make_sign(SignSpec("TMM 2026", width=100, height=50, cell=0.4)).mesh, folder / "sign.stl")
    for k, (name, change) in enumerate(PARTS + [("beet", {"model": {"file": str(sign), "units": "mm"}})]):
        data = yaml.safe_load((JOBS / f"{name}.yaml").read_text())
        data["model"]["file"] = str(read_job(JOBS / f"{name}.yaml").model.file)
        data["tools"] = str((JOBS / data["tools"]).resolve())
        data.update(COARSE, **change)
        (folder / f"part{k + 1}_{Path(data['model']['file']).stem.replace('-', '_')}.yaml").write_text(
            yaml.safe_dump(data))
    return folder


def run(jobs: Path, workers: int, out: Path) -> tuple[float, list[dict]]:
    rows, wall = batch.run_batch(batch.collect([str(jobs)]), out, workers=workers, quiet=True)
    bad = [(r["part"], r.get("state"), r.get("reason") or r.get("problems")) for r in rows if r.get("state") != "verified"]
    if bad:
        print(f"  ({workers} workers: not verified: {bad})")
    return wall, rows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--keep", default=None, help="keep the outputs in this folder")
    args = ap.parse_args()
    tmp = Path(args.keep or tempfile.mkdtemp(prefix="tmm-batch-bench-"))
    jobs = make_jobs(tmp / "jobs")
    print("| workers | parts | verified | wall s | speed-up | part s (median, max) | peak MB a part (median, max) |")
    print("|---|---|---|---|---|---|---|")
    first = None
    for w in args.workers:
        wall, rows = run(jobs, w, tmp / f"out-{w}")
        first = first or wall
        secs = [float(r["seconds"]) for r in rows if r.get("seconds")]
        mb = [float(r["peak_mb"]) for r in rows if r.get("peak_mb")]
        ok = sum(r["state"] == "verified" for r in rows)
        print(f"| {w} | {len(rows)} | {ok} | {wall:.0f} | {first / wall:.2f} | {statistics.median(secs):.1f}, "
              f"{max(secs):.1f} | {statistics.median(mb):.0f}, {max(mb):.0f} |", flush=True)
    if not args.keep:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
