"""Doors at OpenStreetMap's entrances (issue 35 item 4): an ``entrance=*`` node on a
building's outline gives the wall that holds it a door there, in place of the ground
floor's nearest window or, where there is none, a door of its own; nothing the door
covers stays, and no view passes through the wall round it."""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point

from facadecli import load_spec, solve
from facadecli.city.default import default_city
from facadecli.city.entrances import GROUND_FLOOR, NEAR, along_wall, door_owners, with_doors
from facadecli.city.footprints import read_footprints
from facadecli.city.run import planned, run_city
from facadecli.geometry.facade import facade_scene
from tests.instances import placed_triangles
from tests.rays import directions, missing

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "specs").glob("*.yaml"))
ORIGIN = (24.94, 60.17)  # lon, lat
METRE_LAT = 1 / 111_320
METRE_LON = 1 / (111_320 * math.cos(math.radians(ORIGIN[1])))


def test_an_entrance_is_on_the_wall_it_lies_on() -> None:
    a, b = (0.0, 0.0), (10.0, 0.0)
    assert along_wall([(4.0, 0.0), (7.5, 0.3), (3.0, 2.0), (12.0, 0.0)], a, b) == (4.0, 7.5)
    assert along_wall([(4.0, 0.0)], b, a) == (6.0,)  # measured from the wall's start


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
@pytest.mark.parametrize("seed", range(3))
def test_a_door_replaces_what_it_covers_and_leaves_no_hole(path: Path, seed: int) -> None:
    """A door at a random point of every example's width: one door there (on the nearest
    ground-floor opening, or of its own), no other shape left over its rectangle, and
    rays at 35° from eight directions over the door and round it all meet the front of
    something."""
    layout = solve(load_spec(path))
    position = random.Random(seed).uniform(0.5, layout.width - 0.5)
    before = {(s.layer, s.x0, s.x1, s.y0, s.y1) for s in layout.shapes if s.mesh == "door"}
    doored = with_doors(layout, [position])
    added = [
        s
        for s in doored.shapes
        if s.mesh == "door" and (s.layer, s.x0, s.x1, s.y0, s.y1) not in before
    ]
    if not added:  # the façade's own door stands there
        doors = [s for s in layout.shapes if s.mesh == "door" and s.visible]
        assert any(s.x0 - NEAR <= position <= s.x1 + NEAR for s in doors)
        return
    (door,) = added
    assert door.y0 == 0.0 and door.y1 >= 2.0
    assert door.x0 - NEAR <= position <= door.x1 + NEAR
    for shape in doored.shapes:
        if shape is not door and shape.visible:
            inside_x = min(shape.x1, door.x1) - max(shape.x0, door.x0)
            inside_y = min(shape.y1, door.y1) - max(shape.y0, door.y0)
            assert inside_x <= 1e-6 or inside_y <= 1e-6, shape
    triangles = facade_scene(doored, path.parent).to_geometry().triangles
    xs = np.arange(max(door.x0 - 0.4, 0.25), min(door.x1 + 0.4, layout.width - 0.25), 0.1)
    ys = np.arange(0.25, min(door.y1 + 0.4, layout.height - 0.25), 0.1)
    targets = np.array([(x, y, 0.0) for x in xs for y in ys])
    for direction in directions():
        through = targets[missing(triangles, targets, direction, culled=True)]
        assert len(through) == 0, f"rays along {direction} pass at {through[:5].tolist()}"


def test_a_door_takes_the_place_of_the_nearest_ground_floor_window() -> None:
    layout = solve(load_spec(ROOT / "specs" / "townhouse.yaml"))
    frames = sorted(
        (s for s in layout.shapes if s.mesh == "frame" and s.y0 < GROUND_FLOOR),
        key=lambda s: s.x0,
    )
    window = frames[1]
    doored = with_doors(layout, [window.x1 - 0.1])
    (door,) = [s for s in doored.shapes if s.mesh == "door"]
    assert (door.x0, door.x1) == (window.x0, window.x1)
    assert door.y1 >= window.y1
    assert (
        len([s for s in doored.shapes if s.mesh == "frame"])
        == len([s for s in layout.shapes if s.mesh == "frame"]) - 1
    )


