"""``facade watch SPEC`` (issue 16): a live preview served on 127.0.0.1 that changes when
the spec's file does, tested with real HTTP requests (every wait bounded)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest

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
    assert b"<svg" in first and b"/state" in first  # the model, the elevation, the swap
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
