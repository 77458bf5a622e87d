"""Atomic file writes: a reader sees the old file or the new one, never half of one.

A run stages its outputs in a folder of its own inside the output folder
(``.facade-HOST-PID-START-XXXXXXXX``: the host, the process id and its start time, so a
later run can tell whether its owner is still running). A run killed outright (``kill -9``,
a power cut) leaves its staging folder behind; the next run into the same folder removes
such folders of processes that are gone, and only those: folders of runs still going, of
other hosts, or named any other way are never touched. Staging folders of facadecli 0.1.0
(``.facade-XXXXXXXX``) name no owner, so they are never removed either: a run that finds
them says so once (a :class:`~facadecli.errors.FacadeWarning`).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import socket
import tempfile
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from facadecli.errors import FacadeWarning, OutputError, SpecError


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


STAGING_PREFIX = ".facade-"
_STAGING = re.compile(
    r"\.facade-(?P<host>[A-Za-z0-9.]+)-(?P<pid>[0-9]+)-(?P<start>[0-9]+)-[a-z0-9_]+"
)


#: what facadecli 0.1.0 named its staging folders (``tempfile.mkdtemp``'s 8 letters)
_OWNERLESS_STAGING = re.compile(r"\.facade-[a-z0-9_]{8}")


def _host() -> str:
    """This machine's name, in the characters a staging folder's name allows."""
    return re.sub(r"[^A-Za-z0-9.]", "", socket.gethostname())[:64] or "localhost"


def _started(pid: int) -> int | None:
    """When process ``pid`` started (clock ticks since boot, Linux), 0 where that cannot be
    read but the process exists, None when there is no such process."""
    if os.name == "nt":  # os.kill(pid, 0) would send it a Ctrl-C: take it to be running
        return 0
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
        return int(stat.rsplit(")", 1)[1].split()[19])  # field 22: starttime
    except (OSError, ValueError, IndexError):
        pass
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return None
    except OSError:  # it exists, owned by someone else
        return 0
    return 0


def _staging_name() -> str:
    pid = os.getpid()
    return f"{STAGING_PREFIX}{_host()}-{pid}-{_started(pid) or 0}-"


def remove_stale_staging(folder: Path) -> list[Path]:
    """Remove the staging folders in ``folder`` whose run is gone (killed before it could
    clean up): named as ``staged`` names them, on this host, by a process that no longer
    runs (or a new process with the same id). Returns what was removed."""
    removed: list[Path] = []
    host = _host()
    try:
        entries = list(folder.iterdir())
    except OSError:
        return removed
    ownerless = []
    for entry in entries:
        found = _STAGING.fullmatch(entry.name)
        if found is None and _OWNERLESS_STAGING.fullmatch(entry.name) and entry.is_dir():
            ownerless.append(entry.name)
        if found is None or found["host"] != host:
            continue
        started, recorded = _started(int(found["pid"])), int(found["start"])
        # a process with the id that started at another time took the id of a gone one
        alive = started is not None and (0 in (started, recorded) or started == recorded)
        if alive or entry.is_symlink() or not entry.is_dir():
            continue
        shutil.rmtree(entry, ignore_errors=True)
        removed.append(entry)
    if ownerless:
        _warn_ownerless(folder, sorted(ownerless))
    return removed


def _warn_ownerless(folder: Path, names: list[str]) -> None:
    shown = ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")
    warnings.warn(
        FacadeWarning(
            f"{folder}: warning: {len(names)} staging folder{'s' * (len(names) > 1)} of "
            f"facadecli 0.1.0 left as they are ({shown}): they name no owner, so they may be "
            "a run's still writing here; remove them when no facade run writes into this folder"
        ),
        stacklevel=2,
    )


@contextlib.contextmanager
def staged(folder: str | Path) -> Iterator[Path]:
    """A temporary folder inside ``folder`` for one run's outputs. When the block ends
    without an error its files move into ``folder`` (each an atomic rename); on an error
    they are removed, so a run's outputs appear together or not at all. A failure to
    write (a full disk) is an :class:`OutputError`. Staging folders that killed runs left
    in ``folder`` are removed first (``remove_stale_staging``)."""
    target = Path(folder)
    moved: list[Path] = []
    try:
        target.mkdir(parents=True, exist_ok=True)
        remove_stale_staging(target)
        stage = Path(tempfile.mkdtemp(prefix=_staging_name(), dir=target))
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
