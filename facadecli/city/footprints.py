"""Building footprints from GeoJSON, in local metres (SPEC 5).

Lon/lat (RFC 7946, OSM) is projected with pyproj into the UTM zone of the middle of the
data (georef.py: a named CRS, so the outputs can go back on a map); a projected CRS named
in the file is used as it is (scaled to metres if its unit is not). Either way
coordinates are then shifted so the data's south-west corner is the origin, which keeps
glTF's 32-bit floats precise. Invalid rings are repaired with shapely's make_valid;
outlines of more than MAX_VERTICES vertices are simplified. What cannot be used is
reported per feature (id, index, line), never raised; what makes the run ambiguous
(two features with one id) or empty (no usable feature) is a SpecError before any work.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import re
import statistics
from array import array
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
import shapely
import shapely.affinity
from shapely.geometry import Polygon

from facadecli.city.geojson import GeoJSON, printable, read_feature, read_geojson
from facadecli.city.geopackage import read_geopackage
from facadecli.city.georef import utm_epsg
from facadecli.city.landcover import (
    LAND_COVER,
    Area,
    clipped,
    cover_kind,
    district_box,
    ignored_tag,
    is_cover,
    oriented_parts,
)
from facadecli.city.ogr import is_ogr, read_ogr
from facadecli.city.osm import is_osm, read_osm
from facadecli.city.packed import Spooled
from facadecli.errors import Problem, SpecError
from facadecli.limits import (
    BUILDING_HEIGHT_MAX,
    BUILDING_LEVELS_MAX,
    FOOTPRINT_REACH_MAX,
    FOOTPRINT_VERTICES_MAX,
)

MIN_AREA = 1.0  # m²: smaller parts are slivers, not buildings
MAX_VERTICES = FOOTPRINT_VERTICES_MAX  # more are simplified (hip roofs grow with the square)
SIMPLIFY_TOLERANCE = 0.05  # metres: the first tolerance tried; doubled up to MAX_TOLERANCE
MAX_TOLERANCE = 0.8  # metres
MAX_REACH = FOOTPRINT_REACH_MAX  # metres from the middle of the data: a wrong coordinate
MAX_LISTED = 20  # rejected features listed in the error when none is usable
MAX_HEIGHT = BUILDING_HEIGHT_MAX  # metres (the tallest building: 828)
MAX_LEVELS = BUILDING_LEVELS_MAX


@dataclass(frozen=True)
class Simplified:
    """An outline simplified to MAX_VERTICES: vertex counts before and after, tolerance (m)."""

    before: int
    after: int
    tolerance: float


@dataclass(frozen=True)
class Footprint:
    """One building's ground plan: polygons in local metres (outer rings counter-clockwise)."""

    id: str
    parts: tuple[Polygon, ...]
    properties: dict[str, Any] = field(default_factory=dict)
    repaired: bool = False
    simplified: Simplified | None = None
    entrances: tuple[tuple[float, float], ...] = ()  # entrance nodes or points on its outline


@dataclass(frozen=True)
class Rejected:
    """A feature that yields no building, why, and where it is in the file."""

    id: str
    reason: str
    index: int | None  # in the file's features (None: a warning of the planning)
    line: int | None
    column: int | None


@dataclass(frozen=True)
class FootprintSet:
    footprints: tuple[Footprint, ...]
    rejected: tuple[Rejected, ...]
    crs: str  # the projected CRS of the outputs: the input's, or a UTM zone for lon/lat
    origin: tuple[float, float]  # where local (0, 0) is, in that CRS (scaled to metres)
    outside: int = 0  # features left out by a bounding box
    unit: float = 1.0  # metres per unit of ``crs`` (a CRS in feet is scaled to metres)
    warnings: tuple[Rejected, ...] = ()  # footprints built without some of their tags
    ground: tuple[Area, ...] = ()  # the land cover of the district (landcover.py)
    ignored: tuple[Rejected, ...] = ()  # land-cover features of a kind not drawn
    built_up: int = 0  # land-use areas of the town itself, left to the footprint rules


