"""Reading footprints from an OpenStreetMap extract (``.osm.pbf``, ``.osm``, ``.osm.bz2``,
``.osm.gz``) with pyosmium, as one downloads them (Geofabrik, BBBike, the OSM website).

Every area tagged ``building`` or ``building:part`` is a footprint: closed ways and
multipolygon relations, assembled by libosmium (holes and all). Its id is ``way/<id>`` or
``relation/<id>``, its properties its tags, so heights, levels, roof shapes, colours and
building parts work as in a GeoJSON export (the city's S3DB rules). Coordinates are
lon/lat (EPSG:4326). The file is read in one streaming pass per object kind; only the
buildings are kept.

An XML extract is checked first (:mod:`facadecli.city.osmxml`: its inflated size, ids,
coordinates and tag text, each problem at its line); a PBF's blocks are counted
(:mod:`facadecli.city.osmpbf`). Whatever libosmium still cannot read is a SpecError
(exit 2). A building libosmium cannot draw (a way naming a node the file does not hold,
a multipolygon whose member way is missing, a ring that does not close) is a feature
without a geometry, with the reason, which the caller reports and counts as rejected.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyproj

from facadecli.city.geojson import GeoJSON, NoPlaces
from facadecli.city.osmxml import KEYS, check_xml
from facadecli.errors import SpecError
from facadecli.limits import OSM_ID_MAX, OSM_TEXT_CHARS_MAX

SUFFIXES = (".osm.pbf", ".pbf", ".osm", ".osm.bz2", ".osm.gz")
HINT = "give an OpenStreetMap extract (.osm.pbf or .osm), a GeoPackage or a GeoJSON file"
SORT = "sort it: osmium sort FILE -o SORTED.osm.pbf"
LISTED = 5  # missing nodes or members named in a reason
ENTRANCE = "entrance"  # a node tagged so on a building's way, or on a multipolygon
# building's outer way: a door there (entrances.py)
OUTER = ("outer", "")  # roles of a multipolygon's outer ways (none: old multipolygons)
LOOKED_UP = 2**48  # ids looked up in a second pass: below (libosmium's id set grows with them)


def is_osm(path: Path) -> bool:
    return path.name.lower().endswith(SUFFIXES)


class OsmPlaces(NoPlaces):
    """The line and column where each feature's element starts (XML), when known."""

    def __init__(self, places: dict[int, tuple[int, int]]):
        super().__init__()
        self.places = places

    def feature(self, index: int) -> tuple[int, int] | None:
        return self.places.get(index)


@dataclass
class _Drawn:
    """What the pass over the file found: the areas libosmium drew, and the building
    ways and relations, to tell which it could not draw and why."""

    features: list[dict[str, Any]]
    reasons: dict[int, str]  # feature index -> why it has no geometry
    ways: dict[int, tuple[bool, list[int]]]  # id -> closed, missing nodes
    relations: dict[int, tuple[str, list[tuple[str, int, str]]]]  # id -> type, members
    entrances: dict[int, tuple[float, float]] = field(default_factory=dict)  # node -> lon, lat
    doors: dict[int, list[tuple[float, float]]] = field(default_factory=dict)  # way -> theirs


def read_osm(path: Path) -> GeoJSON:
    """The building areas of an extract (see the module)."""
    file = str(path)
    places = {}
    if not path.name.lower().endswith(".pbf"):
        places = check_xml(path)
    else:
        from facadecli.city.osmpbf import check_pbf

        check_pbf(path)
    try:
        drawn = _read(file)
        _undrawn(file, drawn)
    except SpecError:
        raise
    except Exception as error:  # libosmium's own refusals: RuntimeError, ValueError, ...
        message = f"libosmium cannot read it: {error}" if str(error) else type(error).__name__
        hint = HINT
        if "out of order" in message or "twice" in message:
            hint = SORT
        elif "uncompress" in message:
            hint = "download the extract again"
        raise SpecError.at(file, None, None, message, hint) from None
    at = {}
    for index, feature in enumerate(drawn.features):
        kind, oid = feature["id"].split("/")
        if (kind, int(oid)) in places:
            at[index] = places[(kind, int(oid))]
    return GeoJSON(file, drawn.features, pyproj.CRS.from_epsg(4326), OsmPlaces(at), drawn.reasons)


