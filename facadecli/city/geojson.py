"""Reading GeoJSON defensively: RFC 7946, plus the legacy ``crs`` member.

A file that is not GeoJSON (not JSON, no FeatureCollection or Feature at the top, an
unusable ``crs``) is a SpecError at its line and column. A feature that is not a usable
polygon is a reason (a string) for the caller to report with the feature's place; nothing
here raises anything else, whatever the file holds.
"""

from __future__ import annotations

import codecs
import itertools
import json
import math
import os
import re
import stat
from array import array
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, BinaryIO, overload

import pyproj
import pyproj.exceptions
import shapely.errors
from shapely.geometry import MultiPolygon, Polygon

from facadecli.errors import SpecError
from facadecli.files import CHUNK, decode_utf8, read_at_most
from facadecli.limits import GEOJSON_BYTES_MAX, PROJECTED_MAX

GEOMETRY_TYPES = (
    "Point",
    "MultiPoint",
    "LineString",
    "MultiLineString",
    "Polygon",
    "MultiPolygon",
    "GeometryCollection",
)
MAX_PROJECTED = PROJECTED_MAX  # farther from a CRS's origin is no place
LON_LAT = pyproj.CRS.from_epsg(4326)
CRS_HINT = (
    'write "crs": {"type": "name", "properties": {"name": "EPSG:28992"}}, '
    "or leave 'crs' out for lon/lat (RFC 7946)"
)
COLLECTION_HINT = 'write {"type": "FeatureCollection", "features": [...]}'


class Places:
    """Line and column of the file's top-level members and of each feature. The text is
    scanned only when a place is first asked for: a file without problems costs nothing."""

    def __init__(self, text: str, lone: bool = False):
        self.text = text
        self.lone = lone  # the file is one Feature, not a collection

    @cached_property
    def _scan(self) -> tuple[int, dict[str, int], list[int]]:
        return _scan(self.text)

    @cached_property
    def _features(self) -> list[tuple[int, int]]:
        start, _, features = self._scan
        return _line_cols(self.text, [start] if self.lone else features)

    def start(self) -> tuple[int, int]:
        return _line_cols(self.text, [self._scan[0]])[0]

    def member(self, key: str) -> tuple[int, int]:
        """Where the value of a top-level key starts (the file's start if it has none)."""
        start, members = self._scan[:2]
        return _line_cols(self.text, [members.get(key, start)])[0]

    def feature(self, index: int) -> tuple[int, int] | None:
        places = self._features
        return places[index] if 0 <= index < len(places) else None


@dataclass(frozen=True)
class GeoJSON:
    file: str
    features: Iterable[Any]  # as read, each may be anything: walked once, in the file's order
    crs: pyproj.CRS
    places: Places
    reasons: Mapping[int, str] = field(default_factory=dict)  # index -> why it has no geometry


def read_geojson(path: Path) -> GeoJSON:
    """The file's features and CRS; raises SpecError (exit 2) when it is not GeoJSON.

    A FeatureCollection in a regular file is read as a stream (:func:`_streamed`): a
    first pass checks it a chunk of the file at a time, keeping its top-level members
    and each feature's line and column, and its features are read again from the file
    one at a time when they are iterated (:class:`Features`), so neither the file's text
    nor more than one feature's objects are held at once. Anything else (a lone Feature,
    a file that is not valid JSON, a pipe...) is read and parsed whole, which also
    locates the problem."""
    file = str(path)
    streamed = _streamed(path)
    if streamed is not None:
        members, places, features = streamed
        return GeoJSON(file, features, _crs(members, file, places), places)
    text = _text(path)
    data = _parse(text, file)
    whole = Places(text, lone=isinstance(data, dict) and data.get("type") == "Feature")
    return GeoJSON(file, _features(data, file, whole), _crs(data, file, whole), whole)


def read_feature(
    feature: Any, crs: pyproj.CRS
) -> tuple[dict[str, Any], Polygon | MultiPolygon] | str:
    """(properties, polygons in the file's CRS), or why the feature is not a footprint."""
    if not isinstance(feature, dict):
        return f"not a GeoJSON Feature but {_kind(feature)}"
    properties = feature.get("properties")
    if properties is None:
        properties = {}
    if not isinstance(properties, dict):
        return f"'properties' is {_kind(properties)}, not an object"
    geometry = _geometry(feature.get("geometry"))
    if isinstance(geometry, str):
        return geometry
    return _out_of_range(geometry, crs) or (properties, geometry)


