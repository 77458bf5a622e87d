"""The HTTP door of ``facade watch``, fuzzed: seeded raw requests, well-formed and not, sent
to a running server, each judged by what the server did.

``http_case(seed)`` is one request as bytes (the same bytes for the same seed): a request
line, headers and maybe a body, drawn from pieces a browser, a script or an attacker send
(wrong or missing ``Host``, DNS-rebinding names, other methods and versions, paths that
climb, huge lines, too many headers, NUL bytes, bare LFs, cuts at any byte).
:class:`WatchedServer` runs ``facade watch`` in a subprocess and judges each case: the
server answers it with a status it should give (never 500), or closes the connection,
within :data:`TIMEOUT`; it is still alive; nothing was printed on its stderr (no
traceback) after its start-up lines. Every tenth case is sent by a client that resets the
connection at once, without reading the answer.

Run ``python -m tests.fuzz.serve_doors [CASES] [FIRST_SEED]`` for a tally (then 1,500
clients that go away early, :meth:`WatchedServer.go_away`).
"""

from __future__ import annotations

import random
import re
import socket
import struct
import subprocess
import sys
import threading
import time
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType

ROOT = Path(__file__).resolve().parents[2]
KEEP_ALIVE = 5.0  # seconds an event stream of the server may stay quiet (watch.KEEP_ALIVE)
TIMEOUT = 30.0  # seconds a case may take to be answered or closed on a loaded machine
STATUSES = {200, 400, 403, 404, 408, 414, 431, 501, 503, 505}  # what a request may get

METHODS = ["GET"] * 8 + ["HEAD", "POST", "PUT", "DELETE", "OPTIONS", "TRACE", "CONNECT"]
ODD_METHODS = ["get", "G\x00T", "GET GET", "", "X" * 300, "\u00e9T"]
PATHS = ["/", "/index.html", "/state", "/glb", "/svg", "/events", "/events?since=1"]
ODD_PATHS = [
    "/events?since=99999999999999999999",
    "/events?since=-1&since=abc",
    "/../../../etc/passwd",
    "/%2e%2e/%2e%2e/etc/passwd",
    "//etc/passwd",
    "*",
    "http://evil.example/state",
    "/state?" + "a" * 5000,
    "/\u00e9t\u00e9",
    "/%00",
    "",
]
VERSIONS = ["HTTP/1.1"] * 6 + ["HTTP/1.0"] * 3
ODD_VERSIONS = ["HTTP/0.9", "HTTP/2.0", "HTTP/1.1x", "HTTP/999999999999.1", "http/1.1", ""]
BAD_HOSTS = [
    "evil.example",
    "evil.example:{port}",
    "127.0.0.1",
    "127.0.0.1:1",
    "localhost.:{port}",
    "127.0.0.1.nip.io:{port}",
    "[::1]:{port}",
    "0.0.0.0:{port}",
    "",
    "127.0.0.1:{port}\x00",
]
HEADERS = [
    "User-Agent: fuzz/1.0",
    "Accept: text/event-stream",
    "Accept: */*",
    "Connection: keep-alive",
    "Connection: close",
    "Last-Event-ID: 1",
    "Last-Event-ID: " + "9" * 40,
    "Last-Event-ID: \u00e9",
    "Content-Length: 5",
    "Content-Length: -1",
    "Content-Length: 99999999999999999999",
    "Transfer-Encoding: chunked",
    "Expect: 100-continue",
    "Range: bytes=0-10",
    "Origin: http://evil.example",
    "Cookie: a=" + "b" * 1000,
]