def feature_id(feature: Any, index: int) -> str:
    """The feature's id, else its osm_id or id property, else ``feature-<index>``."""
    if not isinstance(feature, dict):
        return f"feature-{index}"
    properties = feature.get("properties")
    if not isinstance(properties, dict):
        properties = {}
    for value in (feature.get("id"), properties.get("osm_id"), properties.get("id")):
        if isinstance(value, (str, int, float)) and not isinstance(value, bool) and value != "":
            return printable(str(value))
    return f"feature-{index}"


Found = tuple[int, str, dict[str, Any], Any]  # index, id, properties, geometry
Cover = tuple[int, str, str, Any]  # index, id, kind, geometry (the file's CRS)
Record = tuple[int, str, dict[str, Any], Any, list[tuple[float, float]]]  # and entrances


def _document(path: Path) -> GeoJSON:
    """The features of a footprints file, by its name: an OSM extract, a Shapefile or a
    FlatGeobuf, a GeoPackage, else GeoJSON."""
    if is_osm(path):
        return read_osm(path)
    if is_ogr(path):
        return read_ogr(path)
    if path.suffix.lower() == ".gpkg":
        return read_geopackage(path)
    return read_geojson(path)


BBox = tuple[float, float, float, float]  # west, south, east, north in the file's CRS


def read_footprints(
    path: Path, bbox: BBox | None = None, names: Names | None = None
) -> FootprintSet:
    """Footprints of every usable feature; rejected features with a reason and place.
    With ``bbox``, only the features whose footprint has a point inside it (in the
    file's CRS: lon/lat for OSM extracts) are read. ``names``: the manifest's properties
    holding heights and levels, checked as the OSM tags are. The file is surveyed
    (:func:`survey`), then every footprint read at once (:meth:`Survey.read`); a city
    is planned a region at a time instead (run.py)."""
    surveyed = survey(path, bbox, names)
    read = surveyed.read(range(len(surveyed)), surveyed.doors_within(None))
    footprints = [footprint for _, footprint in read.footprints]
    made = bytearray(len(surveyed))
    for place in read.made:
        made[place] = 1
    return surveyed.found(footprints, read.rejected, made, read.near_doors, [])


@dataclass
class Read:
    """Some of a survey's footprints read (:meth:`Survey.read`): each with its place in
    the survey, in the file's order; the features of them that are not footprints; the
    places of those that are (``made``); the entrance points found on their edges."""

    footprints: list[tuple[int, Footprint]]
    rejected: list[Rejected]
    made: list[int]
    near_doors: set[int]  # the doors' feature indices


