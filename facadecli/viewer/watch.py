"""``facade watch SPEC``: a live preview. The spec is solved again on every complete save
(:mod:`facadecli.viewer.saves`: the kernel's file events, or polling where there are none)
and the viewer's page is served on 127.0.0.1. The page holds one event stream open
(``/events``, server-sent events): when a new layout is ready the server pushes it, model
and elevation, and the page swaps them in place, the camera where the user left it. A
spec with an error keeps the last good model on the page under a banner with the error
(its file, line and column, and the hint).

The spec is read as every reader of specs reads it: at most
:data:`~facadecli.limits.SPEC_BYTES_MAX` bytes, and only a regular file (a link to
``/dev/zero`` or a pipe is an error on the page, not a hung or dead server). A file that
changes while it is read is read again at its next save.

Only this machine can reach the server (127.0.0.1), and only pages it served can read it:
a request whose ``Host`` is not ``127.0.0.1:PORT`` or ``localhost:PORT`` is refused (403),
so a web page that rebinds its own name to 127.0.0.1 gets nothing. Connections are
bounded (:data:`~facadecli.limits.WATCH_CONNECTIONS_MAX`, of them
:data:`~facadecli.limits.WATCH_STREAMS_MAX` event streams); an idle one is closed after
:data:`~facadecli.limits.WATCH_IDLE_SECONDS`, and one whose request's line and headers
have not all arrived :data:`~facadecli.limits.WATCH_REQUEST_SECONDS` after it began (a
byte now and then, to hold a connection forever) too. A client that goes away early is
nothing to report. Solving runs in the serving process, warm, one save at a time.
"""

from __future__ import annotations

import base64
import hashlib
import io
import json
import select
import socket
import socketserver
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from facadecli.errors import FacadeError, SpecError
from facadecli.files import NotRegularFile, read_regular_at_most
from facadecli.limits import (
    SPEC_BYTES_MAX,
    WATCH_CONNECTIONS_MAX,
    WATCH_IDLE_SECONDS,
    WATCH_REQUEST_SECONDS,
    WATCH_STREAMS_MAX,
)
from facadecli.viewer.saves import Saves, watch_saves

KEEP_ALIVE = 5.0  # seconds between comments on a quiet event stream (a gone page shows)
LOOK = 0.5  # seconds between looks at whether a quiet stream's page closed it
RETRY_MS = 1000  # how soon a page's event stream connects again after losing the server
WAIT = 0.2  # seconds between the serving loop's looks at whether it should stop

# the page's own code: the event stream's "layout" swaps in the model and elevation, its
# "state" shows or hides the error banner; a page made before any layout reloads instead
LIVE = """
<div id="watch-error" style="display:none;position:fixed;left:0;right:0;top:0;padding:8px 12px;
background:#7a1d1d;color:#fff;font:13px monospace;white-space:pre-wrap;z-index:9"></div>
<script>
(function () {
  var box = document.getElementById('watch-error');
  var shown = VERSION, events;
  function follow() {  // a stream closed for good (a 503: too many pages) is opened again
    events = new EventSource('/events?since=' + shown);
    events.addEventListener('layout', swap);
    events.addEventListener('state', banner);
    events.onerror = function () {
      if (events.readyState === EventSource.CLOSED) setTimeout(follow, 3000);
    };
  }
  function swap(event) {
    var layout = JSON.parse(event.data);
    var model = document.getElementById('glb');
    if (!model || !window.facadeShow) { location.reload(); return; }
    model.textContent = layout.glb;
    var old = document.querySelector('#side svg');
    if (old) old.outerHTML = layout.svg;
    window.facadeShow('glb', true);
    shown = layout.version;
    document.documentElement.dataset.version = layout.version;
  }
  function banner(event) {
    var state = JSON.parse(event.data);
    box.style.display = state.error ? 'block' : 'none';
    box.textContent = state.error || '';
  }
  follow();
})();
</script>
"""


def live_script(version: int) -> str:
    """The page's live code, for a page showing layout ``version``."""
    return LIVE.replace("VERSION", str(version))


class _Unsettled(Exception):
    """The file changed while it was read: its next save is read instead."""


