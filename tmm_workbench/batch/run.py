"""`tmm batch JOBS...`: every part's plan on Dask distributed (a local cluster of one single-threaded worker process
per core by default, or the cluster at `--scheduler`), a part that fails never stopping the others, a part whose
inputs hash to a finished result skipped, a killed worker's part run again elsewhere (Dask's own retries) or
reported with the reason; progress on the terminal (quiet in a pipe) and in Dask's dashboard (bokeh, which setup
installs into the project's venv, the one `tmm` runs); the summary (CSV, HTML) at the end. Exit code 0 when every part is verified, 1 when one is not, 2 on bad
arguments."""
from __future__ import annotations

import argparse
import importlib.util
import logging
import os
import sys
import time
from pathlib import Path
from typing import Optional, Sequence

from tmm_workbench.batch.part import JOB_SUFFIXES, run_part
from tmm_workbench.batch.summary import write_summary

BAD_ARGS = 2


class BatchInputError(ValueError):
    pass


def collect(paths: Sequence[str]) -> list[Path]:
    """The job files named, folders giving theirs (*.yaml, *.yml, *.json, not recursive), in a stable order; a
    tools file beside the jobs (no `model` field) is not a job."""
    jobs: list[Path] = []
    for name in paths:
        p = Path(name)
        if p.is_dir():
            jobs += sorted(f for f in p.iterdir() if f.suffix in JOB_SUFFIXES and _is_job(f))
        elif p.is_file() and p.suffix in JOB_SUFFIXES:
            jobs.append(p)
        else:
            raise BatchInputError(f"JOBS: {name!r} is not a job file ({', '.join(JOB_SUFFIXES)}) or a folder of them")
    if not jobs:
        raise BatchInputError(f"JOBS: no job files in {', '.join(map(str, paths))}")
    stems = [j.stem for j in jobs]
    twice = sorted({s for s in stems if stems.count(s) > 1})
    if twice:
        raise BatchInputError(f"JOBS: two job files named {twice[0]!r}: each part's folder is named after its file")
    return [j.resolve() for j in jobs]


def _is_job(f: Path) -> bool:
    head = f.read_text(encoding="utf-8", errors="replace")[:4000]
    return "model" in head


DASHBOARD = ":8787"
NO_DASHBOARD = "off"
BOKEH_HINT = 'pip install "bokeh>=2.4.2,<3" (Debian 12 has no bokeh; scripts/setup.sh puts it in the project\'s venv)'