@dataclass
class Survey:
    """A footprints file's first pass (:func:`survey`): what the whole city needs (the
    CRS, the origin, the far features, two features with one id, the features that are
    not footprints) and, for each feature kept, its bounding box in local metres and its
    record spooled to a temporary file (:class:`.packed.Spooled`): its footprint is made when a
    region of the city is read (:meth:`read`), not held."""

    document: GeoJSON
    crs: pyproj.CRS
    origin: tuple[float, float]
    outside: int  # features left out by a bounding box
    indices: array[int]  # each kept feature's index in the file, ascending
    boxes: Any  # numpy (n, 4): each kept feature's bounds in local metres
    spool: Spooled[Record]  # each kept feature's record, by its place here
    rejected: list[Rejected]  # features that are no footprint, found by the survey
    warned: list[Rejected]  # tags left out, of every kept feature
    doors: list[Found]  # entrance points inside the box, as read (the file's CRS)
    door_points: Any  # numpy (m, 2): those points in local metres
    cover: Spooled[Cover] = field(default_factory=Spooled)  # land cover (landcover.py)
    ignored: list[Rejected] = field(default_factory=list)  # land cover of no kind drawn
    built_up: int = 0  # land-use areas of the town itself

    def __len__(self) -> int:
        return len(self.indices)

    def doors_within(self, box: tuple[float, float, float, float] | None) -> list[int]:
        """The doors (their numbers) whose point is in ``box`` (local metres; None: all)."""
        if box is None:
            return list(range(len(self.doors)))
        xs, ys = self.door_points[:, 0], self.door_points[:, 1]
        inside = (xs >= box[0]) & (xs <= box[2]) & (ys >= box[1]) & (ys <= box[3])
        return [int(k) for k in np.flatnonzero(inside)]

    def read(self, places: Iterable[int], doors: list[int]) -> Read:
        """The footprints of the kept features at ``places`` (ascending), with the
        entrance points of ``doors`` lying on their edges; each feature's footprint made
        as :func:`read_footprints` always made it, one form at a time."""
        project = _projection(self.document.crs, self.crs)
        minx, miny = self.origin
        words = Words()
        footprints: list[tuple[int, Footprint]] = []
        rejected: list[Rejected] = []
        for place in places:
            index, fid, properties, geometry, points = self.spool[place]
            metres = shapely.transform(geometry, project, interleaved=False)
            del geometry
            local = shapely.affinity.translate(metres, -minx, -miny)
            footprint = _footprint(fid, words.properties(properties), local)
            del metres, local, properties
            if isinstance(footprint, str):
                rejected.append(_rejected(self.document, index, fid, footprint))
                continue
            if points:
                xs, ys = project(*zip(*points, strict=True))
                at = tuple((x - minx, y - miny) for x, y in zip(xs, ys, strict=True))
                footprint = dataclasses.replace(footprint, entrances=at)
            footprints.append((place, footprint))
        made = [place for place, _ in footprints]
        with_doors, astray = _with_entrances(
            [footprint for _, footprint in footprints],
            [self.doors[k] for k in doors],
            project,
            self.origin,
        )
        footprints = list(zip(made, with_doors, strict=True))
        lost = {index for index, *_ in astray}
        near = {self.doors[k][0] for k in doors} - lost
        return Read(footprints, rejected, made, near)

    @property
    def unit(self) -> float:
        return _unit(self.crs)

    def ground(self) -> list[Area]:
        """The land cover of the district, in local metres, clipped to the buildings'
        extent and the margin round it (landcover.py), read from the spool a feature at
        a time."""
        project = _projection(self.document.crs, self.crs)
        box = district_box(self.boxes)
        minx, miny = self.origin
        areas = []
        for place in range(len(self.cover)):
            index, fid, kind, geometry = self.cover[place]
            metres = shapely.transform(geometry, project, interleaved=False)
            local = shapely.affinity.translate(metres, -minx, -miny)
            area = clipped(kind, fid, index, local, box)
            if area is not None:
                areas.append(area)
        return areas

    def found(
        self,
        footprints: list[Footprint],
        rejected: list[Rejected],
        made: bytearray,
        near_doors: set[int],
        planned: list[Rejected],
    ) -> FootprintSet:
        """The town read, its footprints ``footprints`` (those a run keeps): the features
        rejected (the survey's and those of ``rejected``, in the file's order; a
        SpecError when no feature is a footprint: ``made`` is 1 at the place of each
        that is), and the
        warnings (:meth:`warnings`, then the planning's, ``planned``)."""
        rejected = self.all_rejected(rejected)
        if rejected and not any(made):
            raise _nothing_usable(self.document, rejected)
        return FootprintSet(
            tuple(footprints),
            tuple(rejected),
            self.crs.to_string(),
            self.origin,
            self.outside,
            unit=self.unit,
            warnings=(*self.warnings(made, near_doors), *planned),
            ground=tuple(self.ground()),
            ignored=tuple(self.ignored),
            built_up=self.built_up,
        )

    def made(self, made: bytearray, index: int | None) -> bool:
        """Is the feature of ``index`` in the file a footprint (kept here, and 1 at its
        place in ``made``)?"""
        place = bisect.bisect_left(self.indices, -1 if index is None else index)
        return place < len(self.indices) and self.indices[place] == index and bool(made[place])

    def all_rejected(self, read: Iterable[Rejected]) -> list[Rejected]:
        """The survey's rejected features and ``read``'s, in the file's order."""
        rejected = [*self.rejected, *read]
        rejected.sort(key=lambda r: -1 if r.index is None else r.index)
        return rejected

    def warnings(self, made: bytearray, near_doors: set[int]) -> tuple[Rejected, ...]:
        """The warnings of reading: the tags left out of the features that are footprints
        (``made``: their places), then the entrance points on no footprint's edge (those
        not in ``near_doors``), each in the file's order."""
        found = tuple(w for w in self.warned if self.made(made, w.index))
        return found + tuple(
            _rejected(self.document, index, fid, ASTRAY.format(x=point.x, y=point.y))
            for index, fid, _, point in self.doors
            if index not in near_doors
        )