def _text(path: Path) -> str:
    try:
        raw = read_at_most(path, GEOJSON_BYTES_MAX)
    except OSError as error:
        raise SpecError.at(
            str(path),
            None,
            None,
            f"cannot read the footprints: {error.strerror}",
            "check the path in the manifest",
        ) from None
    if raw is None:
        raise too_long(path)
    return decode_utf8(raw, str(path), "save the GeoJSON as UTF-8 (RFC 7946)")


def changed_while_read(file: str) -> SpecError:
    """The error of a footprints file whose features, read again a feature at a time,
    are not those its first pass counted (GeoJSON, GeoPackage, Shapefile, FlatGeobuf)."""
    return SpecError.at(
        file,
        None,
        None,
        "the footprints file changed while it was read",
        "run again once the file is written",
    )


def too_long(path: Path) -> SpecError:
    """The error of a footprints file past the limit of a file read whole."""
    return SpecError.at(
        str(path),
        None,
        None,
        f"the footprints file is longer than {GEOJSON_BYTES_MAX:,} bytes",
        "split the district into several manifests, or cut the extract to a bounding box",
    )


class NoPlaces(Places):
    """A file without lines and columns (a GeoPackage, an OSM extract, a Shapefile): its
    features are named by their id alone."""

    def __init__(self) -> None:
        super().__init__("")

    def feature(self, index: int) -> tuple[int, int] | None:
        return None


class StreamedPlaces(Places):
    """The places a streamed FeatureCollection's first pass found (:func:`_streamed`):
    its start, its top-level members' values and each feature's start, 8 bytes a
    feature (line and column), not the file's text."""

    def __init__(self, start: tuple[int, int]) -> None:
        super().__init__("")
        self.first = start
        self.members: dict[str, tuple[int, int]] = {}
        self.lines = array("I")
        self.columns = array("I")

    def start(self) -> tuple[int, int]:
        return self.first

    def member(self, key: str) -> tuple[int, int]:
        return self.members.get(key, self.first)

    def feature(self, index: int) -> tuple[int, int] | None:
        if 0 <= index < len(self.lines):
            return self.lines[index], self.columns[index]
        return None


class Features(Sequence[Any]):
    """The features of a FeatureCollection checked by :func:`_streamed`, read again from
    its file one at a time as they are iterated (the ``features`` list that counts: the
    last, as in :func:`json.loads`). A file changed since the first pass is a SpecError."""

    def __init__(self, path: Path, count: int, occurrence: int, status: os.stat_result):
        self.path = path
        self.length = count
        self.occurrence = occurrence  # which 'features' member (0: the first) holds them
        self.status = status  # the file's when it was checked

    def __len__(self) -> int:
        return self.length

    def __iter__(self) -> Iterator[Any]:
        found = 0
        try:
            with self.path.open("rb") as handle:
                status = os.fstat(handle.fileno())
                if (status.st_size, status.st_mtime_ns) != (
                    self.status.st_size,
                    self.status.st_mtime_ns,
                ):
                    raise _NotStreamed
                for kind, value, _ in _walk(_Stream(handle, self.status.st_size)):
                    if kind == "feature" and value[0] == self.occurrence:
                        found += 1
                        yield value[1]
        except (OSError, _NotStreamed, _TooLong, json.JSONDecodeError, ValueError):
            found = -1  # UnicodeDecodeError is a ValueError
        if found != self.length:
            raise changed_while_read(str(self.path))

    @overload
    def __getitem__(self, index: int) -> Any: ...
    @overload
    def __getitem__(self, index: slice) -> list[Any]: ...
    def __getitem__(self, index: int | slice) -> Any:
        """A feature by its place, read again up to it (the features are meant to be
        iterated: this is for a few)."""
        if isinstance(index, slice):
            wanted = range(*index.indices(len(self)))
            return [f for k, f in enumerate(self) if k in wanted]
        if index < 0:
            index += len(self)
        if not 0 <= index < len(self):
            raise IndexError(index)
        return next(itertools.islice(self, index, None))


class _NotStreamed(Exception):
    """A file :func:`_streamed` leaves to be read whole (not a FeatureCollection, not
    valid JSON...): the whole read says what is wrong, and where."""


class _TooLong(Exception):
    """More bytes than the limit of a footprints file."""


