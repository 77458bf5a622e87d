"""Run the ``facade`` command in the test process, as a user would from a shell."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from facadecli.cli import main


def facade(capsys: pytest.CaptureFixture[str], *args: str | Path) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of one command; never a traceback or internal error."""
    argv = sys.argv
    sys.argv = ["facade", *map(str, args)]
    try:
        main()
        code = 0
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    finally:
        sys.argv = argv
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "internal error" not in err, err
    return code, out, err


def files(folder: Path) -> list[str]:
    """Every file and folder under ``folder`` (none when it does not exist)."""
    return sorted(p.name for p in folder.rglob("*")) if folder.exists() else []
