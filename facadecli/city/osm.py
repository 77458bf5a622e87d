"""Reading footprints from an OpenStreetMap extract (``.osm.pbf``, ``.osm``, ``.osm.bz2``,
``.osm.gz``) with pyosmium, as one downloads them (Geofabrik, BBBike, the OSM website).

Every area tagged ``building`` or ``building:part`` is a footprint: closed ways and
multipolygon relations, assembled by libosmium (holes and all). Its id is ``way/<id>`` or
``relation/<id>``, its properties its tags, so heights, levels, roof shapes, colours and
building parts work as in a GeoJSON export (the city's S3DB rules). Coordinates are
lon/lat (EPSG:4326). The buildings are given one at a time as libosmium draws them in
its pass over the file (:class:`Buildings`), never gathered: the survey walks them once
and spools what it keeps (footprints.py). What is held besides is compact or small:
libosmium's index of node locations (C++, 16 bytes a node), the entrance nodes (24
bytes each, :class:`Entrances`), each feature's element (9 bytes) and, for XML, its
place (17 bytes, :class:`.osmxml.Places`), the building relations' members, and the
building ways read but not yet drawn (libosmium draws a buffer's worth at a time).

An XML extract is checked first (:mod:`facadecli.city.osmxml`: its inflated size, ids,
coordinates and tag text, each problem at its line); a PBF's blocks are counted
(:mod:`facadecli.city.osmpbf`). Whatever libosmium still cannot read is a SpecError
(exit 2). A building libosmium cannot draw (a way naming a node the file does not hold,
a multipolygon whose member way is missing, a ring that does not close) is a feature
without a geometry, with the reason, which the caller reports and counts as rejected.
"""

from __future__ import annotations

import bisect
import json
from array import array
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pyproj

from facadecli.city.geojson import GeoJSON, NoPlaces
from facadecli.city.landcover import COVER_KEYS, LAND_COVER
from facadecli.city.osmxml import ELEMENTS, KEYS, Places, check_xml
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
    """The line and column where each feature's element starts (XML), when known: the
    element of the feature at an index (:class:`Buildings` keeps it, as it is read), then
    its place (:class:`.osmxml.Places`)."""

    def __init__(self, places: Places, buildings: Buildings):
        super().__init__()
        self.places = places
        self.buildings = buildings

    def feature(self, index: int) -> tuple[int, int] | None:
        element = self.buildings.element(index)
        return None if element is None or not self.places else self.places.get(*element)


def read_osm(path: Path) -> GeoJSON:
    """The building areas of an extract (see the module), read one at a time as they are
    iterated (:class:`Buildings`)."""
    file = str(path)
    places = Places()
    if not path.name.lower().endswith(".pbf"):
        places = check_xml(path)
    else:
        from facadecli.city.osmpbf import check_pbf

        check_pbf(path)
    buildings = Buildings(file)
    return GeoJSON(
        file, buildings, pyproj.CRS.from_epsg(4326), OsmPlaces(places, buildings), buildings.reasons
    )


class Entrances:
    """The entrance nodes read so far, id -> (lon, lat): 24 bytes a node in arrays,
    looked up by bisection (an extract's nodes come sorted by id; sorted here when not,
    a node given twice found at its last place, as a dict would keep it)."""

    def __init__(self) -> None:
        self.ids = array("q")
        self.lon_lat = array("d")
        self.sorted = True

    def __bool__(self) -> bool:
        return bool(self.ids)

    def add(self, oid: int, lon: float, lat: float) -> None:
        if self.ids and oid < self.ids[-1]:
            self.sorted = False
        self.ids.append(oid)
        self.lon_lat.extend((lon, lat))

    def get(self, oid: int) -> tuple[float, float] | None:
        if not self.sorted:
            order = sorted(range(len(self.ids)), key=self.ids.__getitem__)
            self.ids = array("q", (self.ids[k] for k in order))
            self.lon_lat = array("d", (v for k in order for v in self.lon_lat[2 * k : 2 * k + 2]))
            self.sorted = True
        at = bisect.bisect_right(self.ids, oid) - 1
        if at < 0 or self.ids[at] != oid:
            return None
        return self.lon_lat[2 * at], self.lon_lat[2 * at + 1]

    def doors(self, nodes: Iterable[int]) -> list[tuple[float, float]]:
        """The places of those of ``nodes`` that are entrances, each once, in their order
        (a ring's last node is its first)."""
        found = (self.get(node) for node in nodes)
        return list(dict.fromkeys(door for door in found if door is not None))


