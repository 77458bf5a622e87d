"""The ``facade`` command as a user runs it: exit codes, messages, no tracebacks."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from facadecli import __version__

ROOT = Path(__file__).resolve().parent.parent
CASES = Path(__file__).parent / "cases"
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))


def facade(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "COLUMNS": "200", "NO_COLOR": "1"}
    return subprocess.run(
        [sys.executable, "-m", "facadecli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=60,
    )


def test_version() -> None:
    result = facade("--version")
    assert result.returncode == 0
    assert result.stdout.strip() == f"facade {__version__}"


def test_validate_accepts_every_example() -> None:
    result = facade("validate", *map(str, EXAMPLES), str(CASES / "valid" / "spec-md-example.yaml"))
    assert result.returncode == 0, result.stderr
    assert result.stdout.count(": ok (") == len(EXAMPLES) + 1


@pytest.mark.parametrize("path", sorted((CASES / "invalid").glob("*.yaml")), ids=lambda p: p.stem)
def test_validate_rejects_with_position_and_no_traceback(path: Path) -> None:
    started = time.perf_counter()
    result = facade("validate", str(path))
    elapsed = time.perf_counter() - started
    assert result.returncode == 2
    assert "Traceback" not in result.stderr + result.stdout
    line, col = path.read_text().split()[2].split(":")
    assert f"{path}:{line}:{col}: error: " in result.stderr
    assert elapsed < 5.0  # includes starting Python; the check itself is timed in test_spec


def test_binary_garbage_and_missing_files(tmp_path: Path) -> None:
    garbage = tmp_path / "garbage.yaml"
    garbage.write_bytes(os.urandom(4096))
    result = facade("validate", str(garbage), str(tmp_path / "missing.yaml"), str(tmp_path))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert f"{garbage}" in result.stderr
    assert f"{tmp_path / 'missing.yaml'}: error: no such file" in result.stderr
    assert "is a folder" in result.stderr


def test_bad_options_exit_2() -> None:
    result = facade("validate", "--no-such-option")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_schema_is_json_and_matches_the_checked_in_copy(tmp_path: Path) -> None:
    result = facade("schema")
    assert result.returncode == 0
    schema = json.loads(result.stdout)
    assert schema["title"] == "facadecli façade spec"
    assert result.stdout == (ROOT / "specs" / "facade.schema.json").read_text()
    assert facade("schema", "-o", str(tmp_path / "s.json")).returncode == 0
    assert (tmp_path / "s.json").read_text() == result.stdout


def test_words_previews_each_layer() -> None:
    result = facade("words", str(CASES / "valid" / "spec-md-example.yaml"), "-n", "2")
    assert result.returncode == 0, result.stderr
    assert "A B A B A B A   (k=3)" in result.stdout
    assert "C [e] C" in result.stdout
