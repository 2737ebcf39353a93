"""The studio's ASGI application (Starlette): the page, its static files and the JSON endpoints of :mod:`.api`.

Every request body is JSON (``Content-Type: application/json``, so that other web sites cannot post to it without
a CORS preflight), at most :data:`MAX_BODY` bytes. A user's mistake answers 4xx with ``{"error": message}``
(and ``loc``/``field``/``message`` for a :class:`~wmrkit.errors.DescriptionError`); nothing a request holds can
stop the server. Files: only the package's ``static/`` folder is served, and descriptions only inside `root`.
"""

from __future__ import annotations

import json
import logging
import math
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

from .. import catalog
from ..errors import DescriptionError, WmrkitError
from ..robot import Robot
from . import api, files

#: Largest accepted request body [bytes].
MAX_BODY = 1_000_000
#: Host names of this machine: the ``Host`` headers a studio on a loopback interface answers.
LOCAL_HOSTS = ["127.0.0.1", "localhost", "::1", "[::1]"]
#: Sent with every answer: no other site may frame the page (clickjacking), and the page loads and runs only the
#: studio's own files (it needs nothing else: no CDN, no inline script or style).
SECURITY_HEADERS = {
    "X-Frame-Options": "DENY",
    "Content-Security-Policy": "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
                               "connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'none'; "
                               "frame-ancestors 'none'",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
}

log = logging.getLogger("wmrkit.studio")


def require_starlette() -> None:
    """Raise a :class:`WmrkitError` naming the 'studio' extra when Starlette or uvicorn is missing."""
    try:
        import starlette  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError:
        raise WmrkitError("the 'studio' extra is needed: pip install 'wmrkit[studio]'") from None


def static_dir() -> Path:
    """The folder of the page's files (package data)."""
    return Path(str(resources.files("wmrkit.studio").joinpath("static")))


class _HTTPError(Exception):
    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def create_app(root: str | Path = ".", robot: Robot | None = None, *, robot_spec: str | None = None,
               allowed_hosts: list[str] | None = None):
    """The Starlette app serving the studio for files under `root`, starting with `robot` (default: diff-drive).

    `robot_spec` is what the user named (a catalog name or a file path relative to `root`), shown by the page.
    `allowed_hosts`: the only ``Host`` headers answered (against DNS rebinding: a web page whose name is made to
    resolve to 127.0.0.1 must not reach the studio); None answers any (the test client's ``testserver``).
    """
    require_starlette()
    from starlette.applications import Starlette
    from starlette.concurrency import run_in_threadpool
    from starlette.exceptions import HTTPException
    from starlette.middleware import Middleware
    from starlette.responses import FileResponse, Response
    from starlette.routing import Mount, Route
    from starlette.staticfiles import StaticFiles

    root = Path(root).resolve()
    start = robot or catalog.load("diff-drive")
    static = static_dir()

    def respond(data: Any, status: int = 200) -> Response:
        # ASCII JSON: a lone surrogate of the request ("\ud800"), quoted by a message, stays an escape (JSONResponse
        # wrote UTF-8, which cannot encode it: a plain-text 500 outside the handlers).
        body = json.dumps(_finite(data), ensure_ascii=True, allow_nan=False, separators=(",", ":"))
        return Response(body, status_code=status, media_type="application/json")

    def endpoint(fn: Callable[[Any], Any], *, body: bool = True, thread: bool = False):
        """`thread`: run in a worker thread, so that a slow answer does not hold up the other requests (the live
        analysis of a 64-wheel robot takes over a second; opening a 256 KiB YAML file, seconds). Save stays on the
        event loop: it checks that its file does not exist and writes it in one step, with no other request in
        between."""

        async def handle(request) -> Response:
            t0 = time.perf_counter()
            try:
                payload = await _read_json(request) if body else None
                data = await run_in_threadpool(fn, payload) if thread else fn(payload)
            except _HTTPError as err:
                return respond({"error": str(err)}, err.status)
            except files.ForbiddenPathError as err:
                return respond({"error": str(err)}, 403)
            except files.FileExistsStudioError as err:
                return respond({"error": str(err), "exists": True}, 409)
            except DescriptionError as err:
                return respond({"error": str(err), "message": err.message, "loc": list(err.loc),
                                "field": _field_name(err.loc)}, 422)
            except WmrkitError as err:
                return respond({"error": str(err)}, 400)
            except Exception as err:  # a bug: answer it, log it, keep serving
                log.exception("studio: internal error")
                return respond({"error": f"internal error ({err.__class__.__name__}); please report it"}, 500)
            response = respond(data)
            response.headers["Server-Timing"] = f"app;dur={(time.perf_counter() - t0) * 1e3:.2f}"
            return response

        return handle

    start_file = robot_spec if robot_spec and Path(robot_spec).suffix.lower() in files.SUFFIXES else None
    last_good: dict[str, Any] = {"description": api.description_of(start), "warnings": []}

    def start_robot() -> dict[str, Any]:
        """The robot the page starts with. A start file is read again (it may have been edited since: a reload
        showed the robot read at start, and Save then wrote it over the edit); one now invalid or gone keeps the
        last good robot, with the error naming the file. ``warnings``: the description's (of that robot)."""
        out: dict[str, Any] = {"spec": robot_spec or start.name}
        if start_file is not None:
            try:
                opened = files.open_robot(root, {"path": start_file})
                last_good.update(description=opened["description"], warnings=opened["warnings"])
            except WmrkitError as err:
                out["error"] = str(err)
        return out | {"description": last_good["description"], "warnings": last_good["warnings"]}

    def meta(_: Any) -> dict[str, Any]:
        return {"catalog": list(catalog.names()), "kinds": api.kinds(), "root": root.name or str(root),
                "files": files.list_files(root), "start": start_robot()}

    async def http_error(request, err: HTTPException) -> Response:  # 404, 405: JSON as every other mistake
        response = respond({"error": f"{err.detail}: {request.method} {request.url.path[:200]}"}, err.status_code)
        response.headers.update(err.headers or {})  # a 405's Allow
        return response

    async def index(request) -> Response:
        return FileResponse(static / "index.html", headers={"Cache-Control": "no-store"})

    routes = [
        Route("/", index),
        Route("/favicon.ico", lambda request: Response(status_code=204)),
        Route("/api/meta", endpoint(meta, body=False, thread=True)),
        Route("/api/files", endpoint(lambda _: {"files": files.list_files(root)}, body=False, thread=True)),
        Route("/api/open", endpoint(lambda p: files.open_robot(root, p), thread=True), methods=["POST"]),
        Route("/api/save", endpoint(lambda p: files.save_robot(root, p)), methods=["POST"]),
        Route("/api/analyze", endpoint(api.analyze_live, thread=True), methods=["POST"]),
        Route("/api/configurations", endpoint(api.configurations, thread=True), methods=["POST"]),
        Route("/api/drive", endpoint(api.drive, thread=True), methods=["POST"]),
        Route("/api/kappa", endpoint(api.kappa_map, thread=True), methods=["POST"]),
        Mount("/static", app=StaticFiles(directory=str(static)), name="static"),
    ]
    middleware = [Middleware(_SecurityHeaders)]
    if allowed_hosts is not None:
        middleware.append(Middleware(_HostCheck, allowed_hosts=allowed_hosts))
    return Starlette(routes=routes, middleware=middleware, exception_handlers={HTTPException: http_error})


