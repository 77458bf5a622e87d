"""One run at a time in an output folder, by a lock the system drops when the run ends,
however it ends (``kill -9`` and power cuts included: nothing stale is left to clean).

- Where ``fcntl`` exists (Linux, macOS, the BSDs): ``flock`` on the folder itself; nothing
  is written.
- On Windows (``msvcrt``): ``msvcrt.locking`` on the first byte of a lock file in the
  folder, :data:`LOCK_NAME`, which the run removes as it ends (a killed run's lock file
  stays, unlocked, and the next run takes it).
- Elsewhere, or on a file system that has no locks, runs are not locked.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

from facadecli.errors import OutputError, SpecError

fcntl: ModuleType | None
msvcrt: ModuleType | None
try:
    import fcntl
except ImportError:  # Windows
    fcntl = None
try:
    import msvcrt
except ImportError:  # everywhere but Windows
    msvcrt = None

LOCK_NAME = ".facade-lock"  # the lock file, where the folder itself cannot be locked


class _Busy(Exception):
    """Another process holds the lock."""


@contextlib.contextmanager
def locked(folder: Path, command: str) -> Iterator[None]:
    """``folder``, made if missing and locked for this run: another run of ``command`` into
    it meanwhile is exit 2."""
    held = contextlib.ExitStack()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        held.enter_context(_held(folder))
    except _Busy:
        raise SpecError.at(
            "--output",
            None,
            None,
            f"another {command} run is writing in '{folder}'",
            "wait for it to end, or give another folder",
        ) from None
    except OSError as error:
        raise OutputError(f"{folder}: cannot write the outputs: {error.strerror}") from None
    with held:  # the run's own errors pass through as they are
        yield


@contextlib.contextmanager
def _held(folder: Path) -> Iterator[None]:
    if fcntl is not None:
        with _flocked(folder):
            yield
    elif msvcrt is not None:
        with _byte_locked(folder / LOCK_NAME):
            yield
    else:  # no locks on this platform
        yield


@contextlib.contextmanager
def _flocked(folder: Path) -> Iterator[None]:
    assert fcntl is not None
    handle = os.open(folder, os.O_RDONLY)
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise _Busy from None
        except OSError:  # a file system without locks: run unlocked
            pass
        yield
    finally:
        os.close(handle)  # and with it the lock


@contextlib.contextmanager
def _byte_locked(path: Path) -> Iterator[None]:
    assert msvcrt is not None
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise OSError(0, f"'{path.name}' is not a regular file")
    handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        msvcrt.locking(handle, msvcrt.LK_NBLCK, 1)
    except OSError:  # held by another process (EACCES, EDEADLOCK)
        os.close(handle)
        raise _Busy from None
    try:
        yield
    finally:
        os.lseek(handle, 0, os.SEEK_SET)
        with contextlib.suppress(OSError):
            msvcrt.locking(handle, msvcrt.LK_UNLCK, 1)
        os.close(handle)
        with contextlib.suppress(OSError):  # another run may hold it open by now: it stays
            path.unlink()