def _read(file: str) -> _Drawn:
    import osmium  # imported here: only OSM extracts need it

    factory = osmium.geom.GeoJSONFactory()
    drawn = _Drawn([], {}, {}, {})
    processor = (
        osmium.FileProcessor(file)
        .with_areas(osmium.filter.KeyFilter(*KEYS))
        .with_filter(osmium.filter.KeyFilter(*KEYS, ENTRANCE))
    )
    for item in processor:
        if isinstance(item, osmium.osm.Node):
            if ENTRANCE in item.tags and item.location.valid():
                drawn.entrances[item.id] = (item.location.lon, item.location.lat)
            continue
        if not any(key in item.tags for key in KEYS):  # a way or relation tagged entrance
            continue
        if isinstance(item, osmium.osm.Area):
            kind = "way" if item.from_way() else "relation"
            reason = ""
            try:
                geometry = json.loads(factory.create_multipolygon(item))
            except RuntimeError as error:
                geometry, reason = None, f"libosmium cannot draw its outline: {error}"
            _add(drawn, kind, item.orig_id(), _tags(file, kind, item.orig_id(), item.tags), reason)
            drawn.features[-1]["geometry"] = geometry
        elif isinstance(item, osmium.osm.Way):
            _tags(file, "way", _id(file, "way", item.id), item.tags)
            missing = [node.ref for node in item.nodes if not node.location.valid()]
            drawn.ways[item.id] = (item.is_closed(), missing)
            doors = [drawn.entrances[n.ref] for n in item.nodes if n.ref in drawn.entrances]
            if doors:
                drawn.doors[item.id] = list(dict.fromkeys(doors))  # a ring's last node: its first
        elif isinstance(item, osmium.osm.Relation):
            tags = _tags(file, "relation", _id(file, "relation", item.id), item.tags)
            members = [(m.type, m.ref, m.role) for m in item.members]
            drawn.relations[item.id] = (tags.get("type", ""), members)
    _relation_doors(file, drawn)
    for feature in drawn.features:
        kind, oid = feature["id"].split("/")
        if kind == "way" and int(oid) in drawn.doors:
            feature["entrances"] = drawn.doors[int(oid)]
    return drawn


def _relation_doors(file: str, drawn: _Drawn) -> None:
    """The entrances of multipolygon buildings: the entrance nodes of their outer member
    ways (role ``outer``, or none as in old multipolygons), which the pass over the file
    did not see when untagged; read in a second pass over those ways only."""
    drawn_relations = [
        int(f["id"].split("/")[1]) for f in drawn.features if f["id"].startswith("relation/")
    ]
    outers = {
        oid: [ref for kind, ref, role in drawn.relations[oid][1] if kind == "w" and role in OUTER]
        for oid in drawn_relations
        if oid in drawn.relations
    }
    if not drawn.entrances or not any(outers.values()):
        return
    nodes = _way_nodes(file, {ref for refs in outers.values() for ref in refs})
    for feature in drawn.features:
        kind, oid = feature["id"].split("/")
        if kind != "relation" or int(oid) not in outers:
            continue
        doors = [
            drawn.entrances[node]
            for ref in outers[int(oid)]
            for node in nodes.get(ref, ())
            if node in drawn.entrances
        ]
        if doors:
            feature["entrances"] = list(dict.fromkeys(doors))


def _way_nodes(file: str, ids: set[int]) -> dict[int, list[int]]:
    """The nodes of the ways with these ids the file holds."""
    import osmium

    ids = {i for i in ids if 0 <= i < LOOKED_UP}
    if not ids:
        return {}
    processor = osmium.FileProcessor(file, osmium.osm.WAY).with_filter(osmium.filter.IdFilter(ids))
    return {
        item.id: [node.ref for node in item.nodes]
        for item in processor
        if isinstance(item, osmium.osm.Way)
    }


def _add(drawn: _Drawn, kind: str, oid: int, tags: dict[str, str], reason: str = "") -> None:
    """A feature; one without a geometry has the reason (and no need of its tags)."""
    drawn.features.append(
        {"type": "Feature", "id": f"{kind}/{oid}", "properties": tags, "geometry": None}
    )
    if reason:
        drawn.reasons[len(drawn.features) - 1] = reason


def _id(file: str, kind: str, oid: int) -> int:
    if abs(oid) > OSM_ID_MAX:  # libosmium's area id (twice the id) would overflow
        raise SpecError.at(
            file, None, None, f"{kind} {oid}: an id beyond {OSM_ID_MAX:,}", "renumber it"
        )
    return oid


