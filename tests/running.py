"""Run the ``facade`` command in the test process, as a user would from a shell."""

from __future__ import annotations

import io
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

from facadecli.cli import main


def _exit_code(args: tuple[str | Path, ...]) -> int:
    """The exit code of ``facade ARGS`` run by :func:`facadecli.cli.main`."""
    argv = sys.argv
    sys.argv = ["facade", *map(str, args)]
    try:
        main()
        return 0
    except SystemExit as stop:
        return stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    finally:
        sys.argv = argv


def _no_traceback(err: str) -> None:
    assert "Traceback" not in err and "internal error" not in err, err


def facade(capsys: pytest.CaptureFixture[str], *args: str | Path) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of one command; never a traceback or internal error."""
    code = _exit_code(args)
    out, err = capsys.readouterr()
    _no_traceback(err)
    return code, out, err


def facade_output(*args: str | Path) -> tuple[int, str, str]:
    """As :func:`facade`, its output taken without a capture fixture: for a fixture a
    module's tests share (``capsys`` is a test's own)."""
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = _exit_code(args)
    _no_traceback(err.getvalue())
    return code, out.getvalue(), err.getvalue()


def files(folder: Path) -> list[str]:
    """Every file and folder under ``folder`` (none when it does not exist)."""
    return sorted(p.name for p in folder.rglob("*")) if folder.exists() else []
