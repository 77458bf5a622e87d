"""``facade watch SPEC``: a live preview. The spec is solved again whenever its file changes,
and the viewer's page is served on 127.0.0.1; the page asks ``/state`` twice a second and,
when a new layout is ready, swaps in its model (``/glb``) and elevation (``/svg``) in
place, the camera where the user left it. A spec with an error keeps the last good model
on the page under a banner with the error (its file, line and column, and the hint).

Only this machine can reach the server (127.0.0.1). The file is polled (its size, time and
content), so any editor's way of saving is seen; solving runs in the serving process, warm,
one change at a time.
"""

from __future__ import annotations

import base64
import hashlib
import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

from facadecli.errors import FacadeError

POLL = 0.2  # seconds between looks at the file
ASK = 500  # milliseconds between the page's questions to /state
LIVE = f"""
<div id="watch-error" style="display:none;position:fixed;left:0;right:0;top:0;padding:8px 12px;
background:#7a1d1d;color:#fff;font:13px monospace;white-space:pre-wrap;z-index:9"></div>
<script>
(function () {{
  var seen = null;
  function swap(version) {{  // the new model and elevation, in place: the camera stays
    Promise.all([fetch('/glb', {{cache: 'no-store'}}).then(function (r) {{ return r.text(); }}),
                 fetch('/svg', {{cache: 'no-store'}}).then(function (r) {{ return r.text(); }})])
      .then(function (got) {{
        document.getElementById('glb').textContent = got[0];
        var old = document.querySelector('#side svg');
        if (old) old.outerHTML = got[1];
        window.facadeShow('glb', true);
        seen = version;
      }});
  }}
  function ask() {{
    fetch('/state', {{cache: 'no-store'}}).then(function (r) {{ return r.json(); }})
      .then(function (state) {{
        var banner = document.getElementById('watch-error');
        banner.style.display = state.error ? 'block' : 'none';
        banner.textContent = state.error || '';
        if (seen === null) seen = state.version;
        else if (state.version !== seen) swap(state.version);
      }}).catch(function () {{}}).finally(function () {{ setTimeout(ask, {ASK}); }});
  }}
  ask();
}})();
</script>
"""


@dataclass
class Preview:
    """What the server shows: the page of the last good layout, and the state."""

    spec: Path
    version: int = 0  # a new page, each time one is made
    page: str = "<!doctype html><title>solving</title><p>solving...</p>" + LIVE
    glb: str = ""  # the model, base64 (what the page's element holds)
    svg: str = ""  # the elevation, inline
    error: str = ""  # why the spec as saved has no layout (empty when it has one)
    solved_ms: float = 0.0
    seen: str = ""  # the file's fingerprint when it was last solved
    lock: threading.RLock = field(default_factory=threading.RLock)

    def state(self) -> dict[str, object]:
        with self.lock:
            return {
                "version": self.version,
                "ok": not self.error,
                "error": self.error,
                "solved_ms": round(self.solved_ms, 1),
            }

    def refresh(self) -> bool:
        """Solve the spec again if its file changed; True when it did."""
        fingerprint = _fingerprint(self.spec)
        if fingerprint == self.seen:
            return False
        self.seen = fingerprint
        started = time.perf_counter()
        try:
            page, glb, svg = _page(self.spec)
        except FacadeError as error:
            with self.lock:
                self.error = str(error)
            return True
        except Exception as error:  # a bug: shown, and the preview goes on with the next save
            with self.lock:
                self.error = f"{self.spec}: internal error: {type(error).__name__}: {error}"
            return True
        with self.lock:
            self.page, self.glb, self.svg = page, glb, svg
            self.error = ""
            self.version += 1
            self.solved_ms = (time.perf_counter() - started) * 1000
        return True


def _fingerprint(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as error:
        return f"unreadable: {error}"


def _page(path: Path) -> tuple[str, str, str]:
    """The viewer's page of the spec's layout, with the script that swaps in new ones; and
    the model (base64) and the elevation (inline SVG) it swaps in."""
    from facadecli.export.gltf import glb_bytes
    from facadecli.export.svg import svg_text
    from facadecli.geometry.facade import facade_scene, transmissions
    from facadecli.solve import solve
    from facadecli.spec import load_spec
    from facadecli.viewer import page

    spec = load_spec(path)
    layout = solve(spec)
    glb = glb_bytes(facade_scene(layout, path.parent), transmissions(spec))
    svg = svg_text(layout)
    html = page(spec.name, glb, svg).replace("</body>", LIVE + "</body>", 1)
    return html, base64.b64encode(glb).decode(), svg.split("?>", 1)[-1]


def _handler(preview: Preview) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            path = self.path.split("?", 1)[0]
            with preview.lock:
                served = {
                    "/state": (json.dumps(preview.state()), "application/json"),
                    "/": (preview.page, "text/html; charset=utf-8"),
                    "/index.html": (preview.page, "text/html; charset=utf-8"),
                    "/glb": (preview.glb, "text/plain"),
                    "/svg": (preview.svg, "image/svg+xml"),
                }.get(path)
            if served is not None:
                body, kind = served[0].encode(), served[1]
            else:
                self.send_error(404)
                return
            self.send_response(200)
            self.send_header("Content-Type", kind)
            self.send_header("Cache-Control", "no-store")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, format: str, *args: object) -> None:  # quiet
            return

    return Handler


def serve(spec: Path, port: int, echo: Callable[[str, bool], None]) -> None:
    """Serve the preview until interrupted; ``echo`` gets the address, then a line for
    every change: how long the solve took, or the error (with True)."""
    preview = Preview(spec)
    server = ThreadingHTTPServer(("127.0.0.1", port), _handler(preview))
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    echo(f"{spec}: serving http://127.0.0.1:{server.server_address[1]}/ (Ctrl-C to stop)", False)
    try:
        while True:
            if preview.refresh():
                state = preview.state()
                if state["ok"]:
                    echo(
                        f"{spec}: solved in {state['solved_ms']} ms (page {state['version']})",
                        False,
                    )
                else:
                    echo(str(state["error"]), True)
            time.sleep(POLL)
    finally:
        server.shutdown()
        server.server_close()
