"""The web front's HTTP API on the real server and a real local Dask cluster: a sign made through the API planned
to G-code; bad uploads (not an STL, truncated, oversized, a zip) and malformed requests refused with a 4xx and the
reason, the server answering afterwards; a model larger than the machine refused by the planner's own check as
the job's failure; a restart keeping the accepted jobs and planning the one not ended (the second server on an existing Dask
cluster, --scheduler)."""
from __future__ import annotations

import http.client
import io
import json
import random
import time
import zipfile

import pytest

from tests.web.conftest import RECIPE, multipart, start_server
from tmm_workbench.core.shared_data import benchmark_file

pytestmark = pytest.mark.xdist_group("web")   # servers with clusters of their own: one such test at a time
BEET = benchmark_file("stl", "beet_mm.stl")
SIGN = {"text": "TMM", "width": "60", "height": "30", "shape": "rounded", "border": "3", "relief": "2",
        "background": "plain", "thickness": "5"}


def _refused(code: int, data: dict, status: int, *words: str) -> None:
    assert code == status, (code, data)
    assert all(w in data["error"] for w in words), data


def test_a_sign_made_through_the_api_plans_to_gcode(server):
    code, job = server.post_job({**SIGN, **RECIPE})
    assert code == 202 and job["state"] in ("queued", "planning") and job["source"] == "sign 'TMM'", job
    code, data = server.call("GET", f"/api/jobs/{job['id']}")   # answered while a worker plans
    assert code == 200 and json.loads(data)["state"] in ("queued", "planning", "verified")
    st = server.wait(job["id"])
    assert st["state"] == "verified" and st["report"]["passed"], st
    assert {"part.ngc", "part.FCStd", "part_sim.png", "toolpath.png", "report.json"} <= set(st["files"])
    code, gcode = server.call("GET", f"/api/jobs/{job['id']}/files/part.ngc")
    folder = next((server.jobs / job["id"] / "out").glob("job-*"))
    assert code == 200 and gcode == (folder / "part.ngc").read_bytes()
    assert gcode.count(b"\nG1") > 100 and st["report"]["cycle_seconds"] > 0
    code, png = server.call("GET", f"/api/jobs/{job['id']}/files/part_sim.png")
    assert code == 200 and png.startswith(b"\x89PNG")
    code, data = server.call("GET", f"/api/jobs/{job['id']}/files/state.json")   # in its folder, not its listing
    _refused(code, json.loads(data), 404, "not among")


