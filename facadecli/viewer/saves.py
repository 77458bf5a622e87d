"""Waiting for a file's next complete save: what ``facade watch`` solves on.

On Linux the kernel says when a file is saved (inotify, through a small ctypes binding:
no dependency): a writer closing the file (``IN_CLOSE_WRITE``), a file renamed onto its
name (``IN_MOVED_TO``: how most editors save), a link made in its place. A file still
being written is never reported, so a half-written spec is never read. The spec's
folder is watched, not the file, since an editor's rename replaces the file; when the
spec is a link, the folder of the file it names is watched too.

Elsewhere, or with ``--poll``, the file's status (inode, size, time) is looked at every
:data:`POLL` seconds, and a change is reported once the status has held still for
:data:`SETTLE` seconds (an empty file for :data:`SETTLE_EMPTY`: a save that truncates
first is empty for a moment).
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import select
import struct
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

POLL = 0.05  # seconds between looks at the file, when polling
SETTLE = 0.1  # seconds a polled file's status holds still before it counts as saved
SETTLE_EMPTY = 1.0  # the same for an empty file
GONE_GRACE = 0.25  # seconds a removed spec is given to come back (a save by rename)

IN_CLOSE_WRITE = 0x0008
IN_MOVED_FROM = 0x0040
IN_MOVED_TO = 0x0080
IN_CREATE = 0x0100
IN_DELETE = 0x0200
IN_DELETE_SELF = 0x0400
IN_MOVE_SELF = 0x0800
IN_Q_OVERFLOW = 0x4000
IN_IGNORED = 0x8000
IN_ONLYDIR = 0x0100_0000
IN_NONBLOCK = 0o4000
IN_CLOEXEC = 0o2000000
FOLDER_EVENTS = (
    (IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_MOVED_FROM | IN_DELETE)
    | IN_DELETE_SELF
    | IN_MOVE_SELF
)
EVENT = struct.Struct("iIII")  # struct inotify_event: wd, mask, cookie, len (then the name)


class Saves(Protocol):
    """Where a spec's saves come from."""

    kind: str  # "file events" or "polling", for the user

    def wait(self, timeout: float) -> bool:
        """Whether the file was saved (or removed, or replaced) within ``timeout`` seconds."""
        ...

    def close(self) -> None: ...