def survey(path: Path, bbox: BBox | None = None, names: Names | None = None) -> Survey:
    """The first pass over a footprints file (:class:`Survey`): each feature read once,
    checked (its tags, its geometry, its id against the others') and spooled as it was
    read (its tags, its polygons in the file's CRS); what is held a feature is its index,
    the middle of its box, and its offset in the spool. Then the features are projected
    to metres one at a time, without those far from the others, for their boxes and the
    origin (the south-west corner of the data)."""
    document = _document(path)
    rejected: list[Rejected] = []
    warned: list[Rejected] = []
    doors: list[Found] = []
    spool: Spooled[Record] = Spooled()
    cover: Spooled[Cover] = Spooled()  # land cover, kept apart from the footprints
    ignored: list[Rejected] = []
    built_up = 0
    kept = array("q")
    middles = array("d")  # each kept feature's box's middle, x then y (the file's CRS)
    readable = 0
    first: dict[str, int] = {}  # id -> the first feature with it
    duplicates: list[tuple[int, str]] = []
    for index, feature in enumerate(document.features):
        fid = feature_id(feature, index)
        if first.setdefault(fid, index) != index:
            duplicates.append((index, fid))
            continue
        point = entrance_point(feature)
        if point is not None:
            if bbox is None or _within(point, bbox):
                doors.append((index, fid, feature["properties"], point))
            continue
        reason = document.reasons.get(index)
        read = reason if reason is not None else read_feature(feature, document.crs)
        if isinstance(read, str):
            rejected.append(_rejected(document, index, fid, read))
            continue
        if feature.get(LAND_COVER) is True or is_cover(read[0]):
            kind = cover_kind(read[0])
            if kind is None:
                ignored.append(_rejected(document, index, fid, ignored_tag(read[0])))
            elif kind == "built_up":
                built_up += 1
            else:
                cover.append((index, fid, kind, read[1]))
            continue
        readable += 1
        properties, problems = checked_properties(read[0], names)
        geometry = read[1]
        if bbox is not None and not _within(geometry, bbox):
            continue
        warned.extend(_rejected(document, index, fid, problem) for problem in problems)
        bounds = geometry.bounds
        middles.extend(((bounds[0] + bounds[2]) / 2, (bounds[1] + bounds[3]) / 2))
        spool.append((index, fid, properties, geometry, _entrances(feature)))
        kept.append(index)
        del feature, read, properties, geometry
    if duplicates:
        raise _duplicated(document, duplicates, first)
    del first
    crs = _projected(document.crs, middles)
    del middles
    project = _projection(document.crs, crs)
    projected = array("d")  # each kept feature's bounds in metres
    for place in range(len(spool)):
        geometry = spool[place][3]
        projected.extend(shapely.transform(geometry, project, interleaved=False).bounds)
    bounds = np.frombuffer(projected, dtype=np.float64).reshape(-1, 4)
    middle = _middle_of(
        ((bounds[:, 0] + bounds[:, 2]) / 2).tolist(), ((bounds[:, 1] + bounds[:, 3]) / 2).tolist()
    )
    near = []
    for place, box in enumerate(bounds):
        far = _far((float(box[0]), float(box[1]), float(box[2]), float(box[3])), middle)
        if far is None:
            near.append(place)
        else:
            index, fid = spool[place][:2]
            rejected.append(_rejected(document, index, fid, far))
    spool = spool.only(near)
    indices = array("q", (kept[place] for place in near))
    boxes = bounds[near]
    minx = float(boxes[:, 0].min()) if len(boxes) else 0.0
    miny = float(boxes[:, 1].min()) if len(boxes) else 0.0
    boxes = boxes - np.array([minx, miny, minx, miny])
    door_points = np.zeros((len(doors), 2))
    for k, (*_, point) in enumerate(doors):
        x, y = project(point.x, point.y)
        door_points[k] = (x - minx, y - miny)
    return Survey(
        document,
        crs,
        (minx, miny),
        readable - len(kept),
        indices,
        boxes,
        spool,
        rejected,
        warned,
        doors,
        door_points,
        cover,
        ignored,
        built_up,
    )