class _SecurityHeaders:
    """ASGI middleware adding :data:`SECURITY_HEADERS` to every HTTP answer (static files and errors included)."""

    def __init__(self, app) -> None:
        self.app = app

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def with_headers(message) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", []))
                present = {k.lower() for k, _ in headers}
                headers += [(k.lower().encode(), v.encode()) for k, v in SECURITY_HEADERS.items()
                            if k.lower().encode() not in present]
                message = {**message, "headers": headers}
            await send(message)

        await self.app(scope, receive, with_headers)


class _HostCheck:
    """Starlette's ``TrustedHostMiddleware`` (only the ``Host`` names `allowed_hosts`: against DNS rebinding), its
    refusal answered as every other mistake, ``{"error": ...}`` naming the host and the names answered (it was the
    plain text 'Invalid host header')."""

    def __init__(self, app, allowed_hosts: list[str]) -> None:
        from starlette.middleware.trustedhost import TrustedHostMiddleware

        self.app, self.allowed = app, allowed_hosts
        self.check = TrustedHostMiddleware(self._passed, allowed_hosts=allowed_hosts, www_redirect=False)

    async def _passed(self, scope, receive, send) -> None:
        scope["wmrkit.host_passed"] = True
        await self.app(scope, receive, send)

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        answer = send

        async def refused(message) -> None:  # the check's own plain-text answer: replaced below
            if not scope.get("wmrkit.host_passed"):
                return
            await answer(message)

        await self.check(scope, receive, refused)
        if not scope.get("wmrkit.host_passed"):
            from starlette.datastructures import Headers
            from starlette.responses import Response

            host = Headers(scope=scope).get("host", "")
            shown = repr(host) if len(host) <= 80 else repr(host[:77] + "...")
            message = (f"host {shown} refused: the studio answers only {', '.join(dict.fromkeys(self.allowed))} "
                       "(a web site whose name leads here must not reach it; docs/studio.md)")
            body = json.dumps({"error": message}, ensure_ascii=True)
            await Response(body, status_code=400, media_type="application/json")(scope, receive, send)


async def _read_json(request) -> Any:
    """The request's JSON body, refusing other content types, bodies over MAX_BODY, malformed JSON and a key given
    twice in one object."""
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind != "application/json":
        raise _HTTPError(415, "send JSON (Content-Type: application/json)")
    declared = request.headers.get("content-length")
    if declared is not None and (not declared.isdigit() or int(declared) > MAX_BODY):
        raise _HTTPError(413, f"request too large (limit {MAX_BODY} bytes)")
    chunks, size = [], 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > MAX_BODY:
            raise _HTTPError(413, f"request too large (limit {MAX_BODY} bytes)")
        chunks.append(chunk)
    try:
        return json.loads(b"".join(chunks).decode("utf-8"), parse_constant=_no_constant, object_pairs_hook=_no_twice)
    except (ValueError, RecursionError) as err:
        raise _HTTPError(400, f"malformed JSON: {str(err).splitlines()[0][:200]}") from None


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a number JSON allows")


def _no_twice(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object whose keys are all different (as description files: the last of two was taken silently)."""
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set[str] = set()
        twice = next(k for k, _ in pairs if k in seen or seen.add(k))
        raise ValueError(f"field {twice[:80]!r} given twice")
    return out


def _field_name(loc: tuple) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in loc).lstrip(".")


def _finite(x: Any) -> Any:
    """JSON has no NaN or infinities: they become null (recursively through lists and mappings)."""
    if isinstance(x, dict | list | tuple):
        return {k: _finite(v) for k, v in x.items()} if isinstance(x, dict) else [_finite(v) for v in x]
    return None if isinstance(x, float) and not math.isfinite(x) else x