def read_spec(path: Path) -> bytes:
    """The spec's bytes as saved: a SpecError when it is missing, not a regular file or
    longer than :data:`SPEC_BYTES_MAX` (at most one byte more is read); _Unsettled when
    its size or time changed while it was read."""
    where = str(path)
    try:
        raw, opened = read_regular_at_most(path, SPEC_BYTES_MAX)
        after = path.stat()
    except FileNotFoundError:
        raise SpecError.at(where, None, None, "no such file", "save the spec again") from None
    except NotRegularFile:
        raise SpecError.at(
            where,
            None,
            None,
            "not a regular file (a device, a pipe or a folder)",
            "save the spec as a file of YAML",
        ) from None
    except OSError as error:
        raise SpecError.at(
            where, None, None, f"cannot read: {error.strerror}", "check its permissions"
        ) from None
    if raw is None:
        raise SpecError.at(
            where,
            None,
            None,
            f"the file is longer than specs are limited to ({SPEC_BYTES_MAX:,} bytes, "
            "SPEC_BYTES_MAX)",
            "a spec is a page of YAML: generate repeated layers with patterns",
        )
    if (opened.st_ino, opened.st_size, opened.st_mtime_ns) != (
        after.st_ino,
        after.st_size,
        after.st_mtime_ns,
    ):
        raise _Unsettled
    return raw


@dataclass
class Preview:
    """What the server shows: the page of the last good layout, and the state. Every
    change (a new layout, a new error) bumps ``serial`` and wakes the event streams."""

    spec: Path
    version: int = 0  # a new page, each time one is made
    page: str = "<!doctype html><title>solving</title><p>solving...</p>" + live_script(0)
    glb: str = ""  # the model, base64 (what the page's element holds)
    svg: str = ""  # the elevation, inline
    error: str = ""  # why the spec as saved has no layout (empty when it has one)
    solved_ms: float = 0.0
    seen: str = ""  # the file's fingerprint when it was last solved
    serial: int = 0
    closing: bool = False
    changed: threading.Condition = field(default_factory=threading.Condition)

    def state(self) -> dict[str, object]:
        with self.changed:
            return {
                "version": self.version,
                "ok": not self.error,
                "error": self.error,
                "solved_ms": round(self.solved_ms, 1),
            }

    def refresh(self) -> bool:
        """Solve the spec again if its saved content changed; True when it did."""
        try:
            raw = read_spec(self.spec)
        except _Unsettled:
            return False
        except SpecError as error:  # missing, not a file, too long: the page says so
            return self._new(f"unreadable: {error}") and self._change(error=str(error))
        if not self._new(hashlib.sha256(raw).hexdigest()):
            return False
        started = time.perf_counter()
        try:
            page, glb, svg = _page(self.spec, raw, self.version + 1)
        except FacadeError as error:
            return self._change(error=str(error))
        except Exception as error:  # a bug: shown, and the preview goes on with the next save
            return self._change(
                error=f"{self.spec}: internal error: {type(error).__name__}: {error}"
            )
        solved_ms = (time.perf_counter() - started) * 1000
        return self._change(
            page=page, glb=glb, svg=svg, error="", version=self.version + 1, solved_ms=solved_ms
        )

    def moved(self, serial: int) -> bool:
        """Whether anything changed since ``serial`` (or the preview is closing)."""
        return self.serial != serial or self.closing

    def _new(self, fingerprint: str) -> bool:
        """Whether the file differs from when it was last solved (and remember it)."""
        if fingerprint == self.seen:
            return False
        self.seen = fingerprint
        return True

    def _change(self, **values: Any) -> bool:
        with self.changed:
            for name, value in values.items():
                setattr(self, name, value)
            self.serial += 1
            self.changed.notify_all()
        return True

    def close(self) -> None:
        """End every event stream."""
        self._change(closing=True)


def _page(path: Path, raw: bytes, version: int) -> tuple[str, str, str]:
    """The viewer's page of the spec's layout, with the code that follows the spec; and
    the model (base64) and the elevation (inline SVG) it swaps in."""
    from facadecli.export.gltf import glb_bytes
    from facadecli.export.svg import svg_text
    from facadecli.geometry.facade import facade_scene, material_extensions
    from facadecli.solve import solve
    from facadecli.spec import parse_spec
    from facadecli.viewer import page

    spec = parse_spec(raw, str(path), base_dir=path.parent)
    layout = solve(spec)
    glb = glb_bytes(facade_scene(layout, path.parent), material_extensions(spec))
    svg = svg_text(layout)
    html = page(spec.name, glb, svg).replace("</body>", live_script(version) + "</body>", 1)
    return html, base64.b64encode(glb).decode(), svg.split("?>", 1)[-1]


def _event(kind: str, data: dict[str, object], ident: int | None = None) -> bytes:
    head = f"event: {kind}\n" + (f"id: {ident}\n" if ident is not None else "")
    return (head + f"data: {json.dumps(data)}\n\n").encode()