def _extract(path: Path, entrance: float) -> None:
    """Two houses 12 x 9 m, 30 m apart; the first has an entrance node ``entrance``
    metres along its south wall, a node of its way."""
    nodes = {1: (0, 0), 2: (12, 0), 3: (12, 9), 4: (0, 9), 5: (entrance, 0)}
    nodes |= {11: (30, 0), 12: (42, 0), 13: (42, 9), 14: (30, 9), 20: (20, 20)}
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="tests">']
    for nid, (x, y) in nodes.items():
        place = f'lat="{ORIGIN[1] + y * METRE_LAT:.9f}" lon="{ORIGIN[0] + x * METRE_LON:.9f}"'
        tags = '<tag k="entrance" v="main"/>' if nid in (5, 20) else ""  # 20: on no building
        lines.append(f'  <node id="{nid}" version="1" {place}>{tags}</node>')
    house = '<tag k="building" v="house"/><tag k="building:levels" v="2"/>'
    refs = "".join(f'<nd ref="{n}"/>' for n in (1, 5, 2, 3, 4, 1))
    lines.append(f'  <way id="100" version="1">{refs}{house}</way>')
    refs = "".join(f'<nd ref="{n}"/>' for n in (11, 12, 13, 14, 11))
    lines.append(f'  <way id="101" version="1">{refs}{house}</way>')
    lines.append("</osm>")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def test_an_osm_entrance_node_is_a_door_in_its_wall(tmp_path: Path) -> None:
    extract = tmp_path / "two.osm"
    _extract(extract, 4.3)
    spec = ROOT / "specs" / "residential-house.yaml"
    report = run_city(default_city(extract, spec), tmp_path / "out", jobs=1)
    assert report["summary"]["ok"] == 2
    doors = {b["id"]: b.get("doors", 0) for b in report["buildings"]}
    assert doors == {"way/100": 1, "way/101": 0}
    files = {b["id"]: tmp_path / "out" / b["file"] for b in report["buildings"]}
    with_door = placed_triangles(files["way/100"].read_bytes())
    assert "door" not in placed_triangles(files["way/101"].read_bytes())
    corners = with_door["door"].reshape(-1, 3)
    low, high = corners.min(axis=0), corners.max(axis=0)
    south = max(float(t[:, :, 2].max()) for t in with_door.values())  # glTF z: south
    # local metres: x east from the westmost corner (the map grid turns the walls a little)
    assert low[0] - 0.1 <= 4.3 <= high[0] + 0.1 and high[0] - low[0] <= 2.5
    assert low[1] == pytest.approx(0.0, abs=0.05) and high[1] >= 2.0
    assert south - 0.5 < high[2] <= south  # in the south wall
    cityjson = json.loads((tmp_path / "out" / "two.city.json").read_text())
    assert all("entrances" not in o.get("attributes", {}) for o in cityjson["CityObjects"].values())


def _node(nid: int, x: float, y: float, tags: str = "") -> str:
    place = f'lat="{ORIGIN[1] + y * METRE_LAT:.9f}" lon="{ORIGIN[0] + x * METRE_LON:.9f}"'
    return f'  <node id="{nid}" version="1" {place}>{tags}</node>'


