"""One part of a batch: its job file's inputs hashed to a key, the planner run on it in a process of its own, its
outputs moved into the part's folder only when whole, and a row saying how it ended (a Dask task: everything it
takes and returns is plain data, so a worker on another machine runs it the same way)."""
from __future__ import annotations

import ctypes
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parents[2]
REPORT = "report.json"
FAILURE = "failure.json"
LOG = "plan.log"
PROGRESS = "progress.json"   # the planner's last progress note (core.plan.progress_note), in the attempt's folder
JOB_SUFFIXES = (".yaml", ".yml", ".json")
EXIT_STATES = {0: "verified", 1: "verification failed", 2: "bad input"}
TIMED_OUT = -1000


def addon_version() -> str:
    """The add-on's version (package.xml) and, in a git checkout, its commit: a new build replans every part."""
    text = (ROOT / "package.xml").read_text(encoding="utf-8")
    version = re.search(r"<version>([^<]+)</version>", text)
    head = ROOT / ".git" / "HEAD"
    commit = ""
    if head.is_file():
        ref = head.read_text().strip()
        target = ROOT / ".git" / ref[5:] if ref.startswith("ref: ") else None
        commit = target.read_text().strip() if target is not None and target.is_file() else ref
    return f"{version.group(1) if version else '?'}+{commit[:12]}"


def input_key(job: Path) -> str:
    """sha256 of the job file, the model file it names, its tools (a shared tools file's too) and the add-on's
    version."""
    from tmm_workbench.core.plan.job_file import read_job   # the planner's own reading of the job file

    h = hashlib.sha256()
    h.update(addon_version().encode())
    h.update(job.read_bytes())
    try:
        spec = read_job(str(job))
    except Exception:   # a job the planner refuses still gets a key: its own bytes (the refusal is its result)
        return h.hexdigest()
    h.update(repr(spec.tools).encode())
    if Path(spec.model.file).is_file():
        h.update(Path(spec.model.file).read_bytes())
    return h.hexdigest()


def folder_of(job: Path, out_root: Path, key: str) -> Path:
    return out_root / f"{job.stem}-{key[:12]}"


def _die_with_parent() -> None:   # the planner stops when its worker is killed, rather than write on alone
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)   # PR_SET_PDEATHSIG
    except OSError:
        pass


def run_part(job: str, out_root: str, timeout_s: float = 3600.0, python: Optional[str] = None) -> dict:
    """Plans `job` into its folder under `out_root` (skipped when a finished result of the same inputs is there) and
    returns its row: job, folder, state, exit code, seconds, peak memory, worker, the report's figures or the
    reason it failed."""
    job_path = Path(job).resolve()
    key = input_key(job_path)
    folder = folder_of(job_path, Path(out_root).resolve(), key)
    row = {"part": job_path.stem, "job": str(job_path), "folder": str(folder), "key": key[:12],
           "worker": os.uname().nodename + f":{os.getpid()}"}
    if (folder / REPORT).is_file():
        return {**row, **_figures(folder), "state": "done before (skipped)", "exit_code": 0, "seconds": 0.0}
    for stale in folder.parent.glob(f".{folder.name}.*"):   # a killed worker's attempt (its planner died with it)
        shutil.rmtree(stale, ignore_errors=True)
    tmp = folder.with_name(f".{folder.name}.{uuid.uuid4().hex[:8]}")
    tmp.mkdir(parents=True)
    env = dict(os.environ, TMM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               TMM_PROGRESS_FILE=str(tmp / PROGRESS), PYTHONPATH=os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    t0 = time.monotonic()
    with open(tmp / LOG, "wb") as log:
        proc = subprocess.Popen([python or sys.executable, "-m", "tmm_workbench.plan", str(job_path), "--out",
                                 str(tmp / "out"), "--quiet"], stdout=log, stderr=subprocess.STDOUT, env=env,
                                cwd=str(job_path.parent), preexec_fn=_die_with_parent)
        code, peak_kb = _wait(proc, timeout_s)
    row.update(seconds=round(time.monotonic() - t0, 2), exit_code=code, peak_mb=round(peak_kb / 1024.0, 1))
    done = tmp / "out" / REPORT
    if code in (0, 1) and done.is_file():
        shutil.move(str(tmp / LOG), str(tmp / "out" / LOG))
        _into_place(tmp / "out", folder)
        shutil.rmtree(tmp, ignore_errors=True)
        return {**row, **_figures(folder), "state": EXIT_STATES[code]}
    reason = _reason(code, tmp / LOG, timeout_s)
    failed = folder.with_name(folder.name + ".failed")   # kept apart: a rerun plans the part again
    shutil.rmtree(failed, ignore_errors=True)
    (tmp / FAILURE).write_text(json.dumps({**row, "reason": reason}, indent=1) + "\n")
    shutil.rmtree(tmp / "out", ignore_errors=True)
    os.replace(tmp, failed)
    return {**row, "folder": str(failed), "state": EXIT_STATES.get(code, "failed"), "reason": reason}


def _wait(proc: subprocess.Popen, timeout_s: float) -> tuple[int, int]:
    """The exit code (-signal when killed, TIMED_OUT when stopped at the timeout) and the peak resident KB of the
    planner and the FreeCAD it waited for (wait4's usage)."""
    end = time.monotonic() + timeout_s
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            proc.returncode = os.waitstatus_to_exitcode(status)
            return proc.returncode, usage.ru_maxrss
        if time.monotonic() > end:
            proc.kill()
            _, status, usage = os.wait4(proc.pid, 0)
            proc.returncode = os.waitstatus_to_exitcode(status)
            return TIMED_OUT, usage.ru_maxrss
        time.sleep(0.1)


def _into_place(src: Path, folder: Path) -> None:
    """`src` becomes `folder` in one rename; a folder already there (the same inputs finished meanwhile by a
    retried task) is kept and `src` dropped."""
    try:
        os.rename(src, folder)
    except OSError:
        if not (folder / REPORT).is_file():
            raise


def _figures(folder: Path) -> dict:
    """What the summary shows of a finished part's report."""
    try:
        rep = json.loads((folder / REPORT).read_text())
    except (OSError, ValueError) as exc:
        return {"reason": f"unreadable {REPORT}: {exc}"}
    v = rep.get("verification", {})
    return {"passed": rep.get("passed"), "cycle_s": v.get("cycle_seconds"), "deepest_gouge_mm": v.get("deepest_gouge_mm"),
            "most_left_mm": v.get("most_material_left_mm"), "problems": "; ".join(rep.get("problems", [])),
            "files": rep.get("files", [])}


def _reason(code: int, log: Path, timeout_s: float) -> str:
    tail = " | ".join(log.read_text(errors="replace").strip().splitlines()[-6:]) if log.is_file() else ""
    if code == TIMED_OUT:
        return f"stopped after the part's time limit of {timeout_s:g} s" + (f": {tail}" if tail else "")
    if code < 0:
        return f"the planner died of signal {-code}" + (f": {tail}" if tail else "")
    return tail or f"the planner exited with code {code} and no report"