class _Server(ThreadingHTTPServer):
    """At most :data:`WATCH_CONNECTIONS_MAX` connections at once, each in a thread; a
    connection past that is closed at once. Errors of clients that went away are not
    reported; anything else is one line through ``report``, never a traceback."""

    daemon_threads = True
    request_queue_size = 64  # connections waiting to be taken (a burst of a page's asks)

    def __init__(
        self,
        port: int,
        handler: type[BaseHTTPRequestHandler],
        report: Callable[[str], None],
    ):
        self.report = report
        self.slots = threading.BoundedSemaphore(WATCH_CONNECTIONS_MAX)
        self.streams = threading.BoundedSemaphore(WATCH_STREAMS_MAX)
        super().__init__(("127.0.0.1", port), handler)

    def server_bind(self) -> None:  # not HTTPServer's, which looks the host's name up
        socketserver.TCPServer.server_bind(self)
        self.server_name, self.server_port = "127.0.0.1", int(self.server_address[1])

    @property
    def hosts(self) -> set[str]:
        """The Host headers this server answers."""
        return {f"127.0.0.1:{self.server_port}", f"localhost:{self.server_port}"}

    def process_request(self, request: Any, client_address: Any) -> None:
        if not self.slots.acquire(blocking=False):
            self.shutdown_request(request)
            return
        try:
            super().process_request(request, client_address)
        except BaseException:
            self.slots.release()
            raise

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        try:
            super().process_request_thread(request, client_address)
        finally:
            self.slots.release()

    def handle_error(self, request: Any, client_address: Any) -> None:
        error = sys.exc_info()[1]
        if isinstance(error, (ConnectionError, TimeoutError)):
            return  # the client went away or went quiet
        self.report(f"facade watch: a request failed: {type(error).__name__}: {error}")


class _Connection(io.RawIOBase):
    """What a client sends, read with a deadline for the whole of a request's line and
    headers (``until``, while they arrive), else with the idle timeout for each read: the
    socket's timeout is set to what is left before every read."""

    def __init__(self, connection: socket.socket, idle: float):
        self.connection, self.idle = connection, idle
        self.until: float | None = None  # monotonic seconds: the request's head is due

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        timeout = self.idle
        if self.until is not None:
            timeout = min(timeout, self.until - time.monotonic())
            if timeout <= 0:
                raise TimeoutError("the request's line and headers took too long")
        self.connection.settimeout(timeout)
        return self.connection.recv_into(buffer)