class _Stream:
    """A JSON text read from a binary file a chunk at a time: whitespace skipped, values
    decoded by the json module's own decoder from a window of the text, which holds what
    is not read yet of the last chunk and grows (doubling) while a value is longer; and
    the line and column of any place passed."""

    def __init__(self, handle: BinaryIO, limit: int):
        self.handle = handle
        self.limit = limit  # bytes: more is _TooLong
        self.size = 0  # bytes read
        self.text = codecs.getincrementaldecoder("utf-8-sig")()
        self.decoder = json.JSONDecoder()
        self.window = ""
        self.at = 0  # the place in the window
        self.ended = False
        self.origin = 0  # the place in the whole text of the window's first character
        self.counted = 0  # lines are counted up to here in the window
        self.line = 1
        self.line_start = 0  # in the whole text

    def _more(self) -> None:
        self.place(self.at)  # lines counted up to the part let go
        self.window = self.window[self.at :]
        self.origin += self.at
        self.counted -= self.at
        self.at = 0
        data = self.handle.read(min(max(CHUNK, len(self.window)), self.limit + 1 - self.size))
        self.size += len(data)
        if self.size > self.limit:
            raise _TooLong
        self.ended = not data
        self.window += self.text.decode(data, final=self.ended)

    def next(self) -> str:
        """The next character but whitespace ('' at the end), the place at it."""
        while True:
            self.at = _skip(self.window, self.at)
            if self.at < len(self.window) or self.ended:
                return self.window[self.at : self.at + 1]
            self._more()

    def value(self) -> Any:
        """The JSON value at the place (after :meth:`next`), the place past it."""
        while True:
            try:
                found, end = self.decoder.raw_decode(self.window, self.at)
            except json.JSONDecodeError:
                if self.ended:
                    raise
                self._more()  # perhaps cut by the window's end
                continue
            if end < len(self.window) or self.ended:  # a number may go on past the end
                self.at = end
                return found
            self._more()

    def place(self, at: int | None = None) -> tuple[int, int]:
        """The 1-based line and column of a place in the window at or past the last asked."""
        at = self.at if at is None else at
        newlines = self.window.count("\n", self.counted, at)
        if newlines:
            self.line += newlines
            self.line_start = self.origin + self.window.rfind("\n", self.counted, at) + 1
        self.counted = at
        return self.line, self.origin + at - self.line_start + 1


Walked = tuple[str, Any, tuple[int, int]]


def _walk(stream: _Stream) -> Iterator[Walked]:
    """A FeatureCollection's parts as they are read, each with its place: ("start", None)
    first, then ("member", (key, value)) for each top-level member but a ``features``
    list, ("features", occurrence) where such a list starts (0 for the first) and
    ("feature", (occurrence, feature)) for each of its elements. _NotStreamed when the
    file is not one object, or json's JSONDecodeError where it is not JSON."""
    if stream.next() != "{":
        raise _NotStreamed
    yield "start", None, stream.place()
    stream.at += 1
    occurrence = 0
    while stream.next() == '"':
        key = stream.value()
        if stream.next() != ":":
            raise _NotStreamed
        stream.at += 1
        if key == "features" and stream.next() == "[":
            yield "features", occurrence, stream.place()
            stream.at += 1
            while stream.next() != "]":
                place = stream.place()
                yield "feature", (occurrence, stream.value()), place
                if stream.next() == ",":
                    stream.at += 1
                    if stream.next() == "]":  # a trailing comma is not JSON
                        raise _NotStreamed
                elif stream.next() != "]":
                    raise _NotStreamed
            stream.at += 1
            occurrence += 1
        else:
            stream.next()
            place = stream.place()
            yield "member", (key, stream.value()), place
        if stream.next() == ",":
            stream.at += 1
        elif stream.next() != "}":
            raise _NotStreamed
    if stream.next() != "}":
        raise _NotStreamed
    stream.at += 1
    if stream.next() != "":
        raise _NotStreamed


def _streamed(path: Path) -> tuple[dict[str, Any], StreamedPlaces, Features] | None:
    """A FeatureCollection checked a chunk of its file at a time (:func:`_walk`): its
    members but its features, their places, and its features to be read again as they
    are iterated; None for anything else or any problem (the caller then reads and
    parses the file whole, which says what and where the problem is)."""
    places: StreamedPlaces | None = None
    found: tuple[int, StreamedPlaces] | None = None  # the 'features' list that counts
    members: dict[str, Any] = {}
    try:
        with path.open("rb") as handle:
            status = os.fstat(handle.fileno())
            if not stat.S_ISREG(status.st_mode):
                return None  # a pipe is read once
            for kind, value, place in _walk(_Stream(handle, GEOJSON_BYTES_MAX)):
                if kind == "start":
                    places = StreamedPlaces(place)
                    continue
                assert places is not None
                if kind == "member":
                    members[value[0]] = value[1]
                    places.members[value[0]] = place
                    if value[0] == "features":
                        found = None  # a later 'features' that is not a list wins, as in json
                elif kind == "features":
                    members.pop("features", None)
                    places.members["features"] = place
                    found = (value, StreamedPlaces(place))
                else:
                    assert found is not None
                    found[1].lines.append(place[0])
                    found[1].columns.append(place[1])
    except (OSError, _TooLong, _NotStreamed, json.JSONDecodeError, RecursionError, ValueError):
        return None  # ValueError: not UTF-8, an integer of more than 4,300 digits...
    if found is None or places is None or members.get("type") == "Feature":
        return None
    occurrence, features = found
    places.lines, places.columns = features.lines, features.columns
    return members, places, Features(path, len(places.lines), occurrence, status)