def http_case(seed: int, port: int = 8765) -> bytes:
    """One raw HTTP request, possibly malformed, the same for the same seed; ``port`` is
    the server's, so that the right ``Host`` can be drawn (and the case get past it)."""
    rng = random.Random(seed)
    odd = rng.random
    method = rng.choice(ODD_METHODS) if odd() < 0.1 else rng.choice(METHODS)
    path = rng.choice(ODD_PATHS) if odd() < 0.25 else rng.choice(PATHS)
    if odd() < 0.03:
        path = "/" + "a" * rng.choice([70_000, 66_000])  # past the request line's limit
    version = rng.choice(ODD_VERSIONS) if odd() < 0.1 else rng.choice(VERSIONS)
    line = " ".join(part for part in (method, path, version) if part or odd() < 0.5)
    headers = []
    host = rng.random()
    good = rng.choice([f"127.0.0.1:{port}", f"localhost:{port}", f"LocalHost:{port}"])
    if host < 0.6:
        headers.append(f"Host: {good}")
    elif host < 0.85:
        headers.append("Host: " + rng.choice(BAD_HOSTS).format(port=port))
    elif host < 0.92:
        headers += [f"Host: {good}", "Host: evil.example"]  # two: refused
    headers += rng.sample(HEADERS, rng.randint(0, 4))
    if odd() < 0.03:
        headers += [f"X-Many-{i}: {i}" for i in range(rng.choice([99, 101, 150]))]
    if odd() < 0.03:
        headers.append("X-Long: " + "x" * 70_000)
    rng.shuffle(headers)
    newline = "\n" if odd() < 0.1 else "\r\n"
    text = newline.join([line, *headers]) + newline * 2
    if odd() < 0.1:
        text += "hello" * rng.randint(1, 10)  # a body nobody asked for
    data = text.encode("utf-8", "surrogateescape")
    cut = odd()
    if cut < 0.08:
        data = data[: rng.randrange(len(data) + 1)]  # a request cut anywhere
    elif cut < 0.12:
        at = rng.randrange(len(data) + 1)
        data = data[:at] + bytes([rng.randrange(256)]) + data[at:]  # a stray byte
    return data


@dataclass
class Tally:
    """What the cases got: a count per outcome, and the failures."""

    outcomes: Counter[str] = field(default_factory=Counter)
    failures: list[str] = field(default_factory=list)

    def __str__(self) -> str:
        counts = ", ".join(f"{name} {count}" for name, count in sorted(self.outcomes.items()))
        return f"{sum(self.outcomes.values())} cases: {counts}; {len(self.failures)} failures"


