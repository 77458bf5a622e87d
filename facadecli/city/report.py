"""A city's report (:class:`CityReport`), kept and written in flat memory.

Its per-building entries are kept as the JSON lines they are logged as, in a temporary
file (:class:`Entries`: 12 bytes a building in memory, where a parsed entry takes
kilobytes), their sums are kept as they come (:class:`Tally`), and
``<name>.report.json`` is written a building at a time (:func:`report_chunks`), its
bytes those of ``json.dumps(report, indent=2)`` of the whole document.
"""

from __future__ import annotations

import dataclasses
import json
import tempfile
from array import array
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, overload

from facadecli.city.building import PLAIN_REASONS

Entry = dict[str, Any]  # a building's report entry (docs/reference/report.md)


class Entries(Sequence[Entry]):
    """The buildings' report entries in the manifest's order, each kept as its compact JSON
    line and parsed when asked for. Filled by position as buildings end, in any order.

    The lines are kept in an unnamed temporary file (in ``folder``, the run's output
    folder, or the system's), where each is and how long held in memory: 12 bytes a
    building, however many buildings; the file goes when the object does."""

    def __init__(self, count: int, folder: Path | None = None):
        self._file = tempfile.TemporaryFile(dir=folder)  # noqa: SIM115 (closed with self)
        self._start = array("q", [-1]) * count  # where each line starts in the file
        self._size = array("I", [0]) * count
        self._end = 0

    def put(self, index: int, entry: Entry) -> bytes:
        """Keep the entry of the building at ``index``; returns its line (no newline)."""
        line = json.dumps(entry).encode("utf-8")
        self._file.seek(self._end)
        self._file.write(line)
        self._start[index], self._size[index] = self._end, len(line)
        self._end += len(line)
        return line

    def line(self, index: int) -> bytes:
        """The entry of the building at ``index`` as its line (no newline)."""
        if self._start[index] < 0:
            raise LookupError(f"no entry yet for building {index}")
        self._file.seek(self._start[index])
        return self._file.read(self._size[index])

    def __len__(self) -> int:
        return len(self._start)

    @overload
    def __getitem__(self, index: int) -> Entry: ...

    @overload
    def __getitem__(self, index: slice) -> list[Entry]: ...

    def __getitem__(self, index: int | slice) -> Entry | list[Entry]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        parsed: Entry = json.loads(self.line(index))
        return parsed

    def __repr__(self) -> str:
        return f"Entries({len(self)} buildings)"


@dataclass
class Tally:
    """The report's sums over the buildings, added to as each one ends."""

    ok: int = 0
    failed: int = 0
    party_walls: int = 0
    plain_walls: Counter[str] = field(default_factory=Counter)

    def add(self, entry: Entry) -> None:
        if entry["status"] == "ok":
            self.ok += 1
        else:
            self.failed += 1
        self.party_walls += entry.get("party_walls", 0)
        self.plain_walls.update(entry.get("plain", {}))

    def plain_by_reason(self) -> dict[str, int]:
        return {reason: self.plain_walls[reason] for reason in PLAIN_REASONS}


def report_chunks(report: dict[str, Any], key: str, entries: Iterable[Entry]) -> Iterator[str]:
    """``json.dumps(report, indent=2) + "\\n"`` with ``entries`` as ``report[key]`` (which
    stands for them: any value), a piece at a time: an entry at a time in the list, so no
    more than one is held as text."""
    marker = "\0entries\0"
    text = json.dumps({**report, key: marker}, indent=2)
    before, after = text.split(json.dumps(marker), 1)
    yield before
    first = True
    for entry in entries:
        inner = json.dumps(entry, indent=2).replace("\n", "\n    ")
        yield ("[\n    " if first else ",\n    ") + inner
        first = False
    yield "[]" if first else "\n  ]"
    yield after + "\n"


@dataclass(frozen=True)
class Summary:
    """The report's ``summary``: the run in numbers (docs/reference/city.md#outputs)."""

    buildings: int  # planned
    ok: int
    failed: int
    rejected: int  # features that are not footprints
    warnings: int  # built features with tags ignored
    outside_bbox: int
    replaced: int  # outlines whose parts stand in all of them
    trimmed: int  # outlines of which a rest is built beside their parts
    party_walls: int
    plain_walls: dict[str, int]  # by reason (PLAIN_REASONS)
    collinear_nodes_merged: int
    warnings_by_tag: dict[str, int]
    seconds: float
    ground: dict[str, int] = dataclasses.field(default_factory=dict)  # land cover by kind


@dataclass(frozen=True)
class CityReport(Mapping[str, Any]):
    """A city run's report, ``<name>.report.json``: a typed object, read as its JSON
    document too (``report["summary"]["ok"]``), whose keys are its fields in order."""

    name: str
    crs: str
    origin: list[float]
    georeference: dict[str, Any]
    buildings: Entries
    rejected: list[Entry]
    warnings: list[Entry]
    replaced: list[Entry]
    models: dict[str, Any]  # what the writers wrote (facadecli.export.CITY_WRITERS)
    summary: Summary
    version: int = 1
    timings: bool = False  # the times written as measured (else null: the file reproducible)

    def document(self) -> dict[str, Any]:
        """The report as JSON data: ``version`` first, then the fields in order (the
        buildings left as they are: :func:`report_chunks` writes them one at a time)."""
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        fields["summary"] = dataclasses.asdict(self.summary)
        del fields["timings"]
        return {"version": fields.pop("version"), **fields}

    def chunks(self) -> Iterator[str]:
        """The report's JSON text, a building at a time (:func:`report_chunks`); without
        ``timings``, the buildings' ``time_ms`` and the summary's ``seconds`` are null, so
        that the same input gives the same bytes (the object keeps them, for the CLI)."""
        document = self.document()
        if self.timings:
            return report_chunks(document, "buildings", self.buildings)
        document["summary"] = {**document["summary"], "seconds": None}
        untimed = (
            {**entry, "time_ms": None} if "time_ms" in entry else entry for entry in self.buildings
        )
        return report_chunks(document, "buildings", untimed)

    def __getitem__(self, key: str) -> Any:
        return self.document()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.document())

    def __len__(self) -> int:
        return len(dataclasses.fields(self)) - 1  # timings is how it is written, not a key
