"""Atomic file writes: a reader sees the old file or the new one, never half of one."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from facadecli.errors import OutputError, SpecError


@contextlib.contextmanager
def atomic_output(path: str | Path) -> Iterator[BinaryIO]:
    """A binary file that replaces ``path`` only when the block ends without an error."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(temporary, 0o644)
        os.replace(temporary, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        raise


def write_atomic(path: str | Path, content: bytes | str) -> None:
    """Write ``content`` to ``path`` through a temporary file in the same folder."""
    with atomic_output(path) as handle:
        handle.write(content.encode("utf-8") if isinstance(content, str) else content)


def check_output_file(file: str | Path, option: str = "--output") -> None:
    """Before any work: ``file`` may be replaced by a regular file (it is one or does not
    exist: a device, a folder or a link to one is never replaced) in a folder this
    process can write in."""
    path = Path(file)
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise SpecError.at(
            option, None, None, f"'{file}' is not a regular file", "name a file to write"
        )
    check_output_folder(path.parent, option)


def check_output_folder(folder: str | Path, option: str = "--output") -> None:
    """Before any work: ``folder`` is a folder this process can write in, or can be made
    one (its nearest existing ancestor is a writable folder)."""
    path = Path(folder)
    existing = path
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        where = "is not a folder" if existing == path else f"is under '{existing}', not a folder"
        raise SpecError.at(
            option, None, None, f"'{folder}' {where}", "give a folder; it is made if missing"
        )
    if not os.access(existing, os.W_OK | os.X_OK):
        raise SpecError.at(
            option,
            None,
            None,
            f"cannot write in '{existing}' (permission denied)",
            "choose a folder you may write in",
        )


@contextlib.contextmanager
def staged(folder: str | Path) -> Iterator[Path]:
    """A temporary folder inside ``folder`` for one run's outputs. When the block ends
    without an error its files move into ``folder`` (each an atomic rename); on an error
    they are removed, so a run's outputs appear together or not at all. A failure to
    write (a full disk) is an :class:`OutputError`."""
    target = Path(folder)
    moved: list[Path] = []
    try:
        target.mkdir(parents=True, exist_ok=True)
        stage = Path(tempfile.mkdtemp(prefix=".facade-", dir=target))
    except OSError as error:
        raise OutputError(f"{target}: cannot write the outputs: {error.strerror}") from None
    try:
        yield stage
        for item in sorted(stage.iterdir()):
            os.replace(item, target / item.name)
            moved.append(target / item.name)
    except BaseException as error:
        for path in moved:
            with contextlib.suppress(OSError):
                path.unlink()
        if isinstance(error, OSError):
            raise OutputError(f"{target}: cannot write the outputs: {error.strerror}") from None
        raise
    finally:
        shutil.rmtree(stage, ignore_errors=True)
