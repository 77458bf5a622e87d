"""Reading a user's input file: never more than its limit, text as UTF-8 with the place of
a bad byte. Shared by the spec, GeoJSON and layout readers."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path
from typing import BinaryIO

from facadecli.errors import SpecError

CHUNK = 1 << 20  # bytes read at a time


def read_at_most(path: Path, limit: int) -> bytes | None:
    """The file's bytes, or None when it holds more than ``limit``: at most one byte past
    the limit is read (a device such as /dev/zero never ends). OSError propagates."""
    data = read_prefix(path, limit)
    return None if len(data) > limit else data


def read_prefix(path: Path, limit: int) -> bytes:
    """The file's first ``limit + 1`` bytes at most: all of it when it is within the limit
    (see ``read_at_most``), else enough to say where it goes past. OSError propagates."""
    with path.open("rb") as handle:
        return _prefix(handle, limit)


class NotRegularFile(OSError):
    """The path names a device, a pipe, a socket or a folder, not a file of bytes."""


def read_regular_at_most(
    path: Path, limit: int, follow_links: bool = True
) -> tuple[bytes | None, os.stat_result]:
    """Like :func:`read_at_most` for a regular file only (NotRegularFile otherwise, before
    reading a byte: a pipe would wait for a writer, a device never end), with the file's
    status when it was opened; ``follow_links=False`` refuses a link as the last part of
    ``path`` (OSError ELOOP)."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow_links:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    descriptor = os.open(path, flags)  # non-blocking: a pipe opens at once, unread
    with os.fdopen(descriptor, "rb") as handle:
        status = os.fstat(descriptor)
        if not stat.S_ISREG(status.st_mode):
            raise NotRegularFile(errno.EINVAL, "not a regular file", str(path))
        data = _prefix(handle, limit)
        return (None if len(data) > limit else data), status


def _prefix(handle: BinaryIO, limit: int) -> bytes:
    chunks, size = [], 0
    while size <= limit:  # in chunks: one read of limit + 1 bytes would claim that much
        chunk = handle.read(min(CHUNK, limit + 1 - size))  # memory first, however small
        if not chunk:
            break
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


def place(data: bytes, offset: int) -> tuple[int, int]:
    """The 1-based line and column (in characters) of byte ``offset`` of UTF-8 text."""
    line = data.count(b"\n", 0, offset) + 1
    start = data.rfind(b"\n", 0, offset) + 1
    return line, len(data[start:offset].decode("utf-8", "replace")) + 1


def decode_utf8(data: bytes, file: str, hint: str) -> str:
    """UTF-8 text without a leading BOM; a bad byte is a SpecError at its line and column."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line, col = place(data, error.start)
        raise SpecError.at(file, line, col, "not UTF-8 text", hint) from None
