"""A small OpenStreetMap district of our own, written as OSM XML by the tests, with one
case of each thing S3DB says of buildings: a terrace of hipped houses sharing their
nodes, tower parts standing in podium parts (one hipped, one flat), carports
(``building=roof``, ``building=carport``), heights in feet and inches, a long wall drawn
with extra nodes on a line, parts inheriting their outline's tags, every roof shape
(and those OSM documents that are not built), CSS colour names and junk values.

Plans are in metres east and north of ORIGIN; nodes shared by two ways are one node."""

from __future__ import annotations

import math
from pathlib import Path
from xml.sax.saxutils import quoteattr

ORIGIN = (24.94, 60.17)  # lon, lat
METRE_LAT = 1 / 111_320
METRE_LON = 1 / (111_320 * math.cos(math.radians(ORIGIN[1])))

Ring = list[tuple[float, float]]


def box(x: float, y: float, w: float, d: float) -> Ring:
    return [(x, y), (x + w, y), (x + w, y + d), (x, y + d)]


ROOF_SHAPES = [
    "flat",
    "skillion",
    "gabled",
    "hipped",
    "side_hipped",
    "half-hipped",
    "side_half-hipped",
    "hipped-and-gabled",
    "pyramidal",
    "gambrel",
    "bellcast_gable",
    "mansard",
    "saltbox",
    "dome",
    "round",
    "onion",
    "cone",
    "sawtooth",
    "butterfly",
    "zakomar",
    "crosspitched",
    "gabled_height_moved",
]

# (id, outer ring, tags); ways only (the readers' multipolygons are tested elsewhere)
BUILDINGS: list[tuple[int, Ring, dict[str, str]]] = [
    # a terrace of three hipped houses, 10 m wide, sharing the nodes of their party walls
    *(
        (
            100 + k,
            box(10 * k, 0, 10, 12),
            {
                "building": "terrace",
                "building:levels": "2",
                "roof:shape": "hipped",
                "roof:height": "3",
            },
        )
        for k in range(3)
    ),
    # a carport: a roof on posts, 2.5 m high
    (200, box(40, 0, 6, 5), {"building": "roof", "height": "2.5"}),
    # a carport under a gabled roof, one storey high as nothing says otherwise
    (210, box(48, 0, 6, 5), {"building": "carport", "roof:shape": "gabled", "roof:height": "1"}),
    # a 30 m wall drawn with three extra nodes on a line (a few cm off it)
    (
        300,
        [(0, 30), (7.5, 30.03), (15, 29.98), (22.5, 30.02), (30, 30), (30, 40), (0, 40)],
        {"building": "yes", "height": "6"},
    ),
    # heights in feet: 40' is 12.192 m
    (400, box(40, 30, 8, 8), {"building": "yes", "height": "40'"}),
    # an outline with parts: one part with no tags of its own inherits them all, one
    # has its own height; the podium part carries a tower part standing in it
    (
        500,
        box(0, 60, 40, 20),
        {
            "building": "yes",
            "height": "12",
            "building:colour": "rebeccapurple",
            "roof:colour": "papayawhip",
            "roof:shape": "hipped",
            "roof:height": "2",
        },
    ),
    (501, box(0, 60, 10, 20), {"building:part": "yes"}),
    (502, box(10, 60, 30, 20), {"building:part": "yes", "height": "10"}),
    (503, box(20, 66, 8, 8), {"building:part": "yes", "height": "30", "roof:shape": "flat"}),
    # a podium of three levels under a flat roof, drawn as a part of its outline, and a
    # tower part of twelve levels from the ground in it, its roof's height in feet and
    # inches (13'6" is 4.115 m)
    (900, box(100, 0, 30, 20), {"building": "commercial", "name": "Tower"}),
    (901, box(100, 0, 30, 20), {"building:part": "yes", "building:levels": "3"}),
    (
        902,
        box(108, 5, 10, 10),
        {
            "building:part": "yes",
            "building:levels": "12",
            "roof:shape": "pyramidal",
            "roof:height": "13'6\"",
        },
    ),
    # junk: a colour and a roof shape no one knows
    (
        600,
        box(60, 30, 8, 8),
        {"building": "yes", "building:colour": "blurple", "roof:shape": "banana"},
    ),
    # a factory under a sawtooth roof, its glazing facing north
    (
        800,
        box(60, 60, 30, 20),
        {"building": "industrial", "height": "10", "roof:shape": "sawtooth", "roof:height": "3"},
    ),
    # every roof shape S3DB lists, one house each
    *(
        (
            700 + k,
            box(14 * k, 100, 12, 8),
            {"building": "house", "building:levels": "1", "roof:shape": shape, "roof:height": "3"},
        )
        for k, shape in enumerate(ROOF_SHAPES)
    ),
]


Building = tuple[int, Ring, dict[str, str]]


def write_district(path: Path, buildings: list[Building] = BUILDINGS) -> Path:
    """The buildings as an OSM XML file, nodes shared where ways share a point."""
    nodes: dict[tuple[float, float], int] = {}
    ways = []
    for oid, ring, tags in buildings:
        refs = []
        for x, y in ring:
            key = (round(x, 6), round(y, 6))
            refs.append(nodes.setdefault(key, len(nodes) + 1))
        ways.append((oid, [*refs, refs[0]], tags))
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="tests">']
    for (x, y), nid in sorted(nodes.items(), key=lambda item: item[1]):
        lon, lat = ORIGIN[0] + x * METRE_LON, ORIGIN[1] + y * METRE_LAT
        lines.append(f'  <node id="{nid}" version="1" lat="{lat:.9f}" lon="{lon:.9f}"/>')
    for oid, refs, tags in sorted(ways, key=lambda way: way[0]):  # sorted, as OSM files are
        lines.append(f'  <way id="{oid}" version="1">')
        lines.extend(f'    <nd ref="{ref}"/>' for ref in refs)
        lines.extend(f"    <tag k={quoteattr(k)} v={quoteattr(v)}/>" for k, v in tags.items())
        lines.append("  </way>")
    lines.append("</osm>")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
