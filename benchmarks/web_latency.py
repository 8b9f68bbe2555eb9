"""The web front answering while its workers plan: the time of `GET /api/jobs/{id}` and `GET /` with the server
idle and while N jobs (beet_mm, the draft recipe) are queued and planned on its local cluster; and the time from
accepted to verified per job. Prints a table (median, 95th percentile, max in ms).

    python3 benchmarks/web_latency.py [--workers 2] [--jobs 4]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.web.conftest import ENDED, RECIPE, start_server  # noqa: E402


def _timed(server, path: str) -> float:
    t0 = time.perf_counter()
    code, _ = server.call("GET", path)
    assert code == 200, (path, code)
    return 1000.0 * (time.perf_counter() - t0)


def _row(name: str, ms: list[float]) -> str:
    ms = sorted(ms)
    p95 = ms[min(len(ms) - 1, int(0.95 * len(ms)))]
    return f"| {name} | {len(ms)} | {statistics.median(ms):.1f} | {p95:.1f} | {ms[-1]:.1f} |"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--jobs", type=int, default=4)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        server = start_server(Path(tmp) / "jobs", Path(tmp) / "server.log", "--workers", str(args.workers))
        try:
            code, first = server.post_job({"sample": "beet_mm.stl", **RECIPE})
            server.wait(first["id"])
            idle = [_timed(server, f"/api/jobs/{first['id']}") for _ in range(50)]
            idle_page = [_timed(server, "/") for _ in range(20)]
            t0 = time.monotonic()
            ids = [server.post_job({"sample": "beet_mm.stl", **RECIPE})[1]["id"] for _ in range(args.jobs)]
            busy, busy_page, ended = [], [], {}
            while len(ended) < len(ids):
                for i in ids:
                    busy.append(_timed(server, f"/api/jobs/{i}"))
                    if i not in ended and server.status(i)["state"] in ENDED:
                        ended[i] = time.monotonic() - t0
                busy_page.append(_timed(server, "/"))
                time.sleep(0.1)
            states = [server.status(i)["state"] for i in ids]
        finally:
            server.stop()
    print(f"web front, {args.workers} local worker(s), {args.jobs} beet_mm jobs (draft) submitted at once; "
          f"states {states}; ended after {', '.join(f'{s:.1f}' for s in sorted(ended.values()))} s")
    print("| request | n | median ms | p95 ms | max ms |\n|---|---|---|---|---|")
    for name, ms in (("status, idle", idle), ("page, idle", idle_page), ("status, while planning", busy),
                     ("page, while planning", busy_page)):
        print(_row(name, ms))
    return 0


if __name__ == "__main__":
    sys.exit(main())