@dataclass
class _Pass:
    """What the pass over the file holds besides the feature it gives: the entrance
    nodes, the building ways not drawn yet (a way's area follows it) with their doors,
    the building relations' members, the relations drawn, and the nodes of multipolygons'
    outer ways (read when the first multipolygon with entrances is drawn)."""

    entrances: Entrances = field(default_factory=Entrances)
    ways: dict[int, tuple[bool, list[int]]] = field(default_factory=dict)  # closed, missing
    doors: dict[int, list[tuple[float, float]]] = field(default_factory=dict)  # way -> its
    relations: dict[int, tuple[str, list[tuple[str, int, str]]]] = field(default_factory=dict)
    drawn: set[int] = field(default_factory=set)  # relations
    outers: dict[int, list[list[int]]] | None = None  # relation -> its outer ways' nodes


class Buildings(Iterable[dict[str, Any]]):
    """An extract's building areas as GeoJSON features, made one at a time as the file is
    read (libosmium assembles them, its node locations in its own compact index), then
    the building ways and multipolygons it could not draw, each with the reason
    (``reasons``, by index, filled as they are given). A feature is not held once the
    next is made: what is kept a feature is its element (9 bytes, for its place)."""

    def __init__(self, file: str):
        self.file = file
        self.reasons: dict[int, str] = {}  # feature index -> why it has no geometry
        self.kinds = array("b")  # each feature's element: ELEMENTS' index, id
        self.ids = array("q")

    def element(self, index: int) -> tuple[str, int] | None:
        if 0 <= index < len(self.ids):
            return ELEMENTS[self.kinds[index]], self.ids[index]
        return None

    def __iter__(self) -> Iterator[dict[str, Any]]:
        self.reasons.clear()
        self.kinds, self.ids = array("b"), array("q")
        try:
            yield from self._features()
        except SpecError:
            raise
        except Exception as error:  # libosmium's own refusals: RuntimeError, ValueError, ...
            raise _refused(self.file, error) from None

    def _feature(
        self, kind: str, oid: int, tags: dict[str, str], reason: str = ""
    ) -> dict[str, Any]:
        """A feature; one without a geometry has the reason (and no need of its tags)."""
        if reason:
            self.reasons[len(self.ids)] = reason
        self.kinds.append(ELEMENTS.index(kind))
        self.ids.append(oid)
        return {"type": "Feature", "id": f"{kind}/{oid}", "properties": tags, "geometry": None}

    def _features(self) -> Iterator[dict[str, Any]]:
        import osmium  # imported here: only OSM extracts need it

        file = self.file
        factory = osmium.geom.GeoJSONFactory()
        found = _Pass()
        processor = (
            osmium.FileProcessor(file)
            .with_areas(osmium.filter.KeyFilter(*KEYS, *COVER_KEYS))
            .with_filter(osmium.filter.KeyFilter(*KEYS, *COVER_KEYS, ENTRANCE))
        )
        for item in processor:
            if isinstance(item, osmium.osm.Node):
                if ENTRANCE in item.tags and item.location.valid():
                    found.entrances.add(item.id, item.location.lon, item.location.lat)
                continue
            if isinstance(item, osmium.osm.Area) and not _building(item.tags):
                yield from self._cover(item, factory)  # land cover (landcover.py)
                continue
            if not _building(item.tags):  # a way or relation of land cover, or an entrance
                continue
            if isinstance(item, osmium.osm.Area):
                kind = "way" if item.from_way() else "relation"
                oid = item.orig_id()
                reason = ""
                try:
                    geometry = json.loads(factory.create_multipolygon(item))
                except RuntimeError as error:
                    geometry, reason = None, f"libosmium cannot draw its outline: {error}"
                feature = self._feature(kind, oid, _tags(file, kind, oid, item.tags), reason)
                feature["geometry"] = geometry
                if kind == "way":
                    found.ways.pop(oid, None)
                    doors = found.doors.pop(oid, None)
                else:
                    found.drawn.add(oid)
                    doors = _relation_doors(file, found, oid)
                if doors:
                    feature["entrances"] = doors
                yield feature
                del feature, geometry
            elif isinstance(item, osmium.osm.Way):
                _tags(file, "way", _id(file, "way", item.id), item.tags)
                missing = [node.ref for node in item.nodes if not node.location.valid()]
                found.ways[item.id] = (item.is_closed(), missing)
                doors = found.entrances.doors(node.ref for node in item.nodes)
                if doors:
                    found.doors[item.id] = doors
            elif isinstance(item, osmium.osm.Relation):
                tags = _tags(file, "relation", _id(file, "relation", item.id), item.tags)
                members = [(m.type, m.ref, m.role) for m in item.members]
                found.relations[item.id] = (tags.get("type", ""), members)
        yield from self._undrawn(found)

    def _cover(self, item: Any, factory: Any) -> Iterator[dict[str, Any]]:
        """A land-cover area as a feature (survey() tells it from a building by its tags);
        one libosmium cannot draw is left out: a forest cut by the extract's edge is
        common, and no building depends on it."""
        kind = "way" if item.from_way() else "relation"
        oid = item.orig_id()
        try:
            geometry = json.loads(factory.create_multipolygon(item))
        except RuntimeError:
            return
        tags = _tags(self.file, kind, oid, item.tags)
        if not any(key in tags for key in COVER_KEYS):
            return  # an old-style multipolygon's untagged ring, or an entrance way
        feature = self._feature(kind, oid, tags)
        feature["geometry"] = geometry
        feature[LAND_COVER] = True  # not a footprint, whatever its tags (survey())
        yield feature

    def _undrawn(self, found: _Pass) -> Iterator[dict[str, Any]]:
        """The building ways and multipolygons libosmium drew no area of, as features
        without a geometry, each with the reason (a missing node or member way, an open
        ring)."""
        file = self.file
        in_relations = {
            ref
            for _, members in found.relations.values()
            for kind, ref, _ in members
            if kind == "w"
        }
        undrawn = [(oid, way) for oid, way in sorted(found.ways.items()) if oid not in in_relations]
        late = _present_nodes(file, {node for _, (_, missing) in undrawn for node in missing})
        for oid, (closed, missing) in undrawn:
            if missing:
                reason = _missing(missing, late)
            elif not closed:
                reason = "the way is not closed (its first and last nodes differ)"
            else:
                reason = "libosmium could not make a ring of it (too few nodes?)"
            yield self._feature("way", oid, {}, reason)
        broken = {
            oid: members
            for oid, (kind, members) in found.relations.items()
            if oid not in found.drawn and kind in ("multipolygon", "boundary")
        }
        if not broken:
            return
        refs = {ref for members in broken.values() for kind, ref, _ in members if kind == "w"}
        ways = _member_ways(file, refs)
        for oid, members in sorted(broken.items()):
            yield self._feature("relation", oid, {}, _broken(members, ways))