def test_bad_uploads_refused_with_the_reason(server):
    beet = BEET.read_bytes()
    zipped = io.BytesIO()
    with zipfile.ZipFile(zipped, "w") as z:
        z.writestr("beet_mm.stl", beet)
    cases = [(b"hello, not a mesh\n", 400, "not a readable STL"),
             (beet[: len(beet) // 3], 400, "not a readable STL"),   # truncated
             (zipped.getvalue(), 400, "zip"),
             (b"", 400, "empty"),
             (beet + b"\0" * (2 * 2 ** 20), 413, "limit")]          # over the test server's 2 MB
    before = set(server.jobs.iterdir()) if server.jobs.is_dir() else set()
    for data, status, word in cases:
        code, body = server.post_job(RECIPE, {"model": ("x.stl", data)})
        _refused(code, body, status, word)
    assert set(server.jobs.iterdir()) == before   # nothing kept of a refused upload
    code, body = server.post_job(RECIPE, {"model": ("../../etc/evil.stl", beet)})   # its name is never used
    assert code == 202, body
    assert {p.name for p in (server.jobs / body["id"]).iterdir()} <= {"job.yaml", "model.stl", "out", "state.json"}
    assert not [p for p in server.jobs.parent.rglob("*evil*")] and not (server.jobs.parents[1] / "etc").exists()


@pytest.mark.parametrize("fields, status, words", [
    ({"sample": "../../../etc/passwd", **RECIPE}, 400, ("sample", "beet_mm.stl")),
    ({"sample": "beet_mm.stl", **RECIPE, "material": "cheese"}, 400, ("material", "cheese")),
    ({"sample": "beet_mm.stl", **RECIPE, "finish": ""}, 400, ("finish",)),
    ({"sample": "beet_mm.stl", "material": "mdf"}, 400, ("finish",)),
    ({**RECIPE}, 400, ("one model",)),
    ({"sample": "beet_mm.stl", "text": "A", **RECIPE}, 400, ("one model",)),
    ({"sample": "beet_mm.stl", "width": "50", **RECIPE}, 400, ("only for a sign",)),
    ({"sample": "beet_mm.stl", "path": "/etc", **RECIPE}, 400, ("unknown field", "path")),
    ({"sample": "beet_mm.stl", **RECIPE, "_twice": "material=mdf"}, 400, ("material", "twice")),
    ({**SIGN, "width": "wide", **RECIPE}, 400, ("width", "wide")),
    ({**SIGN, "width": "nan", **RECIPE}, 400, ("width",)),
    ({**SIGN, "text": "<script>", **RECIPE}, 400, ("sign text",)),
    ({**SIGN, "shape": "star", **RECIPE}, 400, ("shape", "star")),
    ({**SIGN, "width": "600", "height": "600", **RECIPE}, 400, ("triangles",)),
])
def test_malformed_forms_refused_with_the_reason(server, fields, status, words):
    fields = dict(fields)
    body, kind = multipart({k: v for k, v in fields.items() if k != "_twice"})
    if "_twice" in fields:   # a field sent twice (a dict cannot hold it)
        name, value = fields["_twice"].split("=")
        boundary = kind.split("=")[1]
        body = f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"\r\n\r\n{value}\r\n'.encode() + body
    code, data = server.call("POST", "/api/jobs", body, {"Content-Type": kind})
    body = json.loads(data)
    _refused(code, body, status, *words)


def test_malformed_requests_refused_and_the_server_answers_after(server):
    for method, path, body, headers, status in [
            ("POST", "/api/jobs", b"{}", {"Content-Type": "application/json"}, 415),
            ("POST", "/api/jobs", b"garbage", {"Content-Type": "multipart/form-data; boundary=xx"}, 400),
            ("POST", "/api/jobs", b"garbage", {"Content-Type": "multipart/form-data"}, 400),
            ("POST", "/api/jobs", b"x" * (3 * 2 ** 20), {"Content-Type": "application/x-www-form-urlencoded"}, 413),
            ("GET", "/api/jobs/0123456789abcdef0123456789abcdef", None, {}, 404),
            ("GET", "/api/jobs/..%2F..%2Fetc/files/passwd", None, {}, 404),
            ("GET", "/api/jobs/zzz/files/part.ngc", None, {}, 404),
            ("DELETE", "/api/jobs", None, {}, 405)]:
        code, data = server.call(method, path, body, headers)
        assert code == status, (method, path, code, data)
        assert json.loads(data)["error"], data
    code, data = server.call("GET", "/api/jobs")
    assert code == 200 and "jobs" in json.loads(data)
    assert server.proc.poll() is None


def test_a_streamed_upload_over_the_limit_is_refused_as_it_comes(server):
    """Chunked, without a Content-Length: the bytes counted as they arrive."""
    body, kind = multipart(RECIPE, {"model": ("big.stl", b"\0" * (3 * 2 ** 20))})
    conn = http.client.HTTPConnection("127.0.0.1", server.port, timeout=60)
    try:
        conn.request("POST", "/api/jobs", body=(body[i:i + 65536] for i in range(0, len(body), 65536)),
                     headers={"Content-Type": kind}, encode_chunked=True)
        r = conn.getresponse()
        assert r.status == 413 and "limit" in json.loads(r.read())["error"]
    finally:
        conn.close()
    assert server.call("GET", "/api/jobs")[0] == 200


def test_random_bodies_never_crash_the_server(server):
    rng = random.Random(3)
    pieces = [b"--b\r\n", b"Content-Disposition: form-data; name=\"model\"; filename=\"a.stl\"\r\n\r\n", b"\r\n",
              b"solid x\n facet normal 0 0 1\n", b"--b--\r\n", b"name=\"material\"\r\n\r\nmdf", b"\0\xff", b"=&%"]
    for _ in range(40):
        body = b"".join(rng.choice(pieces) for _ in range(rng.randint(0, 12)))
        kind = rng.choice(["multipart/form-data; boundary=b", "multipart/form-data", "application/x-www-form-urlencoded",
                           "text/plain", "multipart/form-data; boundary="])
        code, data = server.call("POST", "/api/jobs", body, {"Content-Type": kind})
        assert 400 <= code < 500 and json.loads(data)["error"], (body, kind, code, data)
    assert server.proc.poll() is None and server.call("GET", "/api/choices")[0] == 200


def test_a_model_larger_than_the_machine_fails_with_the_planners_reason(server):
    code, job = server.post_job({**SIGN, "text": "WIDE", "width": "400", "height": "20", "border": "0", **RECIPE})
    assert code == 202, job
    st = server.wait(job["id"])
    assert st["state"] == "bad input" and "travel" in st["reason"] and "400" in st["reason"], st
    assert "part.ngc" not in st["files"]


def test_a_restarted_server_keeps_its_jobs_and_plans_the_unfinished(tmp_path):
    jobs, log = tmp_path / "jobs", tmp_path / "server.log"
    first = start_server(jobs, log, "--workers", "1")
    try:
        code, refused = first.post_job({**SIGN, "text": "WIDE", "width": "400", "height": "20", "border": "0",
                                        **RECIPE})
        assert code == 202 and first.wait(refused["id"])["state"] == "bad input"
        code, job = first.post_job({"sample": "beet_mm.stl", **RECIPE})
        assert code == 202, job
        seen = []   # the server answers while its worker plans; stopped in the middle of the plan
        while not seen or seen[-1] == "queued":
            seen.append(first.status(job["id"])["state"])
            time.sleep(0.2)
        assert seen[-1] == "planning", seen
        doing, end = None, time.monotonic() + 60   # what the planner says it does (its progress note)
        while doing is None and time.monotonic() < end:
            doing = first.status(job["id"]).get("doing")
            time.sleep(0.1)
        assert doing and ("the model" in doing or "step" in doing), doing
    finally:
        assert first.stop() == 0, log.read_text()[-2000:]
    assert json.loads((jobs / job["id"] / "state.json").read_text())["state"] == "accepted"
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        _after_restart(start_server(jobs, log, "--scheduler", cluster.scheduler_address), refused, job)


def _after_restart(second, refused: dict, job: dict) -> None:
    """The restarted server (on an existing cluster: --scheduler) lists both jobs and plans the one not ended."""
    jobs = second.jobs
    try:
        code, data = second.call("GET", "/api/jobs")
        listed = {j["id"]: j for j in json.loads(data)["jobs"]}
        assert set(listed) == {refused["id"], job["id"]}
        again = second.status(refused["id"])
        assert again["state"] == "bad input" and "travel" in again["reason"]
        st = second.wait(job["id"])
        assert st["state"] == "verified" and st["report"]["passed"], st
        assert not [p for p in (jobs / job["id"] / "out").iterdir() if p.name.startswith(".")]
    finally:
        assert second.stop() == 0, second.log.read_text()[-2000:]
