"""The web front of seed 003 (docs/web.md): a page and an HTTP API to plan an uploaded STL, a sample or a sign on
the Dask cluster of `tmm batch`. The endpoints are async and leave every slow step (reading an upload, checking it
as STL, making a sign, opening the cluster) to threads, so the server answers while workers plan. Every refusal
is a 4xx with the reason as JSON `{"error": ...}`."""
from __future__ import annotations

import asyncio
import json
import shutil
from pathlib import Path
from typing import Any, Optional

from starlette.datastructures import UploadFile
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.requests import Request
from starlette.responses import FileResponse, HTMLResponse, JSONResponse, Response

from tmm_workbench.web import recipe as rc
from tmm_workbench.web.store import MAX_WAITING, JobStore

PAGE = Path(__file__).with_name("page.html")
FORM_FIELDS = {"model", "sample", "material", "finish", "machine", *rc.SIGN_FIELDS}
CHUNK = 1 << 20


class BodyTooLarge(Exception):
    pass


class BodyLimit:
    """ASGI middleware: a request body larger than `limit` bytes is refused with 413 (by its Content-Length before
    reading, or when the bytes read pass the limit), never spooled whole."""

    def __init__(self, app: Any, limit: int) -> None:
        self.app, self.limit = app, limit

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        length = dict(scope.get("headers") or []).get(b"content-length")
        if length is not None:
            if not length.isdigit():
                return await _send_error(send, 400, f"Content-Length: got {length[:40]!r}; a whole number")
            if int(length) > self.limit:
                await _drain(receive, 0, self.limit)
                return await _send_error(send, 413, _too_large(self.limit, int(length)))
        seen = 0

        async def limited() -> dict:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                if message.get("more_body"):
                    seen = await _drain(receive, seen, self.limit)
                raise BodyTooLarge(_too_large(self.limit, seen))
            return message

        await self.app(scope, limited, send)


async def _drain(receive: Any, seen: int, limit: int) -> int:
    """Reads and drops the rest of a refused body, up to twice the limit, so that the client, still sending, reads
    the 413 rather than a reset connection."""
    while seen <= 2 * limit:
        message = await receive()
        seen += len(message.get("body", b""))
        if message.get("type") != "http.request" or not message.get("more_body"):
            break
    return seen


def _too_large(limit: int, size: int) -> str:
    return f"request body of {size:,} bytes or more; the limit is {limit:,} bytes (the upload's {rc.MAX_UPLOAD_BYTES // 2**20} MB and the form)"


async def _send_error(send: Any, status: int, reason: str) -> None:
    body = json.dumps({"error": reason}).encode()
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode()),
                            (b"connection", b"close")]})
    await send({"type": "http.response.body", "body": body})


def error(status: int, reason: str) -> JSONResponse:
    return JSONResponse({"error": reason}, status_code=status)


def create_app(jobs_dir: Path, scheduler: Optional[str] = None, workers: int = 1, timeout_s: float = 3600.0,
               max_upload: int = rc.MAX_UPLOAD_BYTES):
    """The FastAPI app planning into `jobs_dir` on the cluster at `scheduler` or a local one of `workers`."""
    from fastapi import FastAPI

    rc.MAX_UPLOAD_BYTES = max_upload
    store = JobStore(jobs_dir, timeout_s)
    app = FastAPI(title="TMM web", docs_url=None, redoc_url=None, openapi_url=None)
    app.state.store = store
    cluster: list[Any] = []

    @app.on_event("startup")
    async def start() -> None:
        from tmm_workbench.batch.run import NO_DASHBOARD, open_client

        client, local = await asyncio.to_thread(open_client, scheduler, workers, NO_DASHBOARD)
        store.client = client
        cluster.append(local)
        await asyncio.to_thread(store.recover)

    @app.on_event("shutdown")
    async def stop() -> None:
        def close() -> None:
            if store.client is not None:
                store.client.close()
            if cluster and cluster[0] is not None:
                cluster[0].close()
        await asyncio.to_thread(close)

    @app.exception_handler(rc.RequestError)
    async def refused(request: Request, exc: rc.RequestError) -> JSONResponse:
        return error(exc.status, exc.reason)

    @app.exception_handler(StarletteHTTPException)
    async def http_error(request: Request, exc: StarletteHTTPException) -> JSONResponse:
        return error(exc.status_code, str(exc.detail))

    @app.exception_handler(BodyTooLarge)
    async def too_large(request: Request, exc: BodyTooLarge) -> JSONResponse:
        return error(413, str(exc))

    @app.exception_handler(Exception)
    async def internal(request: Request, exc: Exception) -> JSONResponse:   # a bug: said, never a crash
        return error(500, f"internal error: {type(exc).__name__}: {exc}")

    @app.get("/")
    async def page() -> HTMLResponse:
        return HTMLResponse(PAGE.read_text(encoding="utf-8"))

    @app.get("/api/choices")
    async def choices() -> dict:
        return await asyncio.to_thread(rc.choices)

    @app.get("/api/jobs")
    async def jobs() -> dict:
        return {"jobs": store.listing()}

    @app.post("/api/jobs", status_code=202)
    async def submit(request: Request) -> JSONResponse:
        if store.client is None:
            raise rc.RequestError(503, "the server is starting: try again in a few seconds")
        if store.waiting() >= MAX_WAITING:
            raise rc.RequestError(429, f"{MAX_WAITING} jobs are waiting to be planned: try again later")
        kind = request.headers.get("content-type", "").split(";")[0].strip()
        if kind not in ("multipart/form-data", "application/x-www-form-urlencoded"):
            raise rc.RequestError(415, f"Content-Type: got {kind or 'none'!r}; multipart/form-data (a form, with the "
                                       "STL as the field model) or application/x-www-form-urlencoded")
        try:
            form = await request.form(max_files=2, max_fields=40)
        except (BodyTooLarge, StarletteHTTPException, rc.RequestError):
            raise
        except Exception as exc:   # a malformed body: the parser's reason
            raise rc.RequestError(400, f"the form could not be read: {type(exc).__name__}: {exc}") from None
        try:
            record = await _accept(store, form)
        finally:
            await form.close()
        return JSONResponse(await asyncio.to_thread(store.status, record["id"]), status_code=202)

    @app.get("/api/jobs/{job_id}")
    async def status(job_id: str) -> dict:
        return await asyncio.to_thread(store.status, job_id)   # reads the report from disk

    @app.get("/api/jobs/{job_id}/files/{name}")
    async def file(job_id: str, name: str) -> Response:
        path = await asyncio.to_thread(store.file_path, job_id, name)
        return FileResponse(path, filename=name)

    return BodyLimit(app, max_upload + 256 * 1024)