def _parse(text: str, file: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise SpecError.at(
            file,
            error.lineno,
            error.colno,
            f"invalid GeoJSON: {error.msg}",
            "check the file's JSON syntax",
        ) from None
    except RecursionError:
        raise SpecError.at(
            file, None, None, "invalid GeoJSON: nested too deeply", "check the file's brackets"
        ) from None
    except ValueError as error:  # e.g. an integer of more than 4300 digits
        raise SpecError.at(
            file, None, None, f"invalid GeoJSON: {error}", "check the file's numbers"
        ) from None


def _features(data: Any, file: str, places: Places) -> list[Any]:
    if places.lone:
        return [data]
    features = data.get("features") if isinstance(data, dict) else None
    if isinstance(features, list):
        return features
    if isinstance(data, dict) and "features" in data:
        line, col = places.member("features")
        message = f"'features' is {_kind(data['features'])}, not a list"
        raise SpecError.at(file, line, col, message, COLLECTION_HINT)
    line, col = places.start()
    if isinstance(data, dict) and data.get("type") in GEOMETRY_TYPES:
        raise SpecError.at(
            file,
            line,
            col,
            f"a bare {data['type']} geometry, not a FeatureCollection",
            'wrap it: {"type": "Feature", "properties": {}, "geometry": ...}',
        )
    raise SpecError.at(
        file, line, col, f"not a GeoJSON FeatureCollection but {_kind(data)}", COLLECTION_HINT
    )


def _crs(data: Any, file: str, places: Places) -> pyproj.CRS:
    """The legacy ``crs`` member's CRS; lon/lat (RFC 7946) without one."""
    member = data.get("crs") if isinstance(data, dict) else None
    if member is None:
        return LON_LAT
    line, col = places.member("crs")
    name = _crs_name(member)
    if name is None:
        raise SpecError.at(file, line, col, f"'crs' is {_kind(member)} without a name", CRS_HINT)
    try:
        crs = pyproj.CRS.from_user_input(name)
    except pyproj.exceptions.CRSError:
        raise SpecError.at(file, line, col, f"unknown CRS {_show(name)}", CRS_HINT) from None
    if not (crs.is_geographic or crs.is_projected):
        message = f"CRS {_show(name)} is neither lon/lat nor a map projection"
        raise SpecError.at(file, line, col, message, CRS_HINT)
    return crs


def _crs_name(member: Any) -> str | None:
    """The name in {"type": "name", "properties": {"name": ...}} (or an EPSG "code")."""
    properties = member.get("properties") if isinstance(member, dict) else None
    if not isinstance(properties, dict):
        return None
    name, code = properties.get("name"), properties.get("code")
    if isinstance(name, str) and name.strip():
        return name.strip()
    if isinstance(code, int) and not isinstance(code, bool):
        return f"EPSG:{code}"
    return None


def _geometry(value: Any) -> Polygon | MultiPolygon | str:
    if value is None:
        return "no geometry (null)"
    if not isinstance(value, dict):
        return f"'geometry' is {_kind(value)}, not an object"
    kind, coordinates = value.get("type"), value.get("coordinates")
    if kind not in ("Polygon", "MultiPolygon"):
        if kind in GEOMETRY_TYPES:
            return f"a {kind}, not a polygon"
        return f"unknown geometry type {_show(kind)}"
    polygons = [coordinates] if kind == "Polygon" else coordinates
    if not isinstance(polygons, list) or not polygons:
        return f"the {kind} has no coordinates"
    made = []
    for number, polygon in enumerate(polygons):
        rings = _rings(polygon)
        if isinstance(rings, str):
            return rings if kind == "Polygon" else f"polygon {number}: {rings}"
        try:
            made.append(Polygon(rings[0], rings[1:]))
        except (ValueError, shapely.errors.GEOSException) as error:
            return f"not a polygon: {error}"
    return made[0] if kind == "Polygon" else MultiPolygon(made)


def _rings(polygon: Any) -> list[list[tuple[float, float]]] | str:
    if not isinstance(polygon, list) or not polygon:
        return "coordinates are not a list of rings"
    rings = []
    for number, ring in enumerate(polygon):
        if not isinstance(ring, list):
            return f"ring {number} is {_kind(ring)}, not a list of positions"
        points = []
        for position in ring:
            x, y = _xy(position)
            if x is None or y is None:
                return (
                    f"ring {number}: {_show(position)} is not a position [x, y] of finite numbers"
                )
            points.append((x, y))
        if len(set(points)) < 3:
            return f"ring {number} has fewer than 3 distinct points"
        rings.append(points)
    return rings


def _xy(position: Any) -> tuple[float | None, float | None]:
    if not isinstance(position, list) or len(position) < 2:
        return None, None
    return _finite(position[0]), _finite(position[1])


def _finite(value: Any) -> float | None:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        number = float(value)
    except OverflowError:  # an integer beyond any float
        return None
    return number if math.isfinite(number) else None


def _out_of_range(geometry: Polygon | MultiPolygon, crs: pyproj.CRS) -> str | None:
    minx, miny, maxx, maxy = geometry.bounds
    if crs.is_geographic:
        if max(abs(minx), abs(maxx)) <= 180 and max(abs(miny), abs(maxy)) <= 90:
            return None
        return "lon/lat beyond ±180/±90 (projected coordinates without a 'crs' member?)"
    if max(abs(minx), abs(miny), abs(maxx), abs(maxy)) <= MAX_PROJECTED:
        return None
    return f"coordinates beyond ±{MAX_PROJECTED:.0e} of the CRS's origin"


def _kind(value: Any) -> str:
    """What a JSON value is, for a message: 'a list', 'a string', 'null', ..."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    kinds = {dict: "an object", list: "a list", str: "a string", int: "a number", float: "a number"}
    return kinds.get(type(value), "a value")


def _show(value: Any, width: int = 60) -> str:
    text = printable(json.dumps(value, ensure_ascii=False, default=str))
    return text if len(text) <= width else text[: width - 3] + "..."


def printable(text: str) -> str:
    """Text any terminal and file can take: lone surrogates (JSON allows "\\ud800") and
    control characters written as escapes."""
    text = text.encode("utf-8", "backslashreplace").decode("utf-8")
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


_SPACE = re.compile(r"[ \t\n\r]*")


def _skip(text: str, at: int) -> int:
    match = _SPACE.match(text, at)
    return match.end() if match else at


def _scan(text: str) -> tuple[int, dict[str, int], list[int]]:
    """Offsets of the top-level value, of each top-level member's value, and of each
    element of ``features``: the file is walked with the json module's own decoder, value by
    value (C speed). The text is valid JSON (it was parsed before)."""
    decoder = json.JSONDecoder()
    start = at = _skip(text, 0)
    members: dict[str, int] = {}
    features: list[int] = []
    if not text.startswith("{", at):
        return start, members, features
    at = _skip(text, at + 1)
    while text.startswith('"', at):
        key, at = decoder.raw_decode(text, at)
        at = _skip(text, _skip(text, at) + 1)  # past the ':'
        members[key] = at
        if key == "features" and text.startswith("[", at):
            features, at = _elements(text, at, decoder)
        else:
            at = decoder.raw_decode(text, at)[1]
        at = _skip(text, at)
        at = _skip(text, at + 1) if text.startswith(",", at) else at
    return start, members, features


def _elements(text: str, at: int, decoder: json.JSONDecoder) -> tuple[list[int], int]:
    """Offsets of the elements of the array at ``at``, and the offset past it; a
    JSONDecodeError (at the offending place) when it is not a valid JSON array."""
    offsets = []
    at = _skip(text, at + 1)
    while not text.startswith("]", at):
        offsets.append(at)
        at = _skip(text, decoder.raw_decode(text, at)[1])
        if text.startswith(",", at):
            at = _skip(text, at + 1)
            if text.startswith("]", at):  # a trailing comma is not JSON
                raise json.JSONDecodeError("trailing comma", text, at)
        elif not text.startswith("]", at):
            raise json.JSONDecodeError("expected ',' or ']'", text, at)
    return offsets, at + 1


def _line_cols(text: str, offsets: list[int]) -> list[tuple[int, int]]:
    """1-based (line, column) of ascending offsets, in one pass over the text."""
    places = []
    line, line_start, previous = 1, 0, 0
    for offset in offsets:
        newlines = text.count("\n", previous, offset)
        if newlines:
            line += newlines
            line_start = text.rfind("\n", previous, offset) + 1
        places.append((line, offset - line_start + 1))
        previous = offset
    return places