class WatchedServer:
    """``facade watch SPEC --port 0`` in a subprocess, its stderr collected."""

    def __init__(self, spec: Path, *extra: str):
        self.process = subprocess.Popen(
            [sys.executable, "-m", "facadecli", "watch", str(spec), "--port", "0", *extra],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        assert self.process.stdout is not None and self.process.stderr is not None
        first = self.process.stdout.readline()
        found = re.search(r"http://127\.0\.0\.1:(\d+)/", first)
        if not found:
            self.close()
            raise RuntimeError(f"facade watch did not start: {first!r} {self.stderr()}")
        self.port = int(found.group(1))
        self.lines: list[str] = []
        self.errors: list[str] = []
        for stream, into in ((self.process.stdout, self.lines), (self.process.stderr, self.errors)):
            threading.Thread(target=_drain, args=(stream, into), daemon=True).start()

    def stderr(self) -> str:
        return "".join(getattr(self, "errors", []))

    def alive(self) -> bool:
        return self.process.poll() is None

    def solved(self, timeout: float = TIMEOUT) -> bool:
        """Whether the first solve is done (its line printed) within ``timeout``."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.alive():
            if any("solved in" in line for line in self.lines):
                return True
            time.sleep(0.05)
        return False

    def judge(self, case: bytes, reset: bool = False) -> str:
        """What the server did with one case: ``answered NNN``, ``closed`` (no answer),
        ``reset by client``; a string starting ``FAIL`` when it did what it must not (a
        500, a status it has no reason to give, no status line, no answer nor close in
        time)."""
        with socket.create_connection(("127.0.0.1", self.port), timeout=TIMEOUT) as client:
            try:
                client.sendall(case)
                if reset:  # gone at once: the server's answer meets a reset connection
                    client.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                    return "reset by client"
                client.shutdown(socket.SHUT_WR)
            except OSError:  # closed by the server before all was sent (a refusal)
                pass
            got = b""
            deadline = time.monotonic() + TIMEOUT
            try:
                while b"\r\n\r\n" not in got and time.monotonic() < deadline:
                    chunk = client.recv(65536)
                    if not chunk:
                        break
                    got += chunk
            except TimeoutError:
                return "FAIL: no answer and no close within the timeout"
            except OSError:  # reset by the server after a refusal
                pass
        if not got:
            return "closed"
        status = re.match(rb"HTTP/1\.[01] (\d{3}) ", got)
        if status is None:  # even a refusal of HTTP/0.9 has a status line
            return f"FAIL: an answer without a status line: {got[:60]!r}"
        code = int(status.group(1))
        return f"answered {code}" if code in STATUSES else f"FAIL: status {code}"

    def healthy(self) -> bool:
        """Whether a well-formed request still gets the state."""
        case = f"GET /state HTTP/1.1\r\nHost: 127.0.0.1:{self.port}\r\n\r\n".encode()
        return self.judge(case) == "answered 200"

    def run(self, seeds: Iterable[int], tally: Tally | None = None) -> Tally:
        """Send each seed's case and judge it (every tenth reset at once), checking the
        server's health and stderr every 50 cases and at the end."""
        tally = Tally() if tally is None else tally
        for count, seed in enumerate(seeds, 1):
            outcome = self.judge(http_case(seed, self.port), reset=seed % 10 == 9)
            tally.outcomes[outcome.split(":")[0]] += 1
            if outcome.startswith("FAIL"):
                tally.failures.append(f"seed {seed}: {outcome}")
            if count % 50 == 0:
                self._check(tally, seed)
        self._check(tally, "end")
        return tally

    def go_away(self, count: int, seed: int = 16) -> None:
        """``count`` clients that connect, send nothing, part or all of a request (the
        page, the model, the event stream...) and go, half of them by a reset, none
        reading the answer."""
        rng = random.Random(seed)
        requests = [
            f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{self.port}\r\n\r\n".encode() for path in PATHS
        ]
        for _ in range(count):
            client = socket.create_connection(("127.0.0.1", self.port), timeout=TIMEOUT)
            request = rng.choice(requests)
            client.sendall(request[: rng.choice([0, 5, len(request)])])
            if rng.random() < 0.5:  # a reset, not a close: the server's writes fail at once
                client.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            client.close()

    def _check(self, tally: Tally, at: object) -> None:
        if not self.alive():
            tally.failures.append(f"at {at}: the server died: {self.stderr()[-2000:]}")
        elif not self.healthy():
            tally.failures.append(f"at {at}: the server no longer answers /state")
        if self.errors:
            tally.failures.append(f"at {at}: the server printed: {self.stderr()[-2000:]}")
            self.errors.clear()

    def close(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()

    def __enter__(self) -> WatchedServer:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self.close()


def _drain(stream: object, into: list[str]) -> None:
    for line in stream:  # type: ignore[attr-defined]
        into.append(line)


def main(argv: list[str]) -> int:
    """``python -m tests.fuzz.serve_doors [CASES] [FIRST_SEED]``: the tally, exit 1 on a
    failure."""
    import shutil
    import tempfile

    cases = int(argv[0]) if argv else 1000
    first = int(argv[1]) if len(argv) > 1 else 0
    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder) / "house.yaml"
        shutil.copy(ROOT / "specs" / "residential-house.yaml", spec)
        with WatchedServer(spec) as server:
            if not server.solved():
                print(f"the server did not solve its spec: {server.stderr()}")
                return 1
            tally = server.run(range(first, first + cases))
            server.go_away(1500, first)
            time.sleep(KEEP_ALIVE + 1)  # the streams of gone clients find out
            server._check(tally, "1,500 clients gone early")
    print(tally, "(then 1,500 clients gone early)")
    for failure in tally.failures[:20]:
        print(" ", failure)
    return 1 if tally.failures else 0


# for tests/fuzz/run.py: a door that needs ``facade watch`` running
SERVER_DOORS = {"watch-http": lambda cases, first: main([str(cases), str(first)])}

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