def _within(geometry: Any, bbox: BBox) -> bool:
    x, y = (float(v) for v in geometry.representative_point().coords[0])
    return bbox[0] <= x <= bbox[2] and bbox[1] <= y <= bbox[3]


class Words:
    """The tags' keys and short values held once for all the footprints read, not once a
    footprint (each feature decodes its own: 292 bytes a generated terrace for its four
    keys and values, where the tags of most buildings say the same few words). At most
    WORDS_MAX words are kept; past it, the others stay as they are."""

    def __init__(self) -> None:
        self.seen: dict[str, str] = {}

    def word(self, text: str) -> str:
        found = self.seen.get(text)
        if found is not None:
            return found
        if len(self.seen) < WORDS_MAX:
            self.seen[text] = text
        return text

    def properties(self, properties: dict[str, Any]) -> dict[str, Any]:
        return {
            self.word(key): (
                self.word(value) if type(value) is str and len(value) <= WORD_LENGTH else value
            )
            for key, value in properties.items()
        }


WORDS_MAX = 1 << 16  # distinct keys and values held once (Words)
WORD_LENGTH = 40  # characters: longer values (names, notes) are seldom repeated


def _footprint(fid: str, properties: dict[str, Any], local: Any) -> Footprint | str:
    """The footprint of a feature's polygons in local metres, or why there is none."""
    repaired = False
    if not local.is_valid:
        local = shapely.make_valid(local)
        repaired = True
    parts = oriented_parts(local, MIN_AREA)
    if not parts:
        return "no part of at least 1 m² (degenerate footprint)"
    parts, simplified = _simplify(parts)
    return Footprint(fid, parts, dict(properties), repaired, simplified)


def _vertices(parts: tuple[Polygon, ...]) -> int:
    rings = [ring for part in parts for ring in (part.exterior, *part.interiors)]
    return sum(len(ring.coords) - 1 for ring in rings)


def _simplify(parts: tuple[Polygon, ...]) -> tuple[tuple[Polygon, ...], Simplified | None]:
    """Parts with at most MAX_VERTICES vertices in all: simplified (topology kept) with
    the smallest tolerance, from 5 cm doubling up to MAX_TOLERANCE, that gets there; at
    MAX_TOLERANCE whatever the count is then."""
    before = _vertices(parts)
    if before <= MAX_VERTICES:
        return parts, None
    tolerance = SIMPLIFY_TOLERANCE
    while True:
        simpler = [part.simplify(tolerance, preserve_topology=True) for part in parts]
        kept = tuple(p for s in simpler for p in oriented_parts(s, MIN_AREA))
        if kept and (_vertices(kept) <= MAX_VERTICES or tolerance * 2 > MAX_TOLERANCE):
            return kept, Simplified(before, _vertices(kept), tolerance)
        if not kept:  # simplified away: keep the outline as it is
            return parts, None
        tolerance *= 2


