"""Reading a user's input file: never more than its limit, text as UTF-8 with the place of
a bad byte. Shared by the spec, GeoJSON and layout readers."""

from __future__ import annotations

from pathlib import Path

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
    chunks, size = [], 0
    with path.open("rb") as handle:  # in chunks: one read of limit + 1 bytes would claim
        while size <= limit:  # that much memory first, however small the file
            chunk = handle.read(min(CHUNK, limit + 1 - size))
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
