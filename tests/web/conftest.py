"""The web front's server as a user meets it: `python3 -m tmm_workbench.web` in a process of its own on a free port,
its own local Dask cluster, a jobs folder of the test's; and a small HTTP client (urllib, multipart by hand)."""
from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import pytest

ROOT = Path(__file__).resolve().parents[2]
RECIPE = {"material": "modelling_foam", "finish": "draft", "machine": "3-axis linuxcnc"}   # plan_beet's values
ENDED = ("verified", "verification failed", "bad input", "failed")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def multipart(fields: dict, files: Optional[dict] = None) -> tuple[bytes, str]:
    """The body and content type of a form: `fields` name -> text, `files` name -> (file name, bytes)."""
    boundary = uuid.uuid4().hex
    parts = []
    for name, value in fields.items():
        parts.append(f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"\r\n\r\n{value}\r\n'.encode())
    for name, (filename, data) in (files or {}).items():
        parts.append(f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"; filename="{filename}"\r\n'
                     f'Content-Type: application/octet-stream\r\n\r\n'.encode() + data + b"\r\n")
    return b"".join(parts) + f"--{boundary}--\r\n".encode(), f"multipart/form-data; boundary={boundary}"


@dataclass
class Server:
    port: int
    jobs: Path
    proc: subprocess.Popen
    log: Path

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def call(self, method: str, path: str, body: Optional[bytes] = None,
             headers: Optional[dict] = None) -> tuple[int, bytes]:
        req = urllib.request.Request(self.url + path, data=body, method=method, headers=headers or {})
        try:
            with urllib.request.urlopen(req, timeout=60) as r:
                return r.status, r.read()
        except urllib.error.HTTPError as e:
            return e.code, e.read()

    def post_job(self, fields: dict, files: Optional[dict] = None) -> tuple[int, dict]:
        body, kind = multipart(fields, files)
        code, data = self.call("POST", "/api/jobs", body, {"Content-Type": kind})
        return code, json.loads(data)

    def status(self, job_id: str) -> dict:
        code, data = self.call("GET", f"/api/jobs/{job_id}")
        assert code == 200, data
        return json.loads(data)

    def wait(self, job_id: str, limit_s: float = 120.0) -> dict:
        end = time.monotonic() + limit_s
        while time.monotonic() < end:
            st = self.status(job_id)
            if st["state"] in ENDED:
                return st
            time.sleep(0.5)
        raise AssertionError(f"job {job_id} not ended after {limit_s} s: {st}")

    def stop(self) -> int:
        """SIGTERM (a service stopped): uvicorn's shutdown closes the cluster."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode


def start_server(jobs: Path, log: Path, *args: str) -> Server:
    port = free_port()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    with open(log, "ab") as out:
        proc = subprocess.Popen([sys.executable, "-m", "tmm_workbench.web", "--port", str(port), "--jobs", str(jobs),
                                 *args], cwd=str(ROOT), env=env, stdout=out, stderr=subprocess.STDOUT)
    server = Server(port, jobs, proc, log)
    end = time.monotonic() + 60
    while time.monotonic() < end:
        if proc.poll() is not None:
            raise AssertionError(f"the server exited with {proc.returncode}: {log.read_text()[-2000:]}")
        try:
            if server.call("GET", "/api/choices")[0] == 200:
                return server
        except OSError:
            pass
        time.sleep(0.3)
    server.stop()
    raise AssertionError(f"the server did not answer in 60 s: {log.read_text()[-2000:]}")


@pytest.fixture(scope="session")
def server(tmp_path_factory):
    """One server for the tests that need no restart: two local workers, a 2 MB upload limit (the samples are
    smaller, the oversized upload need not be 50 MB)."""
    base = tmp_path_factory.mktemp("web")
    s = start_server(base / "jobs", base / "server.log", "--workers", "2", "--max-upload-mb", "2")
    yield s
    assert s.stop() == 0, s.log.read_text()[-2000:]