def _building(tags: Any) -> bool:
    """Whether an element is tagged as a building (or a building's part)."""
    return any(key in tags for key in KEYS)


def _refused(file: str, error: Exception) -> SpecError:
    """libosmium's refusal of the file, as a SpecError with a hint."""
    message = f"libosmium cannot read it: {error}" if str(error) else type(error).__name__
    hint = HINT
    if "out of order" in message or "twice" in message:
        hint = SORT
    elif "uncompress" in message:
        hint = "download the extract again"
    return SpecError.at(file, None, None, message, hint)


def _broken(members: list[tuple[str, int, str]], found: dict[int, list[int]]) -> str:
    """Why a multipolygon of these members was not drawn (``found``: its member ways the
    file holds, each with the nodes it names that are missing)."""
    ways = [(ref, role) for t, ref, role in members if t == "w"]
    absent = [f"{role or 'member'} way {ref}" for ref, role in ways if ref not in found]
    nodes = [node for ref, _ in ways for node in found.get(ref, [])]
    if absent:
        more = f" and {len(absent) - LISTED} more" if len(absent) > LISTED else ""
        verb = "are" if len(absent) > 1 else "is"
        return f"its {', '.join(absent[:LISTED])}{more} {verb} not in the file"
    if nodes:
        return f"its ways name nodes the file lacks: {_missing(nodes, set())}"
    if not ways:
        return "the multipolygon has no member way"
    return "its member ways do not close into rings"


def _relation_doors(file: str, found: _Pass, oid: int) -> list[tuple[float, float]]:
    """The entrances of a multipolygon building: the entrance nodes of its outer member
    ways (role ``outer``, or none as in old multipolygons), which the pass over the file
    did not see when untagged. When the first is asked for (every node, so every
    entrance, is read by then: an extract is sorted), the building relations are read
    again for their outer ways, and those ways for their nodes."""
    if not found.entrances:
        return []
    if found.outers is None:
        outers = _outer_ways(file)
        nodes = _way_nodes(file, {ref for refs in outers.values() for ref in refs})
        found.outers = {
            relation: [nodes[ref] for ref in refs if ref in nodes]
            for relation, refs in outers.items()
        }
    return found.entrances.doors(node for way in found.outers.get(oid, []) for node in way)


def _outer_ways(file: str) -> dict[int, list[int]]:
    """The outer member ways of every building relation of the file."""
    import osmium

    processor = osmium.FileProcessor(file, osmium.osm.RELATION).with_filter(
        osmium.filter.KeyFilter(*KEYS)
    )
    return {
        item.id: [m.ref for m in item.members if m.type == "w" and m.role in OUTER]
        for item in processor
        if isinstance(item, osmium.osm.Relation)
    }


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
