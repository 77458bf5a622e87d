"""Reading a user's input file: never more than its limit, text as UTF-8 with the place of
a bad byte. Shared by the spec, GeoJSON and layout readers."""

from __future__ import annotations

from pathlib import Path

from facadecli.errors import SpecError

CHUNK = 1 << 20  # bytes read at a time


def read_at_most(path: Path, limit: int) -> bytes | None:
    """The file's bytes, or None when it holds more than ``limit``: at most one byte past
    the limit is read (a device such as /dev/zero never ends). OSError propagates."""
    chunks, size = [], 0
    with path.open("rb") as handle:  # in chunks: one read of limit + 1 bytes would claim
        while size <= limit:  # that much memory first, however small the file
            chunk = handle.read(min(CHUNK, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    return None if size > limit else b"".join(chunks)


def decode_utf8(data: bytes, file: str, hint: str) -> str:
    """UTF-8 text without a leading BOM; a bad byte is a SpecError at its line and column."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        start = data.rfind(b"\n", 0, error.start) + 1
        col = len(data[start : error.start].decode("utf-8", "replace")) + 1
        raise SpecError.at(file, line, col, "not UTF-8 text", hint) from None
