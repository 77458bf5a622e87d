"""Land cover: the parks, grass, woods, water, pitches and car parks a district's input
maps on its ground, read beside its buildings and written beside the city's models as
``<name>.ground.geojson`` (docs/reference/city.md, "Land cover"), which the viewer draws.

A feature is land cover when it has no ``building`` or ``building:part`` tag and one of
the keys of :data:`COVER_KEYS` (an OSM area), or a kind drawn here or a key of
:data:`NEVER_BUILDINGS` (a feature of another format: :func:`is_cover`); its kind is the
first rule of :data:`KINDS` its tags meet. Land use that is the built town itself
(``landuse=residential``, ``retail`` ..., :data:`BUILT_UP`) is left to the footprint
rules of the viewer, and counted; any other value of those keys is a kind not drawn
here: a warning (``<key> '<value>' is not a land cover drawn here: ignored``), counted in
the report's ``warnings_by_tag`` as ignored tags are. The areas are clipped to the
district (the buildings' extent and :data:`DISTRICT_MARGIN` metres round it) and written
in the order of their kind, then their feature's place in the file: the same input gives
the same bytes.
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import shapely
from shapely.geometry import MultiPolygon, Polygon
from shapely.geometry.polygon import orient

from facadecli.export.atomic import atomic_output

COVER_KEYS = ("leisure", "landuse", "natural", "waterway", "amenity")
BUILDING_KEYS = ("building", "building:part")
NEVER_BUILDINGS = ("landuse", "natural", "waterway")  # keys no building carries alone
LAND_COVER = "land_cover"  # a feature's member: an OSM area not tagged as a building
DISTRICT_MARGIN = 50.0  # metres of land cover kept round the buildings' extent
MIN_AREA = 1.0  # m²: a smaller piece left by clipping is a sliver
DIGITS = 2  # centimetres: the coordinates written

#: kind -> the (key, values) that make it, in the order the kinds are drawn (a later kind
#: covers an earlier one where two overlap: a pond in a park is water)
KINDS: dict[str, tuple[tuple[str, frozenset[str]], ...]] = {
    "wood": (("landuse", frozenset({"forest"})), ("natural", frozenset({"wood", "scrub"}))),
    "grass": (
        ("landuse", frozenset({"grass", "meadow", "village_green", "recreation_ground"})),
        ("natural", frozenset({"grassland", "heath"})),
    ),
    "park": (("leisure", frozenset({"park", "garden", "playground", "common"})),),
    "sand": (("natural", frozenset({"beach", "sand"})),),
    "pitch": (("leisure", frozenset({"pitch", "track"})),),
    "parking": (("amenity", frozenset({"parking"})),),
    "water": (
        ("natural", frozenset({"water"})),
        ("waterway", frozenset({"riverbank", "dock"})),
        ("landuse", frozenset({"reservoir", "basin"})),
        ("leisure", frozenset({"swimming_area"})),
    ),
}
#: land use that is the town itself: its streets and yards the footprints give
BUILT_UP = frozenset(
    {"residential", "commercial", "retail", "industrial", "construction", "garages"}
)
UNKNOWN = "is not a land cover drawn here: ignored"


def is_cover(properties: Mapping[str, Any]) -> bool:
    """Whether a feature of a GeoJSON, GeoPackage, Shapefile or FlatGeobuf file is land
    cover rather than a footprint: no building key, and a kind drawn here, or a
    ``landuse``, ``natural`` or ``waterway`` key (no building is tagged with those alone).
    A polygon tagged otherwise stays a footprint, as before: exports of buildings often
    carry no building tag (``amenity=school``, ``leisure=sports_centre``, none at all).
    An OSM extract's areas are told apart by their building key alone (osm.py:
    :data:`LAND_COVER` marks the others)."""
    if any(key in properties for key in BUILDING_KEYS):
        return False
    if any(isinstance(properties.get(key), str) for key in NEVER_BUILDINGS):
        return True
    return cover_kind(properties) not in (None, "built_up")


def cover_kind(properties: Mapping[str, Any]) -> str | None:
    """The kind of a land-cover feature (:data:`KINDS`), ``"built_up"`` for the town's
    own land use, None for a kind not drawn here."""
    for kind, rules in reversed(KINDS.items()):  # water before the park round it
        for key, values in rules:
            if properties.get(key) in values:
                return kind
    if properties.get("landuse") in BUILT_UP:
        return "built_up"
    return None


def ignored_tag(properties: Mapping[str, Any]) -> str:
    """The warning of a land-cover feature of no kind drawn here: its first cover key."""
    key = next(key for key in COVER_KEYS if isinstance(properties.get(key), str))
    return f"{key} '{str(properties[key])[:40]}' {UNKNOWN}"


@dataclass(frozen=True)
class Area:
    """A land-cover area of the district: its kind, its feature's id and place in the
    file, its polygons in local metres (outer rings counter-clockwise)."""

    kind: str
    id: str
    index: int
    parts: tuple[Polygon, ...]


def district_box(boxes: Any, margin: float = DISTRICT_MARGIN) -> tuple[float, float, float, float]:
    """The district's box in local metres: the buildings' boxes (numpy (n, 4)) grown by
    ``margin``."""
    if len(boxes) == 0:
        return (0.0, 0.0, 0.0, 0.0)
    return (
        float(boxes[:, 0].min()) - margin,
        float(boxes[:, 1].min()) - margin,
        float(boxes[:, 2].max()) + margin,
        float(boxes[:, 3].max()) + margin,
    )


def clipped(kind: str, fid: str, index: int, local: Any, box: tuple[float, ...]) -> Area | None:
    """The area of a feature's polygons (local metres) within ``box``, its slivers left
    out; None when nothing of it is left."""
    if not local.is_valid:
        local = shapely.make_valid(local)
    inside = shapely.clip_by_rect(local, *box)
    parts = oriented_parts(inside)
    return Area(kind, fid, index, parts) if parts else None


def oriented_parts(geometry: Any, least: float = MIN_AREA) -> tuple[Polygon, ...]:
    """The polygons of a geometry (a polygon, a multipolygon, or the collection
    ``make_valid`` gives) of at least ``least`` m², outer rings counter-clockwise: the
    parts of a footprint (footprints.py) and of a land-cover area alike."""
    return tuple(orient(p, sign=1.0) for p in _polygons(geometry) if p.area >= least)


def _polygons(geometry: Any) -> list[Polygon]:
    if isinstance(geometry, Polygon):
        return [geometry]
    if isinstance(geometry, MultiPolygon) or hasattr(geometry, "geoms"):
        return [p for g in geometry.geoms for p in _polygons(g)]
    return []


def kind_counts(areas: Iterable[Area], built_up: int) -> dict[str, int]:
    """The report's ``summary.ground``: areas written by kind, in :data:`KINDS`' order,
    then the built-up land use left to the footprint rules."""
    counted = Counter(area.kind for area in areas)
    found = {kind: counted[kind] for kind in KINDS if counted[kind]}
    return {**found, "built_up": built_up} if built_up else found


def _ring(ring: Any, shift: tuple[float, float], unit: float) -> list[list[float]]:
    return [
        [round((x + shift[0]) / unit, DIGITS), round((y + shift[1]) / unit, DIGITS)]
        for x, y in ring.coords
    ]


def features(
    areas: Iterable[Area], origin: tuple[float, float], unit: float
) -> Iterator[dict[str, Any]]:
    """Each area as a GeoJSON feature in the city's CRS (its units: local metres plus the
    origin, divided by ``unit``), a MultiPolygon, its kind and id as properties."""
    for area in areas:
        polygons = [
            [
                _ring(part.exterior, origin, unit),
                *(_ring(hole, origin, unit) for hole in part.interiors),
            ]
            for part in area.parts
        ]
        yield {
            "type": "Feature",
            "id": area.id,
            "properties": {"kind": area.kind},
            "geometry": {"type": "MultiPolygon", "coordinates": polygons},
        }


def ordered(areas: Iterable[Area]) -> list[Area]:
    """In the order the viewer draws them: by kind (:data:`KINDS`), then file place."""
    rank = {kind: k for k, kind in enumerate(KINDS)}
    return sorted(areas, key=lambda area: (rank[area.kind], area.index))


def write_ground(
    path: Path, areas: Iterable[Area], crs: str, origin: tuple[float, float], unit: float
) -> None:
    """``<name>.ground.geojson``, atomically, a feature a line: a GeoJSON
    FeatureCollection in the city's projected CRS (named in ``crs``, as GDAL and QGIS
    read it), with ``origin`` (local (0, 0), metres) and ``metres_per_unit`` as the
    georeference of the models gives them."""
    head = {
        "type": "FeatureCollection",
        "name": path.name.removesuffix(".ground.geojson"),
        "crs": {"type": "name", "properties": {"name": _urn(crs)}},
        "origin": [origin[0], origin[1]],
        "metres_per_unit": unit,
    }
    text = json.dumps({**head, "features": []}, separators=(",", ":"))
    before = text[: -len("[]}")]
    with atomic_output(path) as out:
        out.write(before.encode("utf-8") + b"[\n")
        for k, feature in enumerate(features(areas, origin, unit)):
            line = json.dumps(feature, separators=(",", ":"))
            out.write((",\n" if k else "").encode("utf-8") + line.encode("utf-8"))
        out.write(b"\n]}\n")


def _urn(crs: str) -> str:
    """``EPSG:32632`` as GeoJSON's (2008) named CRS: ``urn:ogc:def:crs:EPSG::32632``."""
    authority, _, code = crs.partition(":")
    return f"urn:ogc:def:crs:{authority}::{code}" if code.isdigit() else crs