class FileEvents:
    """A spec's saves from the kernel's file events (Linux inotify)."""

    kind = "file events"

    def __init__(self, spec: Path):
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        self._add = libc.inotify_add_watch
        self._add.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_uint32]
        self._add.restype = ctypes.c_int
        self.fd = int(libc.inotify_init1(IN_NONBLOCK | IN_CLOEXEC))
        if self.fd < 0:
            raise OSError(ctypes.get_errno(), "inotify_init1 failed")
        self.spec = spec
        self.names: set[tuple[int, str]] = set()  # (watched folder, file name) of the spec
        self.folders: set[int] = set()
        try:
            self._follow()
        except OSError:
            os.close(self.fd)
            raise
        if not self.names:
            os.close(self.fd)
            raise OSError("no folder of the spec could be watched")

    def _follow(self) -> None:
        """Watch the spec's folder and, when it is a link, the folder of what it names."""
        places = [self.spec.absolute()]
        with contextlib.suppress(OSError, RuntimeError):  # a link to nothing, a loop
            places.append(self.spec.resolve(strict=True))
        for place in places:
            watch = self._add(self.fd, os.fsencode(place.parent), FOLDER_EVENTS | IN_ONLYDIR)
            if watch >= 0:
                self.folders.add(watch)
                self.names.add((watch, place.name))

    def _events(self, timeout: float) -> list[tuple[int, int, str]]:
        ready, _, _ = select.select([self.fd], [], [], max(timeout, 0.0))
        if not ready:
            return []
        try:
            data = os.read(self.fd, 1 << 16)
        except BlockingIOError:
            return []
        events, at = [], 0
        while at + EVENT.size <= len(data):
            watch, mask, _, length = EVENT.unpack_from(data, at)
            raw = data[at + EVENT.size : at + EVENT.size + length]
            events.append((watch, mask, os.fsdecode(raw.rstrip(b"\0"))))
            at += EVENT.size + length
        return events

    def wait(self, timeout: float) -> bool:
        if not self.folders:  # every watched folder went: look for them again, or wait
            self._follow()
            if not self.folders:
                time.sleep(max(min(timeout, 1.0), 0.0))
                return True
        deadline = time.monotonic() + timeout
        gone: float | None = None  # when a removal counts, unless the file comes back first
        while True:
            now = time.monotonic()
            until = deadline if gone is None else min(deadline, gone)
            for watch, mask, name in self._events(until - now):
                if mask & (IN_Q_OVERFLOW | IN_DELETE_SELF | IN_MOVE_SELF | IN_IGNORED):
                    if mask & IN_IGNORED:
                        self.folders.discard(watch)
                    return True  # events were lost, or a folder went: look at the file
                if (watch, name) not in self.names:
                    continue
                if mask & (IN_CLOSE_WRITE | IN_MOVED_TO):
                    self._follow()  # a new link may name a file in another folder
                    return True
                if mask & IN_CREATE and not _is_regular(self.spec):
                    self._follow()  # a link or a device: no write will follow
                    return True
                if mask & (IN_DELETE | IN_MOVED_FROM):
                    gone = time.monotonic() + GONE_GRACE
            now = time.monotonic()
            if gone is not None and now >= gone:
                if not os.path.lexists(self.spec):
                    return True
                gone = None  # it came back: the write that made it says when it is whole
            if now >= deadline:
                return False

    def close(self) -> None:
        os.close(self.fd)


def _is_regular(path: Path) -> bool:
    try:
        return path.is_file() and not path.is_symlink()
    except OSError:
        return False


Status = tuple[int, int, int, int] | None  # device, inode, size, time (ns); None: no file


def file_status(path: Path) -> Status:
    try:
        found = path.stat()
    except (OSError, ValueError):
        return None
    return (found.st_dev, found.st_ino, found.st_size, found.st_mtime_ns)


class Settling:
    """Decides, from the file's status seen at moments in time, when a change is a save:
    once the new status has held still for :data:`SETTLE` seconds (:data:`SETTLE_EMPTY`
    for an empty file)."""

    def __init__(self, status: Status):
        self.reported = status
        self.seen = status
        self.since = 0.0

    def look(self, status: Status, now: float) -> bool:
        if status != self.seen:
            self.seen, self.since = status, now
            return False
        if status == self.reported:
            return False
        empty = status is not None and status[2] == 0
        if now - self.since < (SETTLE_EMPTY if empty else SETTLE):
            return False
        self.reported = status
        return True


class Polling:
    """A spec's saves from looking at its status every :data:`POLL` seconds."""

    kind = "polling"

    def __init__(self, spec: Path, clock: Callable[[], float] = time.monotonic):
        self.spec = spec
        self.clock = clock
        self.settling = Settling(file_status(spec))

    def wait(self, timeout: float) -> bool:
        deadline = self.clock() + timeout
        while True:
            if self.settling.look(file_status(self.spec), self.clock()):
                return True
            if self.clock() >= deadline:
                return False
            time.sleep(POLL)

    def close(self) -> None:
        return


def watch_saves(spec: Path, poll: bool = False) -> tuple[Saves, str]:
    """The spec's saves from file events where the system has them, else by polling; and
    a note when polling although events were asked for."""
    if poll:
        return Polling(spec), ""
    if not sys.platform.startswith("linux"):
        return Polling(spec), f"no file events on {sys.platform} here: the file is polled"
    try:
        return FileEvents(spec), ""
    except (OSError, AttributeError) as error:  # no inotify (old kernel, no libc symbol)
        return Polling(spec), f"no file events ({error}): the file is polled"