def _handler(preview: Preview) -> type[BaseHTTPRequestHandler]:
    head_seconds = WATCH_REQUEST_SECONDS

    class Handler(BaseHTTPRequestHandler):
        timeout = WATCH_IDLE_SECONDS  # every read and write on the connection
        default_request_version = "HTTP/1.0"  # a refusal has a status line, always
        server: _Server

        def setup(self) -> None:
            super().setup()
            self.rfile.close()  # the socket's own reader: the connection is read through
            self.reader = _Connection(self.connection, self.timeout)
            self.rfile = io.BufferedReader(self.reader)

        def handle_one_request(self) -> None:
            # a timeout while the head arrives closes the connection (BaseHTTPRequestHandler)
            self.reader.until = time.monotonic() + head_seconds
            super().handle_one_request()

        def parse_request(self) -> bool:
            read = super().parse_request()
            self.reader.until = None  # the head is in: the idle timeout from here
            if not read:
                return False
            major = self.request_version.partition("/")[2].partition(".")[0]
            if len(self.requestline.split()) < 3 or int(major) < 1:
                self.request_version = "HTTP/1.0"  # HTTP/0.9 or 0.x: refused
                self.send_error(400, "Bad request: HTTP/1.0 or 1.1 only")
                return False
            hosts = self.headers.get_all("Host") or []
            if len(hosts) != 1 or hosts[0].strip().lower() not in self.server.hosts:
                self.send_error(403, "Forbidden: ask for http://127.0.0.1:PORT/")
                return False
            return True

        def send_error(
            self, code: int, message: str | None = None, explain: str | None = None
        ) -> None:
            if self.request_version == "HTTP/0.9":  # not a bare body: every answer has a status
                self.request_version = "HTTP/1.0"
            super().send_error(code, message, explain)

        def do_GET(self) -> None:
            path = self.path.split("?", 1)[0]
            if path == "/events":
                self._stream()
                return
            with preview.changed:
                served = {
                    "/state": (json.dumps(preview.state()), "application/json"),
                    "/": (preview.page, "text/html; charset=utf-8"),
                    "/index.html": (preview.page, "text/html; charset=utf-8"),
                    "/glb": (preview.glb, "text/plain"),
                    "/svg": (preview.svg, "image/svg+xml"),
                }.get(path)
            if served is None:
                self.send_error(404)
                return
            body = served[0].encode()
            self._head(200, served[1], len(body))
            self.wfile.write(body)

        def _head(self, code: int, kind: str, length: int | None) -> None:
            self.send_response(code)
            self.send_header("Content-Type", kind)
            self.send_header("Cache-Control", "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            if length is not None:
                self.send_header("Content-Length", str(length))
            self.end_headers()

        def _since(self) -> int:
            """The version the page shows: the stream's last event id, or ``?since=``."""
            given = self.headers.get("Last-Event-ID") or ""
            if not given and "since=" in self.path:
                given = self.path.split("since=", 1)[1].split("&", 1)[0]
            return int(given) if given.isdigit() and len(given) < 10 else -1

        def _stream(self) -> None:
            """The event stream: the state at once, then a state (and a layout when there
            is a new one) after every change; a comment when quiet, to notice a gone page."""
            if not self.server.streams.acquire(blocking=False):
                self.send_error(503, "Too many pages follow this spec")
                return
            try:
                shown = self._since()
                self._head(200, "text/event-stream", None)
                self.wfile.write(f"retry: {RETRY_MS}\n\n".encode())
                serial, spoke = -1, time.monotonic()
                while True:
                    with preview.changed:
                        preview.changed.wait_for(partial(preview.moved, serial), LOOK)
                        if preview.closing:
                            return
                        quiet, serial = preview.serial == serial, preview.serial
                        state, version = preview.state(), preview.version
                        glb, svg = preview.glb, preview.svg
                    if quiet:
                        if self._gone():  # its slot is free for the page's next stream
                            return
                        if time.monotonic() - spoke > KEEP_ALIVE:
                            self.wfile.write(b": still here\n\n")
                            spoke = time.monotonic()
                        continue
                    spoke = time.monotonic()
                    message = b""
                    if version != shown and glb:
                        shown = version
                        layout = {"version": version, "glb": glb, "svg": svg}
                        message = _event("layout", layout, version)
                    self.wfile.write(message + _event("state", state))
            finally:
                self.server.streams.release()

        def _gone(self) -> bool:
            """Whether the client closed the stream (a page sends nothing after its
            request, so an end to read means it went)."""
            readable, _, _ = select.select([self.connection], [], [], 0)
            if not readable:
                return False
            try:
                return bool(self.connection.recv(1, socket.MSG_PEEK) == b"")
            except OSError:
                return True

        def log_message(self, format: str, *args: object) -> None:  # quiet
            return

    return Handler


@dataclass
class Session:
    """A running preview: the server (in its own thread) and the spec's saves."""

    preview: Preview
    server: _Server
    saves: Saves
    note: str  # why the file is polled, when it is although events were asked for

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.server.server_port}/"

    def solve_on_saves(
        self, echo: Callable[[str, bool], None], stop: threading.Event | None = None
    ) -> None:
        """Solve now, then after every save, until ``stop`` is set (or forever);
        ``echo`` gets a line for every change: how long the solve took, or the error
        (with True)."""
        saved = True
        while stop is None or not stop.is_set():
            if saved and self.preview.refresh():
                state = self.preview.state()
                if state["ok"]:
                    line = f"{self.preview.spec}: solved in {state['solved_ms']} ms"
                    echo(f"{line} (page {state['version']})", False)
                else:
                    echo(str(state["error"]), True)
            saved = self.saves.wait(WAIT)

    def close(self) -> None:
        self.preview.close()
        self.server.shutdown()
        self.server.server_close()
        self.saves.close()


def open_session(
    spec: Path, port: int, report: Callable[[str], None], poll: bool = False
) -> Session:
    """Start serving ``spec``'s preview on 127.0.0.1:``port`` (0: any free port) and
    watching its saves (``poll``: by polling even where file events exist); ``report``
    gets the lines about failed requests. OSError when the port cannot be had."""
    saves, note = watch_saves(spec, poll)  # before the first read: no save is missed
    preview = Preview(spec)
    try:
        server = _Server(port, _handler(preview), report)
    except OSError:
        saves.close()
        raise
    threading.Thread(
        target=server.serve_forever, args=(0.1,), name="facade-watch", daemon=True
    ).start()
    return Session(preview, server, saves, note)


def serve(spec: Path, port: int, echo: Callable[[str, bool], None], poll: bool = False) -> None:
    """Serve the preview until interrupted; ``echo`` gets the address, then a line for
    every change: how long the solve took, or the error (with True)."""
    session = open_session(spec, port, lambda line: echo(line, True), poll)
    echo(f"{spec}: serving {session.url} (Ctrl-C to stop)", False)
    if session.note:
        echo(f"{spec}: {session.note}", True)
    try:
        session.solve_on_saves(echo)
    finally:
        session.close()