def _rejected(document: GeoJSON, index: int, fid: str, reason: str) -> Rejected:
    line, column = document.places.feature(index) or (None, None)
    return Rejected(fid, reason, index, line, column)


def _duplicated(
    document: GeoJSON, duplicates: list[tuple[int, str]], first: dict[str, int]
) -> SpecError:
    """Two features with one id would share a file and a report entry: the error, at each
    feature repeating an earlier one's id."""
    problems = []
    for index, fid in duplicates:
        line, col = document.places.feature(index) or (None, None)
        earlier = document.places.feature(first[fid])
        at = f" (line {earlier[0]})" if earlier else ""
        problems.append(
            Problem(
                document.file,
                line,
                col,
                f"features[{index}] has the id '{fid}' of features[{first[fid]}]{at}",
                "give every feature its own id",
            )
        )
    return SpecError(problems)


def _nothing_usable(document: GeoJSON, rejected: list[Rejected]) -> SpecError:
    problems = [
        Problem(document.file, r.line, r.column, f"feature '{r.id}' is not a footprint: {r.reason}")
        for r in rejected[:MAX_LISTED]
    ]
    more = len(rejected) - MAX_LISTED
    problems.append(
        Problem(
            document.file,
            None,
            None,
            "no feature is a usable footprint"
            + (f" ({more} more rejected features not listed)" if more > 0 else ""),
            "give building polygons (Polygon or MultiPolygon features)",
        )
    )
    return SpecError(problems)


def _projected(source: pyproj.CRS, middles: Sequence[float]) -> pyproj.CRS:
    """The CRS of the outputs: a projected ``source`` itself; for lon/lat, the UTM zone
    of the middle of the data (see georef.py; ``middles``: the features' boxes' middles,
    x then y, in ``source``)."""
    if not source.is_geographic:
        return source
    return pyproj.CRS.from_epsg(utm_epsg(*_middle_of(middles[0::2], middles[1::2])))


def _unit(crs: pyproj.CRS) -> float:
    return float(crs.axis_info[0].unit_conversion_factor) if crs.axis_info else 1.0


def _projection(source: pyproj.CRS, target: pyproj.CRS) -> Any:
    """A function (x, y) -> (x, y) in metres: lon/lat into ``target``; a projected CRS
    (``target`` is ``source``) as it is, scaled from its unit to metres."""
    if source.is_geographic:
        return pyproj.Transformer.from_crs(source, target, always_xy=True).transform
    scale = _unit(source)
    if scale == 1.0:
        return lambda x, y: (x, y)
    return lambda x, y: (x * scale, y * scale)


def _middle_of(xs: Sequence[float], ys: Sequence[float]) -> tuple[float, float]:
    """The (low) median of the features' bounding-box middles (``xs``, ``ys``): stray
    features cannot move it, and of two features it is one of them."""
    if len(xs) == 0:
        return 0.0, 0.0
    return float(statistics.median_low(xs)), float(statistics.median_low(ys))


def _far(bounds: tuple[float, float, float, float], middle: tuple[float, float]) -> str | None:
    """Why a projected geometry (its ``bounds``) is no place for a building of this
    city, if it is not."""
    reach = max(
        abs(bounds[0] - middle[0]),
        abs(bounds[2] - middle[0]),
        abs(bounds[1] - middle[1]),
        abs(bounds[3] - middle[1]),
    )
    if reach <= MAX_REACH:
        return None
    return (
        f"{reach / 1000:.0f} km from the middle of the other footprints "
        f"(at most {MAX_REACH / 1000:.0f} km): a wrong coordinate?"
    )


