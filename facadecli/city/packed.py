"""A run's tasks kept packed (:class:`Packed`): what lets a client plan a city of any
size in little memory.

A building's task holds its footprint, tags, heights, roof, party walls... as Python
and GEOS objects: kilobytes a building, held for the whole run. Packed, tasks are kept
in chunks of :data:`CHUNK`, each pickled (geometry as its WKB: exact coordinates) and
compressed, the run's specs (large, and the same objects for many buildings) named by a
key rather than copied (:meth:`pickle.Pickler.persistent_id`); a task is made again when
it is read, equal to the one put in. Reading in order decodes each chunk once. The
packed chunks are spilled to an unnamed temporary file (gone when the object is, or the
process): what stays in memory is where each chunk starts, 8 bytes for CHUNK items.
"""

from __future__ import annotations

import io
import pickle
import tempfile
import zlib
from array import array
from collections.abc import Iterable, Iterator, Sequence
from typing import Any, Generic, TypeVar, overload

T = TypeVar("T")

CHUNK = 64  # items a chunk: compressed together (their tags and class names repeat)
LEVEL = 6  # zlib's level: deterministic for a given input


class Positional(Sequence[T], Generic[T]):
    """A sequence read by position: slices, negative positions and the bounds handled
    here once; a subclass gives its length and :meth:`_at` (a position within bounds)."""

    def _at(self, index: int) -> T:
        raise NotImplementedError

    @overload
    def __getitem__(self, index: int) -> T: ...

    @overload
    def __getitem__(self, index: slice) -> list[T]: ...

    def __getitem__(self, index: int | slice) -> T | list[T]:
        if isinstance(index, slice):
            return [self._at(i) for i in range(*index.indices(len(self)))]
        if index < 0:
            index += len(self)
        if not 0 <= index < len(self):
            raise IndexError(index)
        return self._at(index)


class Pickling:
    """Items pickled with the large objects they refer to named, not copied (``shared``:
    name -> object, the run's specs, which stay in memory anyway), and read back."""

    def __init__(self, shared: dict[str, object] | None = None):
        self._shared = dict(shared or {})
        self._names = {id(item): name for name, item in self._shared.items()}

    def _dumps(self, item: object) -> bytes:
        buffer = io.BytesIO()
        pickler = pickle.Pickler(buffer, protocol=pickle.HIGHEST_PROTOCOL)
        pickler.persistent_id = lambda item: self._names.get(id(item))  # type: ignore[method-assign]
        pickler.dump(item)
        return zlib.compress(buffer.getvalue(), LEVEL)

    def _loads(self, data: bytes) -> Any:
        unpickler = pickle.Unpickler(io.BytesIO(zlib.decompress(data)))
        unpickler.persistent_load = self._shared.__getitem__  # type: ignore[method-assign]
        return unpickler.load()


class Spooled(Pickling, Positional[T]):
    """Items appended (:meth:`append`) then read by position in any order, each pickled
    (as :class:`Pickling`) and compressed into an unnamed temporary file: 8 bytes an
    item in memory (its offset), one item unpacked at a time. For what is put in one
    order and read in another (a town's regions' tasks, run.py), or read again later
    (the features a survey of a footprints file keeps, footprints.py)."""

    def __init__(self, shared: dict[str, object] | None = None):
        super().__init__(shared)
        self._file = tempfile.TemporaryFile()  # noqa: SIM115 (open as long as the items)
        self._offsets = array("q")

    def append(self, item: T) -> None:
        data = self._dumps(item)
        self._file.seek(0, io.SEEK_END)
        self._offsets.append(self._file.tell())
        self._file.write(len(data).to_bytes(4, "little") + data)

    def only(self, positions: Iterable[int]) -> Spooled[T]:
        """The items at ``positions``, in that order (the same file, not copied)."""
        kept: Spooled[T] = Spooled.__new__(Spooled)
        kept._shared, kept._names, kept._file = self._shared, self._names, self._file
        kept._offsets = array("q", (self._offsets[k] for k in positions))
        return kept

    def __len__(self) -> int:
        return len(self._offsets)

    def _at(self, index: int) -> T:
        self._file.seek(self._offsets[index])
        size = int.from_bytes(self._file.read(4), "little")
        item: T = self._loads(self._file.read(size))
        return item