def test_a_multipolygon_building_s_entrances_are_read_on_its_outer_ways(tmp_path: Path) -> None:
    """A multipolygon building (a courtyard block: its outer way and inner way untagged,
    the relation tagged) gets the entrance nodes of its outer way, not of its inner way
    (issue 35, item 4); a way building next to it keeps its own."""
    entrance = '<tag k="entrance" v="yes"/>'
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="tests">']
    outer = {1: (0, 0), 2: (30, 0), 3: (30, 30), 4: (0, 30), 5: (10, 0)}
    inner = {11: (10, 10), 12: (10, 20), 13: (20, 20), 14: (20, 10), 15: (15, 10)}
    house = {21: (40, 0), 22: (52, 0), 23: (52, 9), 24: (40, 9), 25: (46, 9)}
    for nid, (x, y) in {**outer, **inner, **house}.items():
        lines.append(_node(nid, x, y, entrance if nid in (5, 15, 25) else ""))
    lines.append(
        '  <way id="100" version="1">'
        + "".join(f'<nd ref="{n}"/>' for n in (1, 5, 2, 3, 4, 1))
        + "</way>"
    )
    lines.append(
        '  <way id="101" version="1">'
        + "".join(f'<nd ref="{n}"/>' for n in (11, 12, 13, 14, 15, 11))
        + "</way>"
    )
    tags = '<tag k="building" v="yes"/>'
    nds = "".join(f'<nd ref="{n}"/>' for n in (21, 22, 23, 25, 24, 21))
    lines.append(f'  <way id="102" version="1">{nds}{tags}</way>')
    members = (
        '<member type="way" ref="100" role="outer"/><member type="way" ref="101" role="inner"/>'
    )
    lines.append(
        f'  <relation id="7" version="1">{members}<tag k="type" v="multipolygon"/>{tags}</relation>'
    )
    lines.append("</osm>")
    extract = tmp_path / "block.osm"
    extract.write_text("\n".join(lines) + "\n", encoding="utf-8")
    found = {f.id: f for f in read_footprints(extract).footprints}
    assert set(found) == {"relation/7", "way/102"}
    block, house_ = found["relation/7"], found["way/102"]
    assert len(block.entrances) == 1 and len(house_.entrances) == 1
    # on the outline, 10 m from its nearest corner (the UTM grid turns the map a little)
    for footprint, corner in ((block, 10.0), (house_, 6.0)):
        (part,) = footprint.parts
        where = Point(footprint.entrances[0])
        assert part.exterior.distance(where) < 0.01
        corners = [Point(c) for c in part.simplify(0.01).exterior.coords]  # not its node
        assert min(c.distance(where) for c in corners) == pytest.approx(corner, abs=0.05)
    assert block.parts[0].interiors[0].distance(Point(block.entrances[0])) > 5


def _square(x: float, y: float, size: float) -> list[list[float]]:
    return [[x, y], [x + size, y], [x + size, y + size], [x, y + size], [x, y]]


def test_geojson_entrance_points_on_an_edge_are_doors_the_rest_warned(tmp_path: Path) -> None:
    """Point features tagged ``entrance`` lying on a footprint's edge (within 0.5 m) are
    its entrances, on any edge of any ring; a point farther off is warned once, by id
    and line, and counted under ``entrance``; a point that is not an entrance stays a
    rejected feature."""

    def point(fid: str, x: float, y: float, tags: dict[str, str]) -> dict[str, object]:
        geometry = {"type": "Point", "coordinates": [x, y]}
        return {"type": "Feature", "id": fid, "properties": tags, "geometry": geometry}

    house = {"building": "house", "building:levels": 2}
    features = [
        {
            "type": "Feature",
            "id": "a",
            "properties": house,
            "geometry": {"type": "Polygon", "coordinates": [_square(0, 0, 12)]},
        },
        {
            "type": "Feature",
            "id": "b",
            "properties": house,
            "geometry": {"type": "Polygon", "coordinates": [_square(30, 0, 12)]},
        },
        point("door-a", 4.0, -0.3, {"entrance": "main"}),  # 0.3 m off a's south wall
        point("door-b", 42.2, 6.0, {"entrance": "service"}),  # 0.2 m off b's east wall
        point("lost", 20.0, 6.0, {"entrance": "yes"}),  # between them, on neither
        point("tree", 5.0, 5.0, {"natural": "tree"}),
    ]
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::3067"}}
    path = tmp_path / "doors.geojson"
    document = {"type": "FeatureCollection", "crs": crs, "features": features}
    path.write_text(json.dumps(document, indent=1), encoding="utf-8")
    found = read_footprints(path)
    doors = {f.id: f.entrances for f in found.footprints}
    assert doors["a"] == ((4.0, -0.3),) and doors["b"] == ((42.2, 6.0),)
    assert [(w.id, w.reason.split(" ")[0]) for w in found.warnings] == [("lost", "entrance")]
    assert found.warnings[0].line is not None
    assert [r.id for r in found.rejected] == ["tree"]


