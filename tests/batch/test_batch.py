"""`tmm batch` on a real local Dask cluster, each part a real planner run in its own headless FreeCAD (the
planner's coarse test job, tests/data/plan_beet.yaml, a few seconds a part): parts verified and a broken one
reported without stopping them, outputs only whole, a rerun skipping what is done, a worker killed in the
middle of a part, and the arguments refused by name."""
from __future__ import annotations

import csv
import json
import os
import signal
import socket
import threading
import time
import urllib.request
from pathlib import Path

import pytest
import yaml

from tmm_workbench.batch import run as batch
from tmm_workbench.core.plan.job_file import read_job

JOB = Path(__file__).resolve().parents[1] / "data" / "plan_beet.yaml"
pytestmark = pytest.mark.xdist_group("batch")   # a cluster of its own: one such test at a time


def _jobs(folder: Path, **variants: dict) -> Path:
    """Job files in `folder`: the test job with each variant's fields changed (the model by its absolute path)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, change in variants.items():
        data = yaml.safe_load(JOB.read_text())
        data["model"]["file"] = str(read_job(JOB).model.file)
        for key, value in change.items():
            data[key] = value
        (folder / f"{name}.yaml").write_text(yaml.safe_dump(data))
    return folder


def _rows(out: Path) -> dict[str, dict]:
    with open(out / "summary.csv") as f:
        return {r["part"]: r for r in csv.DictReader(f)}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dashboard_while(run: threading.Thread, port: int) -> dict:
    """What Dask's dashboard at `port` says while `run` plans: its page served, and the batch's tasks counted."""
    seen: dict = {"status": None, "tasks": 0, "processing": 0, "progress": None}
    base = f"http://127.0.0.1:{port}"
    while run.is_alive():
        try:
            with urllib.request.urlopen(base + "/json/counts.json", timeout=5) as r:
                counts = json.loads(r.read())
            if counts["processing"] and seen["status"] is None:
                with urllib.request.urlopen(base + "/status", timeout=5) as r:
                    seen["status"] = (r.status, b"Dask" in r.read())
                with urllib.request.urlopen(base + "/individual-progress", timeout=5) as r:
                    seen["progress"] = r.status
            seen["tasks"] = max(seen["tasks"], counts["tasks"])
            seen["processing"] = max(seen["processing"], counts["processing"])
        except OSError:   # the cluster is still starting, or already gone
            pass
        time.sleep(0.3)
    return seen


def test_parts_on_two_workers_a_broken_one_reported_and_a_rerun_skips(tmp_path):
    jobs = _jobs(tmp_path / "jobs", a={}, b={"finish": {"cusp": 0.12, "tolerance": 0.01}},
                 broken={"material": "cheese"})
    (jobs / "tools.yaml").write_text("- {name: T, type: ball, diameter: 6, flutes: 2, flute_length: 20}\n")
    out = tmp_path / "out"
    port, code = _free_port(), []
    run = threading.Thread(target=lambda: code.append(batch.main(
        [str(jobs), "--out", str(out), "--workers", "2", "--quiet", "--dashboard", f"127.0.0.1:{port}"])))
    run.start()
    seen = _dashboard_while(run, port)
    run.join()
    assert code == [1]                                                   # one part not verified
    assert seen["status"] == (200, True) and seen["progress"] == 200 and seen["tasks"] == 3, seen
    assert seen["processing"] >= 2, seen                                # parts on both workers
    rows = _rows(out)
    assert sorted(rows) == ["a", "b", "broken"]                                           # the tools file is no job
    for name in ("a", "b"):
        r = rows[name]
        assert r["state"] == "verified" and r["exit_code"] == "0", r
        folder = Path(r["folder"])
        report = json.loads((folder / "report.json").read_text())
        assert report["passed"] and float(r["cycle_s"]) == pytest.approx(report["verification"]["cycle_seconds"])
        assert (folder / "beet_mm.ngc").read_text().count("\n") > 100 and float(r["peak_mb"]) > 50
    assert rows["a"]["cycle_s"] != rows["b"]["cycle_s"]                  # the parts' own plans
    assert rows["broken"]["state"] == "bad input" and "material" in rows["broken"]["reason"]
    assert "cheese" in rows["broken"]["reason"] and rows["broken"]["folder"].endswith(".failed")
    assert not [p for p in out.iterdir() if p.name.startswith(".")]     # nothing half-written left
    html = (out / "summary.html").read_text()
    assert "3 parts, 2 verified, 1 not" in html and "beet_mm.ngc" in html
    stamp = (Path(rows["a"]["folder"]) / "report.json").stat().st_mtime
    assert batch.main([str(jobs), "--out", str(out), "--workers", "1", "--quiet"]) == 1
    again = _rows(out)
    assert again["a"]["state"] == again["b"]["state"] == "done before (skipped)"
    assert (Path(again["a"]["folder"]) / "report.json").stat().st_mtime == stamp
    assert again["broken"]["state"] == "bad input"                       # a failure is planned again


def test_a_worker_killed_in_the_middle_of_a_part(tmp_path):
    from dask.distributed import Client, LocalCluster

    jobs = _jobs(tmp_path / "jobs", only={})
    out = tmp_path / "out"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        code: list[int] = []
        t = threading.Thread(target=lambda: code.append(batch.main(
            [str(jobs), "--out", str(out), "--scheduler", cluster.scheduler_address, "--quiet"])))
        t.start()
        end = time.monotonic() + 120
        while not list(out.glob(".only-*")) and time.monotonic() < end:   # the part has started
            time.sleep(0.2)
        time.sleep(1.0)
        pids = list(client.run(os.getpid).values())
        assert list(out.glob(".only-*")) and len(pids) == 1
        os.kill(pids[0], signal.SIGKILL)
        t.join(300)
        assert not t.is_alive()
    row = _rows(out)["only"]
    assert code == [0] and row["state"] == "verified", row
    assert not row["worker"].endswith(f":{pids[0]}")                     # run again, on the new worker
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("args,words", [
    (["nowhere.yaml"], "JOBS: 'nowhere.yaml' is not a job file"),
    (["{empty}"], "JOBS: no job files in"),
    (["{jobs}", "--workers", "-1"], "--workers must be >= 1"),
    (["{jobs}", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "not taken with --scheduler"),
    (["{jobs}", "--timeout", "0"], "--timeout must be > 0 s, got 0.0"),
    (["{jobs}", "--scheduler", "tcp://127.0.0.1:1", "--dashboard", ":9999"], "--dashboard is not taken with"),
])
def test_bad_arguments_exit_2_naming_them(tmp_path, capsys, args, words):
    (tmp_path / "empty").mkdir()
    jobs = _jobs(tmp_path / "jobs", a={})
    argv = [a.format(empty=tmp_path / "empty", jobs=jobs) for a in args]
    assert batch.main(argv + ["--out", str(tmp_path / "out")]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
