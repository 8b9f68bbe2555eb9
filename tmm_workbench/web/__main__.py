"""`python3 -m tmm_workbench.web --port P --jobs DIR [--scheduler ADDR | --workers N]` (docs/web.md). Exit code 2
on bad arguments."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Optional, Sequence

BAD_ARGS = 2


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="tmm web", description="The web front: a page and an HTTP API planning "
                                 "uploads, samples and signs on Dask (docs/web.md).")
    ap.add_argument("--port", type=int, default=8000, help="the port (default 8000)")
    ap.add_argument("--host", default="127.0.0.1", help="the address to listen on (default 127.0.0.1; 0.0.0.0 "
                    "for the shop's network)")
    ap.add_argument("--jobs", required=True, help="the folder of the jobs (one folder each, kept across restarts)")
    ap.add_argument("--scheduler", default=None, help="an existing Dask scheduler's address (tcp://host:8786)")
    ap.add_argument("--workers", type=int, default=0, help="local worker processes (default 1; not with "
                    "--scheduler)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="a job's time limit in s (default 3600)")
    ap.add_argument("--max-upload-mb", type=float, default=50.0, help="the largest STL upload (default 50)")
    args = ap.parse_args(argv)
    problem = None
    if not 1 <= args.port <= 65535:
        problem = f"--port must be in [1, 65535], got {args.port}"
    elif args.workers < 0 or (args.scheduler and args.workers):
        problem = (f"--workers must be >= 1 for a local cluster and is not taken with --scheduler (the cluster "
                   f"has its own workers), got {args.workers}")
    elif not args.timeout > 0:
        problem = f"--timeout must be > 0 s, got {args.timeout}"
    elif not 0 < args.max_upload_mb <= 1024:
        problem = f"--max-upload-mb must be in (0, 1024], got {args.max_upload_mb}"
    elif Path(args.jobs).exists() and not Path(args.jobs).is_dir():
        problem = f"--jobs: {args.jobs!r} is not a folder"
    if problem:
        print(f"tmm web: {problem}", file=sys.stderr)
        return BAD_ARGS
    import uvicorn

    from tmm_workbench.web.app import create_app

    jobs = Path(args.jobs).resolve()
    jobs.mkdir(parents=True, exist_ok=True)
    app = create_app(jobs, args.scheduler, args.workers or (0 if args.scheduler else 1), args.timeout,
                     int(args.max_upload_mb * 2 ** 20))
    uvicorn.run(app, host=args.host, port=args.port, log_level="warning")
    return 0


if __name__ == "__main__":
    sys.exit(main())
