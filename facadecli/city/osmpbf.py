"""Counting what an OSM PBF extract inflates to, before libosmium reads it.

A PBF file is a sequence of blocks: a 4-byte length, a BlobHeader, then a Blob that holds
its data compressed (zlib, mostly) with its size inflated (``raw_size``). Walking the
block headers reads a few bytes a block; their sizes inflated are summed and held to the
limit of a compressed extract (:func:`facadecli.city.osmxml.inflated_limit`, without the
cap on XML's bytes), so a small file that would inflate to gigabytes is refused before
the work. A file whose blocks cannot be walked is not a PBF extract (exit 2).
"""

from __future__ import annotations

from pathlib import Path
from typing import BinaryIO

from facadecli.errors import SpecError
from facadecli.limits import OSM_INFLATION_FREE, OSM_INFLATION_MAX

HEADER_MAX = 64 * 1024  # bytes of a BlobHeader (the PBF format's own limit)
BLOB_MAX = 32 * 1024 * 1024  # bytes of a Blob, compressed or inflated (libosmium's limit)
HINT = "download the extract again, or give it as .osm"


class _Broken(Exception):
    """The blocks cannot be walked: why."""


def check_pbf(path: Path) -> None:
    """Refuse the extract if its blocks inflate past the limit (see the module)."""
    file = str(path)
    size = path.stat().st_size
    most = max(OSM_INFLATION_FREE, OSM_INFLATION_MAX * size)
    inflated = 0
    with path.open("rb") as stream:
        while True:
            at = stream.tell()
            try:
                block = _block(stream)
            except _Broken as why:
                message = f"not an OSM extract: {why} (the PBF block at byte {at:,})"
                raise SpecError.at(file, None, None, message, HINT) from None
            if block is None:
                return
            inflated += block
            if inflated > most:
                raise SpecError.at(
                    file,
                    None,
                    None,
                    f"the extract inflates to more than {most:,} bytes (limit: "
                    f"{OSM_INFLATION_MAX} times its size, or {OSM_INFLATION_FREE:,} bytes)",
                    "cut the extract to the district (osmium extract --bbox)",
                )


def _exactly(stream: BinaryIO, count: int, what: str) -> bytes:
    """The next ``count`` bytes of the file, which must not end inside ``what``."""
    data = stream.read(count)
    if len(data) < count:
        raise _Broken(f"the file ends inside {what}")
    return data


def _block(stream: BinaryIO) -> int | None:
    """The inflated size of the next block (None at the end of the file)."""
    head = stream.read(4)
    if not head:
        return None
    if len(head) < 4:
        raise _Broken("the file ends inside a block's length")
    length = int.from_bytes(head, "big")
    if length > HEADER_MAX:
        raise _Broken(f"a block header of {length:,} bytes")
    header = _exactly(stream, length, "a block header")
    datasize = None
    for number, value in _fields(header):
        if number == 3 and isinstance(value, int):
            datasize = value
    if datasize is None or datasize > BLOB_MAX:
        raise _Broken("a block header without a valid data size")
    blob = _exactly(stream, datasize, "a block")
    raw = None
    for number, value in _fields(blob):
        if number == 1 and isinstance(value, bytes):
            raw = len(value)  # stored as it is
        elif number == 2 and isinstance(value, int):
            raw = value
    if raw is None or raw > BLOB_MAX:
        raise _Broken("a block without a valid inflated size")
    return raw


def _fields(message: bytes) -> list[tuple[int, int | bytes]]:
    """The top-level fields of a protobuf message: (number, varint or bytes)."""
    fields: list[tuple[int, int | bytes]] = []
    at = 0
    while at < len(message):
        key, at = _varint(message, at)
        number, kind = key >> 3, key & 7
        if kind == 0:
            value, at = _varint(message, at)
            fields.append((number, value))
        elif kind == 2:
            length, at = _varint(message, at)
            if at + length > len(message):
                raise _Broken("a field runs past its message")
            fields.append((number, message[at : at + length]))
            at += length
        elif kind in (1, 5):
            at += 8 if kind == 1 else 4
        else:
            raise _Broken(f"a field of wire type {kind}")
    if at > len(message):
        raise _Broken("a field runs past its message")
    return fields


def _varint(data: bytes, at: int) -> tuple[int, int]:
    value = shift = 0
    while True:
        if at >= len(data) or shift > 63:
            raise _Broken("a bad number in a block")
        byte = data[at]
        value |= (byte & 0x7F) << shift
        at += 1
        shift += 7
        if not byte & 0x80:
            return value, at