async def _accept(store: JobStore, form: Any) -> dict:
    """The form's model (upload, sample or sign) in a new job folder, checked; the job accepted."""
    keys = [k for k, _ in form.multi_items()]
    unknown = sorted(set(keys) - FORM_FIELDS)
    if unknown:
        raise rc.RequestError(400, f"unknown field(s) {', '.join(k[:40] for k in unknown)}; allowed: "
                                   f"{', '.join(sorted(FORM_FIELDS))}")
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise rc.RequestError(400, f"field {twice[0][:40]} given twice")
    given = [k for k in ("model", "sample", "text") if form.get(k) not in (None, "")]
    if len(given) != 1:
        raise rc.RequestError(400, f"give one model: an STL upload (model), a sample name (sample) or a sign "
                                   f"(text and its fields); got {', '.join(given) or 'none'}")
    sign_fields = sorted(k for k in keys if k in rc.SIGN_FIELDS and k != "text" and form.get(k) != "")
    if given[0] != "text" and sign_fields:
        raise rc.RequestError(400, f"sign field(s) {', '.join(sign_fields)} given with a {given[0]}: only for a sign")
    recipe = rc.recipe_of(form)
    folder = store.new_folder()
    try:
        source = await asyncio.to_thread(_model_into, form, given[0], recipe, folder / rc.MODEL_FILE)
        return await asyncio.to_thread(store.accept, folder, recipe, source)
    except BaseException:
        store.discard(folder)
        raise


def _model_into(form: Any, kind: str, recipe: rc.Recipe, target: Path) -> str:
    """Writes the model to `target` (a thread's work: copying, reading the STL, making a sign); its source."""
    if kind == "model":
        upload = form["model"]
        if not isinstance(upload, UploadFile):
            raise rc.RequestError(400, "model: got a text field; an STL file upload")
        size = _copy_bounded(upload, target)
        with open(target, "rb") as f:
            rc.check_stl_bytes(f.read(8), size)
        rc.check_stl_file(target)
        return "upload"
    if kind == "sample":
        shutil.copyfile(rc.sample_of(form), target)
        return f"sample {form['sample']}"
    from tmm_workbench.core.errors import TmmError
    from tmm_workbench.core.geometry.mesh import save_stl
    from tmm_workbench.core.geometry.sign import make_sign

    spec = rc.sign_spec(form, recipe)
    try:
        mesh = make_sign(spec).mesh
    except TmmError as exc:
        raise rc.RequestError(400, str(exc)) from None
    save_stl(mesh, target)
    return f"sign {spec.text!r}"


def _copy_bounded(upload: UploadFile, target: Path) -> int:
    size = 0
    upload.file.seek(0)
    with open(target, "wb") as out:
        while True:
            chunk = upload.file.read(CHUNK)
            if not chunk:
                return size
            size += len(chunk)
            if size > rc.MAX_UPLOAD_BYTES:
                raise rc.RequestError(413, f"model: more than {rc.MAX_UPLOAD_BYTES:,} bytes; the upload limit is "
                                           f"{rc.MAX_UPLOAD_BYTES // 2**20} MB")
            out.write(chunk)