_NUMBER = re.compile(r"[-+]?(?:\d+(?:[.,]\d+)?|[.,]\d+)(?:[eE][-+]?\d+)?", re.ASCII)
_FEET = re.compile(
    r"\s*(\d+(?:\.\d+)?)\s*(?:'|ft|feet|foot)\s*(?:(\d+(?:\.\d+)?)\s*(?:\"|in))?\s*", re.ASCII
)
FOOT = 0.3048  # metres
INCH = 0.0254


def number(value: Any) -> float | None:
    """A finite number from a property: 12, 12.5, "12.5", "12,5 m", "1e3", "3;4" (the
    first one); None for anything else (NaN, "inf", "1e999", "tall")."""
    if isinstance(value, bool) or value is None:
        return None
    if isinstance(value, (int, float)):
        try:
            found = float(value)
        except OverflowError:  # an integer beyond any float
            return None
        return found if math.isfinite(found) else None
    match = _NUMBER.search(str(value))
    if match is None:
        return None
    found = float(match.group().replace(",", "."))
    return found if math.isfinite(found) else None


def length(value: Any) -> float | None:
    """Metres from a property: a number (metres, "12 m"), or feet and inches as OSM
    allows them ("40'", "12'6\"", "40 ft")."""
    if isinstance(value, str):
        feet = _FEET.fullmatch(value)
        if feet is not None:
            return float(feet.group(1)) * FOOT + float(feet.group(2) or 0) * INCH
    return number(value)


LENGTHS = ("height", "measuredHeight", "min_height", "roof:height")  # metres
COUNTS = ("levels", "building:levels", "building:min_level", "roof:levels")  # levels
Names = dict[str, tuple[str, float]]  # height, eaves, levels, min_height -> (property, scale)


ANGLES = ("roof:angle", "roof:direction")  # degrees (a compass point stays a word)


def _quantities(names: Names | None) -> dict[str, tuple[float, bool]]:
    """Property name -> (the manifest's scale, whether it is a length) for the heights
    and levels read as numbers: OSM's tags and the properties a manifest names."""
    quantities = {key: (1.0, True) for key in LENGTHS} | {key: (1.0, False) for key in COUNTS}
    for key, (name, scale) in (names or {}).items():
        quantities[name] = (scale, key != "levels")
    return quantities


def typed(properties: dict[str, Any], names: Names | None = None) -> dict[str, Any]:
    """The properties with the numbers they mean as JSON numbers: lengths in metres,
    their unit read (``height=40'`` is 12.192), level counts, and ``roof:angle`` and
    ``roof:direction`` in degrees, the properties a manifest names for heights as they
    are (before its scale); whole counts as integers. Any other value, and one that
    is not a number, as it is (a house number or a postcode stays text)."""
    found = dict(properties)
    kinds = {key: metres for key, (_, metres) in _quantities(names).items()}
    kinds |= {key: False for key in ANGLES}
    for key, metres in kinds.items():
        value = properties.get(key)
        if not isinstance(value, str):
            continue
        number_ = length(value) if metres else number(value)
        if number_ is None:
            continue
        found[key] = int(number_) if not metres and number_.is_integer() else number_
    return found


def checked_properties(
    properties: dict[str, Any], names: Names | None = None
) -> tuple[dict[str, Any], list[str]]:
    """The properties without the heights and levels no building has (not a finite
    number, below 0, above BUILDING_HEIGHT_MAX metres or BUILDING_LEVELS_MAX levels, the
    manifest's scale applied), and a warning for each value left out: the building is
    then built from its other tags, or the manifest's defaults."""
    quantities = _quantities(names)
    kept = dict(properties)
    warnings = []
    for name, (scale, metres) in quantities.items():
        value = properties.get(name)
        if value is None or value == "":
            continue
        found = length(value) if metres else number(value)
        most, unit = (MAX_HEIGHT, " m") if metres else (MAX_LEVELS, " levels")
        if found is None:
            problem = "is not a number"
        elif found < 0:
            problem = "is below 0"
        elif found * scale > most:
            problem = f"is more than a building's {most:g}{unit}"
        else:
            continue
        del kept[name]
        shown = printable(str(value))
        shown = shown if len(shown) <= 40 else shown[:37] + "..."
        warnings.append(f"{name} '{shown}' {problem}: ignored")
    from facadecli.city.s3db import tag_problems  # here: s3db reads footprints

    return kept, warnings + tag_problems(kept)


