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

from facadecli import load_spec, solve
from facadecli.city.default import default_city
from facadecli.city.entrances import GROUND_FLOOR, NEAR, along_wall, with_doors
from facadecli.city.run import run_city
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
