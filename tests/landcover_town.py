"""A small district with its land cover, written by the tests as OSM (XML or PBF) and as
GeoJSON, seeded sizes with known answers: two rows of houses along a street, a park west of
them with a pond in it (a multipolygon with an island), a riverbank south of the street, a
wood north reaching far past the district (clipped), a car park east, a railway yard (a
land use of no kind drawn: warned) and the town's residential land use round it all.

Plans are in metres east and north of ORIGIN."""

from __future__ import annotations

import json
import math
import random
from dataclasses import dataclass
from pathlib import Path

import osmium
from osmium.osm.mutable import Node, Relation, Way

ORIGIN = (24.94, 60.17)  # lon, lat
METRE_LAT = 1 / 111_320
METRE_LON = 1 / (111_320 * math.cos(math.radians(ORIGIN[1])))

Ring = list[tuple[float, float]]
STREET = 16.0  # metres between the two rows of houses


def box(x: float, y: float, w: float, d: float) -> Ring:
    return [(x, y), (x + w, y), (x + w, y + d), (x, y + d)]


@dataclass(frozen=True)
class Area:
    """A mapped area: an OSM way (no holes) or multipolygon relation (``holes``)."""

    kind: str  # "way" or "relation"
    id: int
    outer: Ring
    tags: dict[str, str]
    holes: tuple[Ring, ...] = ()


@dataclass(frozen=True)
class Town:
    buildings: list[Area]
    cover: list[Area]
    district: tuple[float, float, float, float]  # the buildings' extent, metres

    @property
    def areas(self) -> list[Area]:
        return self.buildings + self.cover


def town(seed: int) -> Town:
    """The district of ``seed`` (see the module)."""
    chance = random.Random(seed)
    houses = chance.randint(3, 6)
    wide = [chance.uniform(9, 14) for _ in range(houses)]
    deep = chance.uniform(9, 13)
    buildings = []
    x = 0.0
    for k in range(houses):  # a row each side of a street STREET wide
        for side, y in ((0, 0.0), (1, -STREET - deep)):
            tags = {"building": "house", "building:levels": str(chance.randint(2, 4))}
            buildings.append(Area("way", 100 + 20 * side + k, box(x, y, wide[k], deep), tags))
        x += wide[k] + chance.uniform(2, 6)
    east = x
    south = -STREET - deep  # the south row's back
    # a multi-storey car park: a building, whatever its amenity
    buildings.append(
        Area("way", 150, box(east, 0, 20, 16), {"building": "yes", "amenity": "parking"})
    )
    east += 20
    park_w, park_d = chance.uniform(30, 45), chance.uniform(25, 35)
    pond = chance.uniform(8, 12)
    cover = [
        Area("way", 200, box(-park_w - 2, 0, park_w, park_d), {"leisure": "park"}),
        Area(
            "relation",
            300,
            box(-park_w + 2, 5, 2 * pond, pond),
            {"type": "multipolygon", "natural": "water"},
            (box(-park_w + 2 + pond - 2, 5 + pond / 2 - 2, 4, 4),),
        ),
        Area(
            "way",
            400,
            box(-park_w - 8, south - 30, park_w + east + 40, 18),
            {"waterway": "riverbank"},
        ),
        Area("way", 500, box(-20, deep + 16, 60, 400), {"landuse": "forest"}),
        Area("way", 600, box(east + 6, 0, 24, 30), {"amenity": "parking"}),
        Area("way", 700, box(east + 6, south - 60, 30, 10), {"landuse": "railway"}),
        Area("way", 800, box(-300, -300, 600, 600), {"landuse": "residential"}),
    ]
    xs = [p[0] for b in buildings for p in b.outer]
    ys = [p[1] for b in buildings for p in b.outer]
    return Town(buildings, cover, (min(xs), min(ys), max(xs), max(ys)))


def lon_lat(point: tuple[float, float]) -> tuple[float, float]:
    return ORIGIN[0] + point[0] * METRE_LON, ORIGIN[1] + point[1] * METRE_LAT


def write_osm(path: Path, district: Town) -> Path:
    """The district as an extract (``.osm`` or ``.osm.pbf``, by its name), sorted: nodes,
    ways, relations; a multipolygon's rings are untagged ways."""
    path.unlink(missing_ok=True)
    writer = osmium.SimpleWriter(str(path))
    node = 0
    ways: list[Way] = []
    relations: list[Relation] = []
    way_id = 10_000
    for area in district.areas:
        rings = [area.outer, *area.holes]
        refs = []
        for ring in rings:
            ids = []
            for point in ring:
                node += 1
                writer.add_node(Node(id=node, location=lon_lat(point)))
                ids.append(node)
            refs.append([*ids, ids[0]])
        if area.kind == "way":
            ways.append(Way(id=area.id, nodes=refs[0], tags=area.tags))
            continue
        members = []
        for k, ring_refs in enumerate(refs):
            way_id += 1
            ways.append(Way(id=way_id, nodes=ring_refs, tags={}))
            members.append(("w", way_id, "outer" if k == 0 else "inner"))
        relations.append(Relation(id=area.id, members=members, tags=area.tags))
    for way in sorted(ways, key=lambda w: w.id):
        writer.add_way(way)
    for relation in relations:
        writer.add_relation(relation)
    writer.close()
    return path


def write_geojson(path: Path, district: Town) -> Path:
    """The district as a GeoJSON FeatureCollection (lon/lat), tags as properties."""
    features = []
    for area in district.areas:
        rings = [[list(lon_lat(p)) for p in [*r, r[0]]] for r in (area.outer, *area.holes)]
        tags = {k: v for k, v in area.tags.items() if k != "type"}
        features.append(
            {
                "type": "Feature",
                "id": f"{area.kind}/{area.id}",
                "properties": tags,
                "geometry": {"type": "Polygon", "coordinates": rings},
            }
        )
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


if __name__ == "__main__":  # the sample: python -m tests.landcover_town samples/park-town.osm
    import sys

    write_osm(Path(sys.argv[1]), town(1))