class Packed(Pickling, Positional[T]):
    """Items appended (:meth:`append`) then read by position, kept packed in chunks
    spilled to an unnamed temporary file (see the module). ``shared`` names the large
    objects the items refer to and that stay in memory anyway (the run's specs, by
    their manifest path): they are packed as their name. Items must be picklable, and
    equal to themselves pickled and unpickled."""

    def __init__(self, shared: dict[str, object] | None = None, chunk: int = CHUNK):
        super().__init__(shared)
        self._chunk = chunk
        self._file = tempfile.TemporaryFile()  # noqa: SIM115 (open as long as the items)
        self._starts = array("q", [0])  # where each packed chunk starts in the file, then the end
        self._open: list[T] = []  # the last chunk, not yet packed
        self._cached: tuple[int, list[T]] = (-1, [])  # the last chunk read

    def append(self, item: T) -> None:
        self._open.append(item)
        if len(self._open) == self._chunk:
            data = self._pack(self._open)
            self._file.seek(self._starts[-1])
            self._file.write(data)
            self._starts.append(self._starts[-1] + len(data))
            self._open = []

    def extend(self, items: Iterable[T]) -> None:
        for item in items:
            self.append(item)

    def packed_bytes(self) -> int:
        """The bytes the packed chunks take (their payload, on disk)."""
        return self._starts[-1]

    def _packed(self, number: int) -> bytes:
        """The packed chunk ``number``, read from the file."""
        start = self._starts[number]
        self._file.seek(start)
        return self._file.read(self._starts[number + 1] - start)

    def _pack(self, items: list[T]) -> bytes:
        return self._dumps(items)

    def _unpack(self, data: bytes) -> list[T]:
        items: list[T] = self._loads(data)
        return items

    def _chunk_at(self, number: int) -> list[T]:
        if number == len(self._starts) - 1:
            return self._open
        if self._cached[0] != number:
            self._cached = (number, self._unpack(self._packed(number)))
        return self._cached[1]

    def __len__(self) -> int:
        return (len(self._starts) - 1) * self._chunk + len(self._open)

    def _at(self, index: int) -> T:
        return self._chunk_at(index // self._chunk)[index % self._chunk]

    def __iter__(self) -> Iterator[T]:
        for number in range(len(self._starts) - 1):
            yield from self._unpack(self._packed(number))  # not cached: a pass in order
        yield from list(self._open)

    def __repr__(self) -> str:
        return f"Packed({len(self)} items, {self.packed_bytes()} bytes packed)"


class Points(Positional[tuple[float, float]]):
    """Points (x, y) appended then read by position, kept as their floats in one array:
    16 bytes a point, where a list of tuples takes 112 in small objects."""

    def __init__(self) -> None:
        self._xy = array("d")

    def append(self, point: tuple[float, float]) -> None:
        self._xy.extend(point)

    def __len__(self) -> int:
        return len(self._xy) // 2

    def _at(self, index: int) -> tuple[float, float]:
        return self._xy[2 * index], self._xy[2 * index + 1]


class Picked(Sequence[T], Generic[T]):
    """Some of a sequence's items, by their positions in it (ascending), read from it."""

    def __init__(self, items: Sequence[T], positions: Iterable[int]):
        self._items = items
        self.positions = array("q", positions)

    def __len__(self) -> int:
        return len(self.positions)

    @overload
    def __getitem__(self, index: int) -> T: ...

    @overload
    def __getitem__(self, index: slice) -> list[T]: ...

    def __getitem__(self, index: int | slice) -> T | list[T]:
        if isinstance(index, slice):
            return [self._items[p] for p in self.positions[index]]
        return self._items[self.positions[index]]

    def __iter__(self) -> Iterator[T]:
        return (self._items[p] for p in self.positions)
