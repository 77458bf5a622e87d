"""``facade watch``: from save to page. A server runs in its own process on a copy of
residential-house; a client in this process follows its event stream as a page does.
Each of 50 saves writes the spec (a new canvas width, so each is solved; in place or by
rename, as editors do) and times until the ``layout`` event of the new version has
arrived whole. Prints the median, the 95th percentile and the slowest, and the server's
own solve time (the rest is the file event, reading, the page's bytes and the push).

``python tests/benchmarks/watch_bench.py [SAVES] [--poll]`` (``--poll``: the server polls
the file instead of waiting for file events).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "residential-house.yaml"
WIDTHS = (6.0, 6.5, 7.0, 7.5)  # all solve
TIMEOUT = 60.0


class Stream:
    """The server's event stream, read event by event."""

    def __init__(self, port: int, since: int):
        self.client = socket.create_connection(("127.0.0.1", port), timeout=TIMEOUT)
        head = f"GET /events?since={since} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n"
        self.client.sendall(head.encode())
        self.buffer = b""
        self.part(b"\r\n\r\n")

    def part(self, end: bytes) -> bytes:
        while end not in self.buffer:
            chunk = self.client.recv(1 << 20)
            if not chunk:
                raise RuntimeError("the event stream ended")
            self.buffer += chunk
        part, self.buffer = self.buffer.split(end, 1)
        return part

    def event(self) -> tuple[str, dict[str, object]]:
        while True:
            fields = dict(
                line.split(": ", 1)
                for line in self.part(b"\n\n").decode().splitlines()
                if ": " in line
            )
            if "event" in fields:
                return fields["event"], dict(json.loads(fields["data"]))


def percentile(values: list[float], share: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(share * (len(ordered) - 1)))]


def main(saves: int, poll: bool = False) -> None:
    folder = Path(tempfile.mkdtemp())
    spec = folder / "house.yaml"
    text = SPEC.read_text()
    spec.write_text(text)
    server = subprocess.Popen(
        [sys.executable, "-m", "facadecli", "watch", str(spec), "--port", "0"]
        + (["--poll"] if poll else []),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert server.stdout is not None
        found = re.search(r"127\.0\.0\.1:(\d+)/", server.stdout.readline())
        assert found, "facade watch did not start"
        stream = Stream(int(found.group(1)), since=0)
        kind, layout = stream.event()
        while kind != "layout":  # the state before the first solve, then its layout
            kind, layout = stream.event()
        version = int(str(layout["version"]))
        latencies, solves = [], []
        for save in range(saves):
            width = WIDTHS[(save + 1) % len(WIDTHS)]
            new = re.sub(r"canvas: \{width: [0-9.]+", f"canvas: {{width: {width}", text)
            started = time.perf_counter()
            if save % 2:  # by rename, as most editors save
                fresh = folder / ".house.yaml.new"
                fresh.write_text(new)
                os.replace(fresh, spec)
            else:  # in place
                spec.write_text(new)
            while True:
                kind, data = stream.event()
                if kind == "layout" and data["version"] == version + 1:
                    latencies.append((time.perf_counter() - started) * 1000)
                    break
                if kind == "state" and data["error"]:
                    raise RuntimeError(f"width {width}: {data['error']}")
            kind, state = stream.event()  # the state that follows each layout
            solves.append(float(str(state["solved_ms"])))
            version += 1
            time.sleep(0.05)  # saves a person makes are apart
        how = "polling" if poll else "file events"
        print(f"facade watch, save to page ({saves} saves of {SPEC.name}, warm, {how})")
        print(
            f"  save -> layout event received: median {statistics.median(latencies):.1f} ms, "
            f"p95 {percentile(latencies, 0.95):.1f} ms, slowest {max(latencies):.1f} ms"
        )
        print(
            f"  of which the server's solve (glb, SVG, page): median "
            f"{statistics.median(solves):.1f} ms, p95 {percentile(solves, 0.95):.1f} ms"
        )
    finally:
        server.terminate()
        server.wait(timeout=TIMEOUT)
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    numbers = [arg for arg in sys.argv[1:] if arg.isdigit()]
    main(int(numbers[0]) if numbers else 50, "--poll" in sys.argv[1:])