def test_a_door_goes_to_the_building_whose_wall_is_not_a_party_wall() -> None:
    south, party = ((0.0, 0.0), (10.0, 0.0)), ((10.0, 0.0), (10.0, 9.0))
    neighbour = ((10.0, 0.0), (20.0, 0.0))
    walls_a = [(*south, False), (*party, True)]
    walls_b = [(*neighbour, False), (party[1], party[0], True)]
    middle = (10.0, 4.5)  # on the party wall: on no façade
    assert door_owners(middle, [("a", walls_a), ("b", walls_b)]) == []
    assert door_owners(middle, [("a", walls_a), ("b", [(party[1], party[0], False)])]) == ["b"]
    # at the corner both fronts have it at their ends: the first first; 2 m in b, b alone
    assert door_owners((10.0, 0.0), [("a", walls_a), ("b", walls_b)]) == ["a", "b"]
    assert door_owners((12.0, 0.2), [("a", walls_a), ("b", walls_b)]) == ["b"]
    assert door_owners((50.0, 50.0), [("a", walls_a)]) == []


def _terrace(path: Path) -> None:
    """Houses a and b (way 100, 101), 10 x 9 m, sharing the wall from node 2 to 3 (and
    node 9 on it); house c (way 102) of three levels with an annex d (way 103) of one
    sharing its east wall (node 25 on it). Entrances: node 2 (a and b's south corner),
    node 9 (a and b's party wall) and node 25 (c's east wall, d's west wall)."""
    nodes = {1: (0, 0), 2: (10, 0), 3: (10, 9), 4: (0, 9), 6: (20, 0), 7: (20, 9), 9: (10, 4.5)}
    nodes |= {21: (40, 0), 22: (50, 0), 23: (50, 9), 24: (40, 9), 25: (50, 4.5)}
    nodes |= {26: (56, 0), 27: (56, 9)}
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="tests">']
    for nid, (x, y) in nodes.items():
        tags = '<tag k="entrance" v="yes"/>' if nid in (2, 9, 25) else ""
        lines.append(_node(nid, x, y, tags))
    ways = {
        100: ((1, 2, 9, 3, 4, 1), 2),
        101: ((2, 6, 7, 3, 9, 2), 2),
        102: ((21, 22, 25, 23, 24, 21), 3),
        103: ((22, 26, 27, 23, 25, 22), 1),
    }
    for wid, (refs, levels) in ways.items():
        nds = "".join(f'<nd ref="{n}"/>' for n in refs)
        tags = f'<tag k="building" v="house"/><tag k="building:levels" v="{levels}"/>'
        lines.append(f'  <way id="{wid}" version="1">{nds}{tags}</way>')
    lines.append("</osm>")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def test_an_entrance_two_buildings_share_is_one_door(tmp_path: Path) -> None:
    """An entrance node in two buildings' ways is a door in one of them only: at a
    shared corner, the first's (warned and counted, as several could have it); on a
    party wall, in neither (warned); on a wall shared with a lower annex, the house's,
    whose wall there stands free above the annex (not a party wall), not the annex's."""
    extract = tmp_path / "terrace.osm"
    _terrace(extract)
    ahead = planned(default_city(extract, ROOT / "specs" / "residential-house.yaml"), tmp_path)
    held = {task.footprint.id: len(task.footprint.entrances) for task in ahead.tasks}
    read = {f.id: len(f.entrances) for f in read_footprints(extract).footprints}
    assert read == {"way/100": 2, "way/101": 2, "way/102": 1, "way/103": 1}  # as mapped
    assert held == {"way/100": 1, "way/101": 0, "way/102": 1, "way/103": 0}
    warned = [(w.id, w.reason.split(" is ")[1].split(":")[0]) for w in ahead.found.warnings]
    assert warned == [
        ("way/100", "on walls of way/100, way/101, none a party wall"),
        ("way/100", "on party walls of way/100, way/101 only"),
    ]
    (door,) = next(t for t in ahead.tasks if t.footprint.id == "way/100").footprint.entrances
    corner = next(t for t in ahead.tasks if t.footprint.id == "way/100").footprint.parts[0]
    assert min(Point(c).distance(Point(door)) for c in corner.exterior.coords) < 0.01
