"""The web front's jobs: each in its own folder `DIR/<id>/` (a server-made id: 32 hex digits) holding the planner's
job file, the model, a state file and the batch part's outputs; planned by `batch.part.run_part` on the Dask
cluster. The state file is written when a job is accepted and when it ends (replaced whole), so a restarted
server lists every accepted job and submits again those that had not ended (the part's key skips a result already
whole)."""
from __future__ import annotations

import json
import os
import re
import shutil
import threading
import time
import uuid
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable, Optional

from tmm_workbench.batch.part import PROGRESS
from tmm_workbench.core.plan import progress_note
from tmm_workbench.web.recipe import JOB_FILE, MODEL_FILE, PART_NAME, Recipe, RequestError, job_data

STATE_FILE = "state.json"
OUT_DIR = "out"
ID = re.compile(r"^[0-9a-f]{32}$")
ACCEPTED, DONE, FAILED = "accepted", "done", "failed"
MAX_WAITING = 50                     # jobs accepted and not ended: more are refused (429) until some end
REPORT_FIGURES = ("cycle_seconds", "deepest_gouge_mm", "most_material_left_mm")


def _write_json(path: Path, data: dict) -> None:
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    os.replace(tmp, path)


class JobStore:
    """The jobs under `root` and the Dask client planning them (`submit` is given the client's submit)."""

    def __init__(self, root: Path, timeout_s: float) -> None:
        self.root = root.resolve()
        self.timeout_s = timeout_s
        self.jobs: dict[str, dict] = {}
        self.futures: dict[str, Any] = {}
        self.client: Any = None
        self._lock = threading.Lock()

    # --- accepting -----------------------------------------------------------------------------------------

    def _records(self) -> list[tuple[str, dict]]:   # a copy: threads add and end jobs meanwhile
        with self._lock:
            return list(self.jobs.items())

    def waiting(self) -> int:
        return sum(1 for _, j in self._records() if j["state"] == ACCEPTED)

    def new_folder(self) -> Path:
        """A hidden folder for a job being accepted (made whole, then renamed to its id)."""
        self.root.mkdir(parents=True, exist_ok=True)
        folder = self.root / f".new-{uuid.uuid4().hex}"
        folder.mkdir()
        return folder

    def accept(self, folder: Path, recipe: Recipe, source: str) -> dict:
        """`folder` (from new_folder, holding MODEL_FILE) becomes a job: its job file written and checked by the
        planner's own reader (a bad one: 400, nothing kept), its state file, its id; then submitted."""
        from tmm_workbench.core.errors import TmmError
        from tmm_workbench.core.plan.job_file import job_from_dict

        import yaml

        data = job_data(recipe)
        try:
            job_from_dict(data, folder / JOB_FILE)
        except TmmError as exc:
            shutil.rmtree(folder, ignore_errors=True)
            raise RequestError(400, f"recipe: {exc}") from None
        (folder / JOB_FILE).write_text(yaml.safe_dump(data, sort_keys=False))
        job_id = uuid.uuid4().hex
        record = {"id": job_id, "state": ACCEPTED, "created": time.time(), "source": source,
                  "recipe": asdict(recipe), "row": None}
        _write_json(folder / STATE_FILE, record)
        os.rename(folder, self.root / job_id)
        with self._lock:
            self.jobs[job_id] = record
        self.submit(job_id)
        return record

    def discard(self, folder: Path) -> None:
        shutil.rmtree(folder, ignore_errors=True)

    # --- planning ------------------------------------------------------------------------------------------

    def submit(self, job_id: str) -> None:
        """The job's part on the cluster (planned, then its tool path drawn); its end written to its state file by
        the future's callback."""
        from tmm_workbench.web.picture import plan_part

        folder = self.root / job_id
        fut = self.client.submit(plan_part, str(folder / JOB_FILE), str(folder / OUT_DIR), self.timeout_s,
                                 str(folder / MODEL_FILE), f"{PART_NAME}.ngc", pure=False, retries=1, key=f"tmm-web-{job_id}-{uuid.uuid4().hex[:6]}")
        self.futures[job_id] = fut
        fut.add_done_callback(self._ended(job_id))

    def _ended(self, job_id: str) -> Callable[[Any], None]:
        def done(fut: Any) -> None:   # in a thread of the client's
            if fut.status == "cancelled":   # the server stopping: the job stays accepted, planned after a restart
                return
            try:
                row = fut.result()
                state = DONE if row.get("state") in ("verified", "verification failed", "done before (skipped)") \
                    else FAILED
            except Exception as exc:   # the task itself failed (a worker killed again and again)
                row, state = {"state": "failed", "reason": f"{type(exc).__name__}: {exc}"}, FAILED
            with self._lock:
                record = dict(self.jobs[job_id], state=state, row=row, ended=time.time())
                _write_json(self.root / job_id / STATE_FILE, record)
                self.jobs[job_id] = record
            self.futures.pop(job_id, None)
        return done

    def recover(self) -> list[str]:
        """Every job folder's state read back; the ones not ended submitted again. Half-accepted folders (a
        server stopped while accepting) are removed."""
        if not self.root.is_dir():
            return []
        for stale in self.root.glob(".new-*"):
            shutil.rmtree(stale, ignore_errors=True)
        again = []
        for folder in sorted(self.root.iterdir()):
            if not ID.match(folder.name) or not (folder / STATE_FILE).is_file():
                continue
            try:
                record = json.loads((folder / STATE_FILE).read_text())
            except (OSError, ValueError):
                continue
            with self._lock:
                self.jobs[folder.name] = record
            if record.get("state") == ACCEPTED:
                again.append(folder.name)
        for job_id in again:
            self.submit(job_id)
        return again

    # --- looking -------------------------------------------------------------------------------------------

    def record(self, job_id: str) -> dict:
        if not ID.match(job_id) or job_id not in self.jobs:
            raise RequestError(404, f"job {job_id[:40]!r}: no such job")
        return self.jobs[job_id]

    def result_folder(self, record: dict) -> Optional[Path]:
        """The part's folder of an ended job, only when it lies in the job's own folder."""
        row = record.get("row") or {}
        if not row.get("folder"):
            return None
        folder = Path(row["folder"]).resolve()
        own = self.root / record["id"]
        return folder if folder.parent == own / OUT_DIR and folder.is_dir() else None

    def files(self, record: dict) -> list[str]:
        folder = self.result_folder(record)
        return sorted(p.name for p in folder.iterdir() if p.is_file()) if folder else []

    def file_path(self, job_id: str, name: str) -> Path:
        """A file of the job's own listing (the name compared, never joined unchecked)."""
        record = self.record(job_id)
        listing = self.files(record)
        if name not in listing:
            raise RequestError(404, f"file {name[:80]!r}: not among job {job_id}'s files ({', '.join(listing) or 'none yet'})")
        return self.result_folder(record) / name   # type: ignore[operator]

    def status(self, job_id: str) -> dict:
        """What the page and the API show: the state (queued, planning, verified, verification failed, failed),
        the seconds since it was accepted, and when ended the reason or the report's main figures and the files."""
        record = self.record(job_id)
        out = {"id": job_id, "source": record["source"], "recipe": record["recipe"],
               "seconds": round(record.get("ended", time.time()) - record["created"], 1)}
        if record["state"] == ACCEPTED:
            running = sorted((self.root / job_id / OUT_DIR).glob(".job-*"))   # run_part's folder while it plans
            if not running:
                return {**out, "state": "queued"}
            notes = [n for n in (progress_note.read(f / PROGRESS) for f in running) if n]
            return {**out, "state": "planning", **({"doing": progress_note.words(notes[-1])} if notes else {})}
        row = record.get("row") or {}
        state = row.get("state", record["state"])
        if state == "done before (skipped)":   # planned by a worker while the server restarted: its report says
            state = "verified" if row.get("passed") else "verification failed"
        out.update(state=state, files=self.files(record))
        if record["state"] == FAILED or row.get("reason"):
            out["reason"] = row.get("reason", "")
        if row.get("picture"):
            out["picture"] = row["picture"]
        report = self._report(record)
        if report:
            ver = report.get("verification", {})
            out["report"] = {"passed": report.get("passed"), "problems": report.get("problems", []),
                             **{k: ver.get(k) for k in REPORT_FIGURES},
                             "ops": [{"label": o.get("label"), "cycle_seconds": o.get("cycle_seconds")}
                                     for o in ver.get("ops", [])],
                             "decisions": [{"topic": d.get("topic"), "choice": d.get("choice")}
                                           for d in report.get("plan", {}).get("decisions", [])]}
        return out

    def _report(self, record: dict) -> Optional[dict]:
        folder = self.result_folder(record)
        if folder is None or not (folder / "report.json").is_file():
            return None
        try:
            return json.loads((folder / "report.json").read_text())
        except (OSError, ValueError):
            return None

    def listing(self) -> list[dict]:
        return [{"id": k, "state": v["state"], "created": v["created"], "source": v["source"]}
                for k, v in sorted(self._records(), key=lambda kv: kv[1]["created"])]