def building_height(properties: dict[str, Any], default: float, floor_height: float) -> float:
    """``height`` (or ``measuredHeight``), else levels x floor height, else the default."""
    for key in ("height", "measuredHeight"):
        height = length(properties.get(key))
        if height is not None and height > 0:
            return height
    for key in ("levels", "building:levels"):
        levels = number(properties.get(key))
        if levels is not None and levels > 0:
            return levels * floor_height
    return default


ENTRANCE_KEY = "entrance"  # OSM's tag of a building's door
ON_EDGE = 0.5  # metres: an entrance point this near a footprint's edge is on it
ASTRAY = f"entrance at ({{x}}, {{y}}) is on no footprint's edge (within {ON_EDGE} m): no door there"


def entrance_point(feature: Any) -> shapely.Point | None:
    """A GeoJSON (or GeoPackage, Shapefile...) feature that is a point tagged
    ``entrance`` (any value, as OSM's entrance nodes), in the file's CRS; else None."""
    if not isinstance(feature, dict):
        return None
    properties, geometry = feature.get("properties"), feature.get("geometry")
    if not isinstance(properties, dict) or ENTRANCE_KEY not in properties:
        return None
    if not isinstance(geometry, dict) or geometry.get("type") != "Point":
        return None
    where = geometry.get("coordinates")
    if not isinstance(where, list) or len(where) < 2:
        return None
    x, y = where[0], where[1]
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (x, y))
    if not numbers or not all(math.isfinite(v) for v in (x, y)):
        return None
    return shapely.Point(float(x), float(y))


def _with_entrances(
    footprints: list[Footprint],
    doors: list[Found],
    project: Any,
    origin: tuple[float, float],
) -> tuple[list[Footprint], list[Found]]:
    """The footprints with the entrance points lying on their edges (within ON_EDGE: an
    outer ring's or a courtyard's) added to their entrances, in local metres; and the
    points on no footprint's edge (as given). A point on
    a wall two footprints share goes to both (a party wall gets no façade, so no door)."""
    if not doors:
        return footprints, []
    edges = [
        shapely.MultiLineString([r for p in f.parts for r in (p.exterior, *p.interiors)])
        for f in footprints
    ]
    tree = shapely.STRtree(edges)
    added: dict[int, list[tuple[float, float]]] = {}
    astray = []
    for index, fid, properties, point in doors:
        x, y = project(point.x, point.y)
        local = shapely.Point(x - origin[0], y - origin[1])
        near = [int(k) for k in tree.query(local, predicate="dwithin", distance=ON_EDGE)]
        for k in sorted(near):
            added.setdefault(k, []).append((local.x, local.y))
        if not near:
            astray.append((index, fid, properties, point))
    found = [
        dataclasses.replace(f, entrances=tuple(dict.fromkeys((*f.entrances, *added[k]))))
        if k in added
        else f
        for k, f in enumerate(footprints)
    ]
    return found, astray


def _entrances(feature: Any) -> list[tuple[float, float]]:
    """The entrances an OSM extract's reader put on a building's feature (lon, lat of its
    ``entrance=*`` nodes, osm.py); none on any other feature."""
    found = feature.get("entrances") if isinstance(feature, dict) else None
    if not isinstance(found, list):
        return []
    return [
        (float(p[0]), float(p[1]))
        for p in found
        if isinstance(p, (list, tuple))
        and len(p) == 2
        and all(isinstance(v, (int, float)) and math.isfinite(v) for v in p)
    ]