def _tags(file: str, kind: str, oid: int, tags: Iterable[Any]) -> dict[str, str]:
    found = {}
    for tag in tags:
        for text in (tag.k, tag.v):
            if len(text) > OSM_TEXT_CHARS_MAX:
                raise SpecError.at(
                    file,
                    None,
                    None,
                    f"{kind} {oid}: a tag of {len(text):,} characters (limit: "
                    f"{OSM_TEXT_CHARS_MAX}, as in OSM itself)",
                    "shorten the tag",
                )
        found[tag.k] = tag.v
    return found


def _undrawn(file: str, drawn: _Drawn) -> None:
    """The building ways and multipolygons libosmium drew no area of, as features without
    a geometry, each with the reason (a missing node or member way, an open ring)."""
    done = {f["id"] for f in drawn.features}
    in_relations = {
        ref for _, members in drawn.relations.values() for kind, ref, _ in members if kind == "w"
    }
    undrawn = [
        (oid, way)
        for oid, way in sorted(drawn.ways.items())
        if f"way/{oid}" not in done and oid not in in_relations
    ]
    late = _present_nodes(file, {node for _, (_, missing) in undrawn for node in missing})
    for oid, (closed, missing) in undrawn:
        if missing:
            reason = _missing(missing, late)
        elif not closed:
            reason = "the way is not closed (its first and last nodes differ)"
        else:
            reason = "libosmium could not make a ring of it (too few nodes?)"
        _add(drawn, "way", oid, {}, reason)
    broken = {
        oid: members
        for oid, (kind, members) in drawn.relations.items()
        if f"relation/{oid}" not in done and kind in ("multipolygon", "boundary")
    }
    if not broken:
        return
    refs = {ref for members in broken.values() for kind, ref, _ in members if kind == "w"}
    found = _member_ways(file, refs)
    for oid, members in sorted(broken.items()):
        ways = [(ref, role) for t, ref, role in members if t == "w"]
        absent = [f"{role or 'member'} way {ref}" for ref, role in ways if ref not in found]
        nodes = [node for ref, _ in ways for node in found.get(ref, [])]
        if absent:
            more = f" and {len(absent) - LISTED} more" if len(absent) > LISTED else ""
            verb = "are" if len(absent) > 1 else "is"
            reason = f"its {', '.join(absent[:LISTED])}{more} {verb} not in the file"
        elif nodes:
            reason = f"its ways name nodes the file lacks: {_missing(nodes, set())}"
        elif not ways:
            reason = "the multipolygon has no member way"
        else:
            reason = "its member ways do not close into rings"
        _add(drawn, "relation", oid, {}, reason)


def _member_ways(file: str, ids: set[int]) -> dict[int, list[int]]:
    """The member ways the file holds, each with the nodes it names that are missing."""
    import osmium

    found: dict[int, list[int]] = {}
    ids = {i for i in ids if 0 <= i < LOOKED_UP}
    if not ids:
        return found
    processor = osmium.FileProcessor(file).with_locations().with_filter(osmium.filter.IdFilter(ids))
    for item in processor:
        if isinstance(item, osmium.osm.Way):
            found[item.id] = [node.ref for node in item.nodes if not node.location.valid()]
    return found


def _present_nodes(file: str, ids: set[int]) -> set[int]:
    """Which of these nodes the file holds (after the ways naming them, then)."""
    import osmium

    ids = {i for i in ids if 0 <= i < LOOKED_UP}
    if not ids:
        return set()
    processor = osmium.FileProcessor(file, osmium.osm.NODE).with_filter(osmium.filter.IdFilter(ids))
    return {item.id for item in processor if isinstance(item, osmium.osm.Node)}


def _missing(nodes: list[int], late: set[int]) -> str:
    """'node 99 is not in the file', 'nodes 1, 2 are ...', with a word on negative ids;
    or, when the file holds them after the way, that it is not sorted."""
    found = [node for node in nodes if node in late]
    if found:
        return (
            f"node {found[0]} comes after the way in the file: the extract is not sorted "
            "(osmium sort FILE -o SORTED.osm)"
        )
    unique = list(dict.fromkeys(nodes))
    shown = ", ".join(str(i) for i in unique[:LISTED])
    more = f" and {len(unique) - LISTED} more" if len(unique) > LISTED else ""
    several = len(unique) > 1
    text = f"nodes {shown}{more} are" if several else f"node {shown} is"
    text += " not in the file"
    if any(i < 0 for i in unique):
        return text + " (libosmium keeps no location of a node with a negative id: renumber)"
    return text + (" (or have no valid location)" if several else " (or has no valid location)")