def open_client(scheduler: Optional[str], workers: int, dashboard: str):
    """A Dask client on the cluster at `scheduler`, or on a new local cluster of `workers` processes (one thread
    each) with its dashboard at `dashboard` (host:port, or NO_DASHBOARD); with the cluster to close (None for an
    existing one, whose scheduler serves its own dashboard)."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler, timeout="30s"), None
    address = None if dashboard == NO_DASHBOARD or not has_dashboard() else dashboard
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=address,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def has_dashboard() -> bool:
    """Dask's dashboard needs bokeh (below 3 for Debian 12's distributed 2022.12)."""
    return importlib.util.find_spec("bokeh") is not None


def run_batch(jobs: Sequence[Path], out_root: Path, scheduler: Optional[str] = None, workers: int = 0,
              timeout_s: float = 3600.0, quiet: bool = False, dashboard: str = DASHBOARD
              ) -> tuple[list[dict], float]:
    """Every job planned on the cluster: the rows (in the jobs' order) and the wall time. The parts' task keys
    share the prefix `tmm-part`, so the dashboard shows the batch as one progress bar."""
    from dask.distributed import as_completed

    out_root.mkdir(parents=True, exist_ok=True)
    workers = workers or os.cpu_count() or 1
    client, cluster = open_client(scheduler, workers, dashboard)
    t0 = time.monotonic()
    try:
        if not quiet:
            _say_dashboard(client, scheduler, dashboard)
        futures = {client.submit(run_part, str(j), str(out_root), timeout_s, pure=False, retries=1,
                                 priority=_size(j), key=f"tmm-part-{int(t0)}-{j.stem}"): j for j in jobs}
        rows: dict[Path, dict] = {}
        for fut in as_completed(futures):
            job = futures[fut]
            try:
                rows[job] = fut.result()
            except Exception as exc:   # the task itself failed (a worker killed again and again): the reason
                rows[job] = {"part": job.stem, "job": str(job), "state": "failed",
                             "reason": f"{type(exc).__name__}: {exc}"}
            _progress(len(rows), len(jobs), sum(r.get("state") not in _GOOD for r in rows.values()),
                      time.monotonic() - t0, quiet)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    if not quiet and sys.stderr.isatty():
        print(file=sys.stderr)
    return [rows[j] for j in jobs], time.monotonic() - t0


_GOOD = ("verified", "done before (skipped)")


def _say_dashboard(client, scheduler: Optional[str], dashboard: str) -> None:
    if dashboard == NO_DASHBOARD:
        return
    if scheduler or has_dashboard():
        print(f"Dask dashboard: {client.dashboard_link}", file=sys.stderr)
    else:
        print(f"no Dask dashboard: it needs bokeh: {BOKEH_HINT}", file=sys.stderr)


def _size(job: Path) -> int:
    """The part's model file size in KB: the larger first (the longest parts first keep the last worker from
    finishing alone); 0 when the job does not read."""
    from tmm_workbench.core.plan.job_file import read_job

    try:
        return Path(read_job(str(job)).model.file).stat().st_size // 1024
    except Exception:   # the part's own run reports why
        return 0


def _progress(done: int, total: int, failed: int, elapsed: float, quiet: bool) -> None:
    if quiet or not sys.stderr.isatty():
        return
    width = 30
    bar = "#" * (width * done // total) + "." * (width - width * done // total)
    print(f"\r[{bar}] {done}/{total} parts, {failed} not verified, {elapsed:.0f} s", end="", file=sys.stderr,
          flush=True)


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="tmm batch", description="Plans every job file on Dask distributed "
                                 "(docs/batch.md).")
    ap.add_argument("jobs", nargs="+", metavar="JOBS", help="job files or folders of them")
    ap.add_argument("--out", default="batch-out", help="the folder for the parts' results and the summary")
    ap.add_argument("--scheduler", default=None, help="an existing Dask scheduler's address (tcp://host:8786)")
    ap.add_argument("--workers", type=int, default=0, help="local worker processes (default: one per core)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="a part's time limit in s (default 3600)")
    ap.add_argument("--dashboard", default=DASHBOARD, metavar="HOST:PORT",
                    help=f"the local cluster's Dask dashboard (default {DASHBOARD}; '{NO_DASHBOARD}': none)")
    ap.add_argument("--quiet", action="store_true", help="no progress (errors only)")
    args = ap.parse_args(argv)
    try:
        if args.workers < 0 or (args.scheduler and args.workers):
            raise BatchInputError(f"--workers must be >= 1 for a local cluster and is not taken with --scheduler "
                                  f"(the cluster has its own workers), got {args.workers}")
        if args.scheduler and args.dashboard != DASHBOARD:
            raise BatchInputError(f"--dashboard is not taken with --scheduler (the scheduler serves its own), got "
                                  f"{args.dashboard!r}")
        if args.dashboard not in (DASHBOARD, NO_DASHBOARD) and not has_dashboard():
            raise BatchInputError(f"--dashboard {args.dashboard!r} needs bokeh: {BOKEH_HINT}")
        if not args.timeout > 0:
            raise BatchInputError(f"--timeout must be > 0 s, got {args.timeout}")
        jobs = collect(args.jobs)
    except BatchInputError as exc:
        print(f"tmm batch: {exc}", file=sys.stderr)
        return BAD_ARGS
    out_root = Path(args.out).resolve()
    rows, wall = run_batch(jobs, out_root, args.scheduler, args.workers, args.timeout, args.quiet, args.dashboard)
    csv_path, html_path = write_summary(rows, out_root, wall, args.workers or os.cpu_count() or 1)
    bad = [r for r in rows if r.get("state") not in _GOOD]
    if not args.quiet:
        print(f"{len(rows) - len(bad)} of {len(rows)} parts verified in {wall:.0f} s; summary: {html_path}")
        for r in bad:
            print(f"  {r['part']}: {r.get('state')}: {r.get('problems') or r.get('reason', '')}")
    return 0 if not bad else 1
