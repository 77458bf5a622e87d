"""``facade watch SPEC`` (issue 16): a live preview served on 127.0.0.1 that changes when
the spec's file does, tested with real HTTP requests (every wait bounded)."""

from __future__ import annotations

import asyncio
import json
import os
import re
import select
import shutil
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from facadecli.viewer import watch
from facadecli.viewer.saves import SETTLE, SETTLE_EMPTY, Settling
from tests.fuzz.serve_doors import WatchedServer

ROOT = Path(__file__).resolve().parent.parent
WAIT = 120.0  # seconds any one step may take on a loaded machine before the test fails


def _get(url: str) -> bytes:
    with urllib.request.urlopen(url, timeout=30) as response:
        return bytes(response.read())


def _state(url: str) -> dict[str, object]:
    return dict(json.loads(_get(url + "state")))


def _until(check: object, what: str) -> None:
    deadline = time.monotonic() + WAIT
    while time.monotonic() < deadline:
        if check():  # type: ignore[operator]
            return
        time.sleep(0.1)
    pytest.fail(f"no {what} within {WAIT:g} s")


@pytest.fixture
def watched(tmp_path: Path) -> Iterator[tuple[Path, str, subprocess.Popen[str]]]:
    spec = tmp_path / "house.yaml"
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    process = subprocess.Popen(
        [sys.executable, "-m", "facadecli", "watch", str(spec), "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert process.stdout is not None
        line = process.stdout.readline()  # the first line is the address
        found = re.search(r"http://127\.0\.0\.1:\d+/", line)
        assert found, line
        yield spec, found.group(0), process
    finally:
        process.terminate()
        process.wait(timeout=30)


def test_the_page_follows_the_file(watched: tuple[Path, str, subprocess.Popen[str]]) -> None:
    spec, url, _ = watched
    _until(lambda: _state(url)["version"] == 1, "first layout")
    first = _get(url)
    assert b"<svg" in first and b"/events" in first  # the model, the elevation, the swap
    model, elevation = _get(url + "glb"), _get(url + "svg")
    assert model and model in first and elevation.lstrip().startswith(b"<svg")  # as shown
    text = spec.read_text()
    spec.write_text(re.sub(r"canvas: \{width: [0-9.]+", "canvas: {width: 8.5", text))
    _until(lambda: _state(url)["version"] == 2, "second layout")
    assert _get(url) != first and _state(url)["ok"] is True
    assert _get(url + "glb") != model and _get(url + "svg") != elevation  # swapped in place


def test_an_error_shows_with_its_place_and_the_last_model_stays(
    watched: tuple[Path, str, subprocess.Popen[str]],
) -> None:
    spec, url, _ = watched
    _until(lambda: _state(url)["version"] == 1, "first layout")
    page = _get(url)
    spec.write_text(spec.read_text() + "layers: [\n")
    _until(lambda: _state(url)["ok"] is False, "error")
    state = _state(url)
    assert re.search(r"house\.yaml:\d+:\d+: error", str(state["error"])), state
    assert state["version"] == 1 and _get(url) == page  # the last good model stays
    with pytest.raises(urllib.error.HTTPError):
        _get(url + "nothing-here")


# In the test process: the server and the loop that solves on saves, every wait bounded.


class Running:
    """A preview served in this process; ``lines`` what it echoed, ``reports`` the lines
    about failed requests."""

    def __init__(self, spec: Path, poll: bool = False):
        self.lines: list[tuple[str, bool]] = []
        self.reports: list[str] = []
        self.session = watch.open_session(spec, 0, self.reports.append, poll)
        self.port = self.session.server.server_port
        self.url = self.session.url
        self.stop = threading.Event()
        self.loop = threading.Thread(
            target=self.session.solve_on_saves,
            args=(lambda line, error: self.lines.append((line, error)), self.stop),
            daemon=True,
        )
        self.loop.start()

    def close(self) -> None:
        self.stop.set()
        self.loop.join(timeout=WAIT)
        self.session.close()


@pytest.fixture
def running(tmp_path: Path) -> Iterator[tuple[Path, Running]]:
    spec = tmp_path / "house.yaml"
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    served = Running(spec)
    try:
        _until(lambda: _state(served.url)["version"] == 1, "first layout")
        yield spec, served
    finally:
        served.close()


def _ask(port: int, request: bytes) -> bytes:
    """The raw answer to a raw request (the server closes after each)."""
    with socket.create_connection(("127.0.0.1", port), timeout=30) as client:
        client.sendall(request)
        got = b""
        while chunk := client.recv(65536):
            got += chunk
        return got


def _save(spec: Path, text: str) -> None:
    """Save as an editor does: a new file renamed onto the spec."""
    fresh = spec.with_name(".house.yaml.swp")
    fresh.write_text(text)
    os.replace(fresh, spec)


def _wider(text: str, width: float) -> str:
    return re.sub(r"canvas: \{width: [0-9.]+", f"canvas: {{width: {width}", text)


class Events:
    """An event stream of the server, read event by event."""

    def __init__(self, port: int, since: int):
        self.client = socket.create_connection(("127.0.0.1", port), timeout=WAIT)
        head = f"GET /events?since={since} HTTP/1.1\r\nHost: localhost:{port}\r\n\r\n"
        self.client.sendall(head.encode())
        self.buffer = b""
        self.head = self._until(b"\r\n\r\n")

    def _until(self, end: bytes) -> bytes:
        while end not in self.buffer:
            chunk = self.client.recv(65536)
            assert chunk, "the stream ended"
            self.buffer += chunk
        part, self.buffer = self.buffer.split(end, 1)
        return part

    def next(self) -> tuple[str, dict[str, object]]:
        """The next event (comments and the retry skipped): its kind and its data."""
        while True:
            fields = dict(
                line.split(": ", 1) for line in self._until(b"\n\n").decode().splitlines()
            )
            if "event" in fields:
                return fields["event"], dict(json.loads(fields["data"]))

    def close(self) -> None:
        self.client.close()


def test_a_save_is_pushed_to_the_page_as_an_event(running: tuple[Path, Running]) -> None:
    spec, served = running
    events = Events(served.port, since=1)
    try:
        assert b" 200 " in events.head and b"Content-Type: text/event-stream" in events.head
        assert events.next() == ("state", _state(served.url))  # the state at once
        _save(spec, _wider(spec.read_text(), 8.5))
        kind, layout = events.next()  # no layout before: the page shows version 1
        assert kind == "layout" and layout["version"] == 2
        assert layout["glb"] == _get(served.url + "glb").decode()
        assert layout["svg"] == _get(served.url + "svg").decode()
        kind, state = events.next()
        assert kind == "state" and state["version"] == 2 and state["ok"] is True
        spec.write_text(spec.read_text() + "layers: [\n")  # in place: open, write, close
        kind, state = events.next()  # an error: the state, no layout
        assert kind == "state" and state["ok"] is False and state["version"] == 2
        assert re.search(r"house\.yaml:\d+:\d+: error", str(state["error"]))
    finally:
        events.close()
    late = Events(served.port, since=0)  # a page made before the last layout gets it
    try:
        kind, layout = late.next()
        assert kind == "layout" and layout["version"] == 2
    finally:
        late.close()
    assert served.reports == []


def test_only_requests_for_this_machine_are_answered(running: tuple[Path, Running]) -> None:
    _, served = running
    port = served.port
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"LOCALHOST:{port}"):
        answer = _ask(port, f"GET /state HTTP/1.1\r\nHost: {host}\r\n\r\n".encode())
        assert answer.startswith(b"HTTP/1.0 200 "), (host, answer)
    for hosts in (
        ["evil.example"],
        [f"evil.example:{port}"],  # a page of evil.example whose name now means 127.0.0.1
        ["127.0.0.1"],
        [f"127.0.0.1:{port + 1}"],
        [f"127.0.0.1.nip.io:{port}"],
        [],
        [f"localhost:{port}", "evil.example"],
    ):
        request = "GET /state HTTP/1.1\r\n" + "".join(f"Host: {h}\r\n" for h in hosts) + "\r\n"
        for path in ("/state", "/", "/glb", "/events"):
            answer = _ask(port, request.replace("/state", path).encode())
            assert answer.startswith(b"HTTP/1.0 403 "), (hosts, path, answer[:200])
            assert b"version" not in answer and b"glTF" not in answer
    for line in ("GET /state", "GET /state HTTP/0.9"):  # HTTP/0.9: refused, with a status
        answer = _ask(port, f"{line}\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
        assert answer.startswith(b"HTTP/1.0 400 "), (line, answer)
    assert served.reports == []


@pytest.mark.slow
def test_clients_that_go_away_early_print_nothing(tmp_path: Path) -> None:
    spec = tmp_path / "house.yaml"  # a server of its own, its stderr captured
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    with WatchedServer(spec) as server:
        assert server.solved(), server.stderr()
        server.go_away(300)  # 1,500 in python -m tests.fuzz.serve_doors
        assert server.healthy() and server.alive()
        time.sleep(watch.KEEP_ALIVE + 1)  # the streams of gone pages find out, quietly
        assert server.healthy() and server.alive()
        assert server.stderr() == ""


@pytest.fixture
def small(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Running]:
    """A server for 3 connections, 1 event stream."""
    monkeypatch.setattr(watch, "WATCH_CONNECTIONS_MAX", 3)
    monkeypatch.setattr(watch, "WATCH_STREAMS_MAX", 1)
    spec = tmp_path / "house.yaml"
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    served = Running(spec)
    try:
        _until(lambda: _state(served.url)["version"] == 1, "first layout")
        yield served
    finally:
        served.close()
    assert served.reports == []


def test_idle_connections_are_closed(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setattr(watch, "WATCH_IDLE_SECONDS", 0.5)
    spec = tmp_path / "house.yaml"
    spec.write_text("version: 1\n")
    served = Running(spec)
    try:
        for sent in (b"", b"GET /state HTTP/1.1\r\n"):  # then nothing: closed by the server
            idle = socket.create_connection(("127.0.0.1", served.port), timeout=WAIT)
            idle.sendall(sent)
            assert idle.recv(100) == b""
            idle.close()
    finally:
        served.close()


def test_a_request_sent_a_byte_at_a_time_is_cut_off(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """A client that sends its request a byte now and then, each within the idle timeout,
    held a connection (of 32) for as long as it liked: the request's line and headers
    must now all arrive within their own limit (here 0.3 s, the idle timeout 60 s). The
    trickle would take 30 s: the server closes first, with nothing answered."""
    monkeypatch.setattr(watch, "WATCH_IDLE_SECONDS", 60.0)
    monkeypatch.setattr(watch, "WATCH_REQUEST_SECONDS", 0.3)
    spec = tmp_path / "house.yaml"
    spec.write_text("version: 1\n")
    served = Running(spec)
    request = f"GET /state HTTP/1.1\r\nHost: 127.0.0.1:{served.port}\r\n\r\n".encode()
    try:
        for head in (b"", b"GET /state HTTP/1.1\r\n"):  # the request line; the headers
            slow = socket.create_connection(("127.0.0.1", served.port), timeout=60)
            slow.sendall(head)
            rest, answer = request[len(head) :], None
            for i in range(len(rest)):
                try:
                    slow.sendall(rest[i : i + 1])
                except OSError:  # reset: the server has closed it
                    answer = b""
                    break
                if select.select([slow], [], [], 0.5)[0]:  # a byte every 0.5 s at most
                    answer = _received(slow)
                    break
            slow.close()
            assert answer == b"", answer  # closed before the request was whole
        assert served.reports == []
        assert _get(served.url + "state")  # and the server serves on
    finally:
        served.close()


def _received(client: socket.socket) -> bytes:
    try:
        return client.recv(100)
    except OSError:
        return b""


def test_connections_and_event_streams_are_bounded(small: Running) -> None:
    port, slots = small.port, small.session.server.slots
    stream = Events(port, since=1)  # the one stream allowed
    try:
        answer = _ask(port, f"GET /events HTTP/1.1\r\nHost: localhost:{port}\r\n\r\n".encode())
        assert answer.startswith(b"HTTP/1.0 503 "), answer
        _until(lambda: slots._value == 2, "the refused connection done")  # the stream's
        held = [socket.create_connection(("127.0.0.1", port), timeout=WAIT)]
        _until(lambda: slots._value == 1, "two connections held")
        held.append(socket.create_connection(("127.0.0.1", port), timeout=WAIT))
        _until(lambda: slots._value == 0, "three connections held")
        extra = socket.create_connection(("127.0.0.1", port), timeout=WAIT)
        assert extra.recv(100) == b""  # closed at once: the three are in use
        extra.close()
        for client in held:
            client.close()
    finally:
        stream.close()
    _until(lambda: _served(lambda: _state(small.url)["ok"] is True), "a connection again")
    _until(
        lambda: _served(lambda: Events(port, since=1).head.startswith(b"HTTP/1.0 200 ")),
        "a stream again",
    )


def _served(check: Callable[[], bool]) -> bool:
    """``check()``, False when the connection was closed before an answer (all in use)."""
    try:
        return check()
    except (OSError, AssertionError):
        return False


def test_a_spec_that_is_no_file_or_too_long_is_an_error_on_the_page(
    running: tuple[Path, Running],
) -> None:
    spec, served = running
    text = spec.read_text()
    link = spec.with_name("zero")
    link.symlink_to("/dev/zero")
    os.replace(link, spec)  # the spec is now a link to /dev/zero
    _until(lambda: _state(served.url)["ok"] is False, "error")
    assert "not a regular file" in str(_state(served.url)["error"])
    _save(spec, text + "#" * (watch.SPEC_BYTES_MAX + 1 - len(text)))
    _until(lambda: "longer than specs" in str(_state(served.url)["error"]), "too long")
    assert "SPEC_BYTES_MAX" in str(_state(served.url)["error"])
    _save(spec, _wider(text, 7.5))
    _until(lambda: _state(served.url)["ok"] is True, "layout again")
    assert _state(served.url)["version"] == 2 and served.reports == []


def test_a_half_written_save_is_not_read(running: tuple[Path, Running]) -> None:
    spec, served = running
    text = _wider(spec.read_text(), 9.5)
    with spec.open("w") as handle:  # truncated, then half written: not yet a save
        handle.write(text[: len(text) // 2])
        handle.flush()
        time.sleep(1.0)  # far longer than a solve takes: any read would be seen
        assert _state(served.url) == {"version": 1, "ok": True, "error": "", "solved_ms": ANY}
        handle.write(text[len(text) // 2 :])
    _until(lambda: _state(served.url)["version"] == 2, "the whole save")
    assert _state(served.url)["ok"] is True
    assert [error for _, error in served.lines] == [False, False]  # two solves, no error


class _Any:
    def __eq__(self, other: object) -> bool:
        return True


ANY = _Any()


def test_polling_counts_a_save_once_the_file_holds_still() -> None:
    settling = Settling((1, 2, 100, 0))
    assert not settling.look((1, 2, 100, 0), 0.0)  # as it was: nothing
    assert not settling.look((1, 2, 0, 5), 1.0)  # truncated: empty
    assert not settling.look((1, 2, 0, 5), 1.0 + SETTLE)  # still empty: give it longer
    assert not settling.look((1, 2, 50, 6), 1.5)  # half written
    assert not settling.look((1, 2, 120, 7), 1.55)  # written
    assert not settling.look((1, 2, 120, 7), 1.55 + SETTLE / 2)
    assert settling.look((1, 2, 120, 7), 1.55 + 1.5 * SETTLE)  # held still: a save
    assert not settling.look((1, 2, 120, 7), 9.0)  # reported once
    assert not settling.look((1, 2, 0, 8), 10.0)
    assert not settling.look((1, 2, 0, 8), 10.0 + SETTLE_EMPTY / 2)
    assert settling.look((1, 2, 0, 8), 10.0 + 1.5 * SETTLE_EMPTY)  # an empty file stays
    assert not settling.look(None, 11.0)
    assert settling.look(None, 11.0 + 1.5 * SETTLE)  # gone


def test_polling_follows_the_file_too(tmp_path: Path) -> None:
    spec = tmp_path / "house.yaml"
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    served = Running(spec, poll=True)
    try:
        assert served.session.saves.kind == "polling"
        _until(lambda: _state(served.url)["version"] == 1, "first layout")
        _save(spec, _wider(spec.read_text(), 8.5))
        _until(lambda: _state(served.url)["version"] == 2, "second layout")
    finally:
        served.close()


@pytest.mark.slow
def test_fuzzed_requests_get_an_answer_or_a_close_and_no_traceback(tmp_path: Path) -> None:
    spec = tmp_path / "house.yaml"
    spec.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    with WatchedServer(spec) as server:
        assert server.solved(), server.stderr()
        tally = server.run(range(200))
    assert tally.failures == [], tally
    assert sum(tally.outcomes.values()) == 200


BROWSER = shutil.which("chromium") or shutil.which("chromium-browser")


def _in_browser(url: str, profile: Path, steps: Callable[[Callable[[str], object]], None]) -> None:
    """Open ``url`` in headless Chromium and run ``steps`` with a function that evaluates a
    JavaScript expression in the page (through the DevTools protocol) and returns its value."""
    websocket = pytest.importorskip("tornado.websocket")
    flags = [
        "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader",
        "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
        f"--user-data-dir={profile}", "--window-size=1000,600", "--remote-debugging-port=0",
    ]  # fmt: skip
    chrome = subprocess.Popen([str(BROWSER), *flags, url], stderr=subprocess.DEVNULL)
    try:
        active = profile / "DevToolsActivePort"
        _until(lambda: active.exists() and active.read_text().strip(), "the browser's port")
        port = active.read_text().split()[0]
        pages: list[dict[str, str]] = []
        _until(
            lambda: (
                pages.extend(
                    page
                    for page in json.loads(_get(f"http://127.0.0.1:{port}/json/list"))
                    if page["type"] == "page" and page["url"] == url
                )
                or pages
            ),
            "the page",
        )
        loop = asyncio.new_event_loop()

        async def connect() -> Any:
            address = pages[0]["webSocketDebuggerUrl"]
            return await websocket.websocket_connect(address, max_message_size=2**30)

        async def read() -> Any:
            return await connection.read_message()

        connection = loop.run_until_complete(connect())
        asked = iter(range(1, 10**9))

        def evaluate(expression: str) -> object:
            ident = next(asked)
            message = {"id": ident, "method": "Runtime.evaluate"}
            message["params"] = {"expression": expression, "returnByValue": True}
            connection.write_message(json.dumps(message))
            while True:
                answer = json.loads(loop.run_until_complete(read()))
                if answer.get("id") == ident:
                    return answer["result"]["result"].get("value")

        try:
            steps(evaluate)
        finally:
            connection.close()
            loop.close()
    finally:
        chrome.terminate()
        chrome.wait(timeout=WAIT)


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_a_browser_page_follows_the_saves(running: tuple[Path, Running], tmp_path: Path) -> None:
    spec, served = running

    def steps(evaluate: Callable[[str], object]) -> None:
        _until(lambda: evaluate("document.title") == "residential-house", "the model drawn")
        _save(spec, _wider(spec.read_text(), 8.5))
        _until(lambda: evaluate("document.documentElement.dataset.version") == "2", "layout 2")
        assert (
            evaluate("document.getElementById('glb').textContent")
            == _get(served.url + "glb").decode()
        )
        banner = "document.getElementById('watch-error')"
        assert evaluate(f"{banner}.style.display") == "none"
        spec.write_text(spec.read_text() + "layers: [\n")
        _until(lambda: evaluate(f"{banner}.style.display") == "block", "the error banner")
        assert re.search(r"house\.yaml:\d+:\d+: error", str(evaluate(f"{banner}.textContent")))
        _save(spec, _wider(spec.read_text().replace("layers: [\n", ""), 9.5))
        _until(lambda: evaluate("document.documentElement.dataset.version") == "3", "layout 3")
        assert evaluate(f"{banner}.style.display") == "none"
        status = "document.getElementById('status').textContent"
        # the model's pictures take a moment to decode: then the page says how to move
        _until(lambda: evaluate(status) == "drag to orbit, scroll to zoom", "the model shown")

    _in_browser(served.url, tmp_path / "profile", steps)


def test_a_spec_that_is_a_link_follows_the_file_it_names(tmp_path: Path) -> None:
    (tmp_path / "real").mkdir()
    (tmp_path / "work").mkdir()
    real = tmp_path / "real" / "house.yaml"
    real.write_text((ROOT / "specs" / "residential-house.yaml").read_text())
    spec = tmp_path / "work" / "house.yaml"
    spec.symlink_to(real)
    served = Running(spec)
    try:
        _until(lambda: _state(served.url)["version"] == 1, "first layout")
        real.write_text(_wider(real.read_text(), 8.5))  # saved where the file is
        _until(lambda: _state(served.url)["version"] == 2, "a save of the linked file")
        other = tmp_path / "real" / "other.yaml"
        other.write_text(_wider(real.read_text(), 9.5))
        fresh = tmp_path / "work" / ".link"
        fresh.symlink_to(other)
        os.replace(fresh, spec)  # the link now names another file
        _until(lambda: _state(served.url)["version"] == 3, "the newly linked file")
        other.write_text(_wider(other.read_text(), 7.5))
        _until(lambda: _state(served.url)["version"] == 4, "a save of that file")
    finally:
        served.close()
