"""Cities as OpenStreetMap maps them (Simple 3D Buildings): heights including the roof,
parts replacing their outline, lifted parts, colours, party walls, heights from any
property. One small hand-made district, one building a tag."""

from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from facadecli.city.folders import building_file
from facadecli.city.footprints import Footprint
from facadecli.city.manifest import Roof, load_city
from facadecli.city.rooftop import METAL_NAME, ROOFLIGHT_NAME
from facadecli.city.run import run_city
from facadecli.city.s3db import (
    MIN_ROOF,
    ROOF_SHARE,
    Heights,
    blind,
    colour,
    compass,
    lifted,
    outline_rest,
    replaced_outlines,
    shared_edges,
    tagged_heights,
    volume,
)
from facadecli.geometry.facade import INTERIOR_MATERIAL, linear_rgb

SPEC = """
version: 1
name: plain
canvas: {width: 6, height: 6}
symbol_defaults: {opaque: true}
symbols: {E: 1.0, W: 1.2, F: 3.0}
counters: {n: {min: 1}, f: {min: 1}}
patterns: {x: "E (W E)^n", y: "F^f"}
layers: [{name: wall, x: x, y: y}]
shapes: [{match: {x: W}, material: glass, depth: -0.1, thickness: 0.02}]
materials:
  render: {color: "#e0d8c8"}
  glass: {color: "#8fb3d9", opacity: 0.5}
defaults: {material: render}
solver: {tolerance: 0.5}
"""

MANIFEST = """
version: 1
name: tags
footprints: tags.geojson
defaults:
  facade: plain.yaml
  height: 9.0
  floor_height: 3.0
  roof: {{type: flat}}
  min_facade_width: 2.0
{extra}
"""


def _feature(fid: str, ring: list[tuple[float, float]], **tags: Any) -> dict[str, Any]:
    closed = [[x + 100000.0, y + 400000.0] for x, y in [*ring, ring[0]]]
    return {
        "type": "Feature",
        "id": fid,
        "properties": tags,
        "geometry": {"type": "Polygon", "coordinates": [closed]},
    }


def _box(x: float, y: float, w: float, d: float) -> list[tuple[float, float]]:
    return [(x, y), (x + w, y), (x + w, y + d), (x, y + d)]


FEATURES = [
    # height is the top of the roof: a 12 m gabled house with a 4 m roof has 8 m walls
    _feature(
        "gabled",
        _box(0, 0, 12, 8),
        building="house",
        height="12",
        **{"roof:shape": "gabled", "roof:height": "4"},
    ),
    # levels below the roof: 3 x 3 m of wall, the roof on top at its pitch
    _feature(
        "levels",
        _box(30, 0, 10, 8),
        building="yes",
        **{"building:levels": "3", "roof:shape": "hipped", "roof:angle": "45"},
    ),
    # lifted off the ground: walls from 5 m to 10 m
    _feature(
        "lifted", _box(60, 0, 8, 8), **{"building:part": "yes", "min_height": "5", "height": "10"}
    ),
    # an outline and its two parts: the parts are built, the outline is not
    _feature("outline", _box(0, 40, 20, 10), building="yes", height="30"),
    _feature("low", _box(0, 40, 10, 10), **{"building:part": "yes", "height": "6"}),
    _feature(
        "tower",
        _box(10, 40, 10, 10),
        **{
            "building:part": "yes",
            "height": "15",
            "building:colour": "red",
            "roof:colour": "#00ff00",
        },
    ),
    # a terrace of three: the walls between them are party walls, blind
    _feature("t1", _box(40, 40, 7, 10), building="terrace", height="9"),
    _feature("t2", _box(47, 40, 7, 10), building="terrace", height="9"),
    _feature("t3", _box(54, 40, 7, 10), building="terrace", height="9"),
    # a national dataset's property: decimetres
    _feature("dataset", _box(80, 40, 10, 10), HAUTEUR=180),
    # an outline with one wing drawn as a part: the other wing is still built
    _feature("station", _box(0, 15, 20, 10), building="train_station", height="9"),
    _feature("hall", _box(0, 15, 10, 10), **{"building:part": "yes", "height": "15"}),
    # a podium drawn as the outline, upper storeys as a part on it: nothing floats, and
    # the storeys' walls are their own, not party walls (flush with the podium's south)
    _feature("podium", _box(30, 15, 12, 10), building="yes", **{"building:levels": "2"}),
    _feature(
        "storeys",
        _box(32, 15, 8, 6),
        **{"building:part": "yes", "building:min_level": "2", "building:levels": "5"},
    ),
]


def _run(tmp_path: Path, extra: str = "") -> dict[str, Any]:
    (tmp_path / "plain.yaml").write_text(SPEC)
    data = {
        "type": "FeatureCollection",
        "features": FEATURES,
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
    }
    (tmp_path / "tags.geojson").write_text(json.dumps(data))
    (tmp_path / "tags.yaml").write_text(MANIFEST.format(extra=extra))
    return run_city(load_city(tmp_path / "tags.yaml"), tmp_path / "out")


def _model(tmp_path: Path, fid: str) -> trimesh.Scene:
    return trimesh.load(tmp_path / "out" / building_file(fid), force="scene")


ON_ROOF = (METAL_NAME, ROOFLIGHT_NAME, INTERIOR_MATERIAL)  # coping, plant, rooflights' wells


def _top(scene: trimesh.Scene) -> float:
    """The top of a building's walls and roof (y is up): without what stands on a flat
    roof (its coping and plant in the roof metal, the rooflights' glazing and wells; the
    windows' recesses, in the interior's material too, are under the top), which
    S3DB's height leaves out as it does antennas and other roof equipment."""
    kept = [g for g in scene.geometry.values() if g.visual.material.name not in ON_ROOF]
    return float(max(g.bounds[1][1] for g in kept))


@pytest.fixture(scope="module")
def district(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    folder = tmp_path_factory.mktemp("tags")
    return folder, _run(folder, "properties:\n  height: {name: HAUTEUR, scale: 0.1}\n")


def _entry(report: dict[str, Any], fid: str) -> dict[str, Any]:
    return next(b for b in report["buildings"] if b["id"] == fid)


def test_height_is_the_top_of_the_roof(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    scene = _model(folder, "gabled")
    assert scene.bounds[1][1] == pytest.approx(12.0, abs=1e-3)  # y is up
    walls = scene.geometry["gabled/render"]  # the façades' wall material, gable ends too
    heights = walls.vertices[walls.faces][:, :, 1]
    over = heights.max(axis=1) > 8.0 + 0.05  # above the eaves, 12 m less the 4 m roof
    assert over.any() and walls.bounds[1][1] == pytest.approx(12.0, abs=1e-3)
    # only the gable ends: vertical, standing on the eaves (no façade reaches past them)
    assert heights[over].min() == pytest.approx(8.0, abs=0.05)
    assert np.abs(walls.face_normals[over][:, 1]).max() < 1e-4
    assert _entry(report, "gabled")["height"] == pytest.approx(12.0)


def test_levels_are_below_the_roof(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    scene = _model(folder, "levels")
    walls = scene.geometry["levels/render"].bounds
    assert walls[1][1] == pytest.approx(9.0, abs=0.05)  # 3 levels of 3 m
    assert scene.bounds[1][1] == pytest.approx(9.0 + 4.0, abs=1e-3)  # 45°, 8 m deep: 4 m
    assert _entry(report, "levels")["height"] == pytest.approx(13.0)


def test_min_height_lifts_the_walls(district: tuple[Path, dict[str, Any]]) -> None:
    folder, _ = district
    scene = _model(folder, "lifted")
    assert scene.bounds[0][1] == pytest.approx(5.0 - 0.01, abs=1e-3)  # its floor slab
    assert _top(scene) == pytest.approx(10.0, abs=1e-3)
    assert "lifted/ground" not in scene.geometry  # nothing on the ground


def test_parts_replace_their_outline(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    built = {b["id"] for b in report["buildings"]}
    assert "outline" not in built and {"low", "tower"} <= built
    assert {"id": "outline", "parts": ["low", "tower"], "kept_m2": 0.0} in report["replaced"]
    assert report["summary"]["replaced"] == 1
    assert _top(_model(folder, "tower")) == pytest.approx(15.0, abs=1e-3)
    assert _top(_model(folder, "low")) == pytest.approx(6.0, abs=1e-3)


def test_what_parts_leave_of_their_outline_is_built(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, report = district
    wing = _model(folder, "station").bounds
    assert wing[0][0] == pytest.approx(10.0, abs=0.3) and wing[1][0] == pytest.approx(20.0, abs=0.3)
    top = _top(_model(folder, "station"))
    assert top == pytest.approx(9.0, abs=1e-3)  # the outline's own height
    assert _top(_model(folder, "hall")) == pytest.approx(15.0, abs=1e-3)
    entries = {r["id"]: r for r in report["replaced"]}
    assert entries["station"] == {"id": "station", "parts": ["hall"], "kept_m2": 100.0}
    assert entries["podium"]["kept_m2"] == 120.0  # the storeys stand on it: all of it
    assert report["summary"]["trimmed"] == 2
    storeys = _model(folder, "storeys").bounds
    assert _top(_model(folder, "podium")) == pytest.approx(6.0, abs=1e-3)  # 2 levels of 3 m
    assert storeys[0][1] == pytest.approx(6.0 - 0.01, abs=1e-3)  # on the podium's roof
    assert _entry(report, "storeys")["party_walls"] == 0  # walls above the podium's
    assert _entry(report, "storeys")["facades"] == 4
    assert _entry(report, "podium")["party_walls"] == 0


def test_outline_rest_keeps_what_no_part_stands_in() -> None:
    outline = Polygon(_box(0, 0, 20, 10))
    ground = Polygon(_box(0, 0, 10, 10))
    assert outline_rest(outline, 9.0, [(ground, 0.0)])[0].area == pytest.approx(100.0)
    both = [(ground, 0.0), (Polygon(_box(10.3, 0, 9.7, 10)), 0.0)]  # drawn 30 cm apart
    assert outline_rest(outline, 9.0, both) == []  # the strip between them is a gap
    on_top = Polygon(_box(5, 2, 10, 6))
    assert outline_rest(outline, 9.0, [(on_top, 9.0)]) == [outline]  # upper storeys
    arcade = [(on_top, 3.0)]  # lifted, but inside the outline's walls: an overhang
    assert outline_rest(outline, 9.0, arcade)[0].area == pytest.approx(200.0 - 60.0)
    rest = outline_rest(outline, 9.0, [(Polygon(_box(8, 3, 4, 4)), 0.0)])[0]
    assert len(rest.interiors) == 1 and rest.exterior.is_ccw  # a courtyard where it stood


def test_colour_tags_colour_walls_and_roof(district: tuple[Path, dict[str, Any]]) -> None:
    folder, _ = district
    document = json.loads(_json_chunk(folder / "out" / building_file("tower")))
    colours = {
        m["name"]: m["pbrMetallicRoughness"]["baseColorFactor"] for m in document["materials"]
    }
    assert colours["flat_roof"][:3] == pytest.approx([1.0, 1.0, 1.0])  # a drawn deck:
    glb = folder / "out" / building_file("tower")  # its pictures are in the run's textures/
    resolver = trimesh.resolvers.FilePathResolver(glb, allow_anywhere=True)
    scene = trimesh.load(glb, force="scene", resolver=resolver)
    deck = next(
        g.visual.material for name, g in scene.geometry.items() if name.endswith("/flat_roof")
    )
    drawn = np.asarray(deck.baseColorTexture.convert("RGB"), dtype=float).reshape(-1, 3)
    # the colour is in it: its hue, and about its lightness (the tower's covering is gravel,
    # whose shadowed gaps between the stones darken the mean: 228 of 255)
    red, green, blue = drawn.mean(axis=0)
    assert red < 24 and blue < 24 and green > 200
    assert colours["render"][:3] == pytest.approx([1.0, 0.0, 0.0])  # the façade's wall too
    assert colours["glass"][:3] != pytest.approx([1.0, 0.0, 0.0])  # not the windows


def _json_chunk(path: Path) -> bytes:
    data = path.read_bytes()
    length = int.from_bytes(data[12:16], "little")
    return data[20 : 20 + length]


def test_party_walls_of_a_terrace_are_blind(district: tuple[Path, dict[str, Any]]) -> None:
    _, report = district
    assert [_entry(report, t)["party_walls"] for t in ("t1", "t2", "t3")] == [1, 2, 1]
    assert _entry(report, "t2")["facades"] == 2  # street and garden only
    # the tower and the low part share a wall too: the low part's is blind; the tower
    # (15 m) stands free above the low part (6 m, under half its height): a façade
    assert _entry(report, "low")["party_walls"] == 1
    assert _entry(report, "tower")["party_walls"] == 0
    # and the hall and the rest of the station's outline
    assert report["summary"]["party_walls"] == 1 + 2 + 1 + 1 + 1 + 1


def test_heights_from_any_property_with_a_scale(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    assert _entry(report, "dataset")["height"] == pytest.approx(18.0)
    assert _top(_model(folder, "dataset")) == pytest.approx(18.0, abs=1e-3)


def test_colours_spec_keeps_the_spec_materials(tmp_path: Path) -> None:
    _run(tmp_path, "rules:\n  - when: {building:part: 'yes'}\n    colours: spec\n")
    document = json.loads(_json_chunk(tmp_path / "out" / building_file("tower")))
    colours = {
        m["name"]: m["pbrMetallicRoughness"]["baseColorFactor"] for m in document["materials"]
    }
    assert colours["render"][:3] != pytest.approx([1.0, 0.0, 0.0])


def test_a_spec_material_named_wall_is_used_for_plain_walls(tmp_path: Path) -> None:
    (tmp_path / "plain.yaml").write_text(
        SPEC.replace(
            'render: {color: "#e0d8c8"}', 'render: {color: "#e0d8c8"}\n  wall: {color: "#123456"}'
        )
    )
    data = {
        "type": "FeatureCollection",
        "features": [_feature("a", _box(0, 0, 1.5, 1.5))],
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
    }
    (tmp_path / "tags.geojson").write_text(json.dumps(data))
    (tmp_path / "tags.yaml").write_text(MANIFEST.format(extra=""))
    run_city(load_city(tmp_path / "tags.yaml"), tmp_path / "out")
    document = json.loads(_json_chunk(tmp_path / "out" / building_file("a")))
    wall = next(m for m in document["materials"] if m["name"] == "wall")
    expected = [c / 255 for c in linear_rgb("#123456")]  # glTF's factor is linear light
    assert wall["pbrMetallicRoughness"]["baseColorFactor"][:3] == pytest.approx(expected, abs=0.01)


def test_the_roof_is_lowered_to_leave_a_wall() -> None:
    part = Polygon(_box(0, 0, 10, 10))
    tall = volume(
        part, Heights(top=5.0, eaves=None, base=0.0, roof=8.0, default=9.0), Roof(type="gable")
    )
    assert tall.eaves == pytest.approx(0.5) and tall.top == pytest.approx(5.0)
    wide = volume(
        Polygon(_box(0, 0, 40, 30)), Heights(9.0, None, 0.0, None, 9.0), Roof(type="gable")
    )  # its pitch would make the roof 8.7 m high: half the building at most
    assert (wide.eaves, wide.top) == pytest.approx((4.5, 9.0))
    levels = volume(
        Polygon(_box(0, 0, 40, 30)), Heights(None, 6.0, 0.0, None, 9.0), Roof(type="gable")
    )  # under 2 levels of 3 m: the walls stay 6 m, the roof half the building, 6 m
    assert (levels.eaves, levels.top) == pytest.approx((6.0, 12.0))
    flat = volume(part, Heights(None, None, 0.0, None, 9.0), Roof(type="flat"))
    assert (flat.eaves, flat.roof.type) == (9.0, "flat")


def test_a_tagged_roof_lifts_the_default_top_of_a_lifted_part() -> None:
    dome = volume(
        Polygon(_box(0, 0, 4, 4)),
        Heights(top=None, eaves=None, base=18.0, roof=5.0, default=12.0),
        Roof(type="dome"),
    )  # a dome drawn as a part of its own above a tower: min_height and roof:height
    assert (dome.base, dome.eaves, dome.top) == pytest.approx((18.0, 18.5, 23.5))
    assert dome.roof.type == "dome"


def test_tags_read_as_osm_writes_them() -> None:
    heights = tagged_heights(
        {"height": "15 m", "building:levels": "4", "building:min_level": "1"}, 3.0, 9.0
    )
    assert (heights.top, heights.eaves, heights.base, heights.roof) == (15.0, 12.0, 3.0, 3.0)
    assert colour("#ABC") == "#aabbcc" and colour("Light Grey") == "#d3d3d3"
    assert colour("no such colour") is None
    assert compass("SW") == 225.0 and compass("90") == 90.0 and compass(None) is None


def test_shared_edges_and_replaced_outlines_are_found() -> None:
    def footprint(fid: str, ring: list[tuple[float, float]], **tags: Any) -> Footprint:
        return Footprint(fid, (Polygon(ring),), tags)

    a = footprint("a", _box(0, 0, 5, 5))
    b = footprint("b", _box(5.1, 0, 5, 5))  # 10 cm apart: still a party wall
    c = footprint("c", _box(20, 0, 5, 5))
    shared = shared_edges([a, b, c], 0.3)
    assert set(shared) == {"a", "b"}
    assert blind((5, 0), (5, 5), shared["a"], 0.3)  # the wall facing b
    assert not blind((0, 0), (5, 0), shared["a"], 0.3)  # a street wall, 0.2 m of it near b
    outline = footprint("o", _box(0, 0, 10, 10), building="yes")
    part = footprint("p", _box(1, 1, 3, 3), **{"building:part": "yes"})
    other = footprint("q", _box(30, 30, 3, 3), **{"building:part": "yes"})
    assert replaced_outlines([outline, part, other]) == {"o": ["p"]}
    assert blind((5.1, 5), (5.1, 0), shared["b"], 0.3)


@pytest.mark.parametrize("seed", range(6))
def test_a_part_standing_in_a_lower_one_starts_at_its_eaves(seed: int) -> None:
    """Any part over any other, by their heights: the taller, most of it inside, starts
    where the lower one's walls stop; one beside it, one lifted above that already, and
    one no taller, stay as they are."""
    rng = np.random.default_rng(seed)
    x, y = rng.uniform(0, 50, 2)
    w, d = rng.uniform(20, 40, 2)
    podium_top, roof = float(rng.uniform(6, 15)), float(rng.choice([0.0, 2.0]))
    tower_top = podium_top + float(rng.uniform(3, 40))
    tags = {"height": str(podium_top), "roof:height": str(roof)}
    shape = Roof(type="hip" if roof else "flat")
    found = [
        Footprint("podium", (Polygon(_box(x, y, w, d)),), tags),
        Footprint("tower", (Polygon(_box(x + 2, y + 2, w / 3, d / 3)),), {}),
        Footprint("half", (Polygon(_box(x + w - 2, y + 2, 6, 6)),), {}),  # mostly beside
        Footprint("high", (Polygon(_box(x + w / 2, y + d / 2, 4, 4)),), {}),
        Footprint("low", (Polygon(_box(x + 2, y + d - 6, 4, 4)),), {}),
    ]
    heights = {
        "podium": tagged_heights(tags, 3.0, 9.0),
        "tower": tagged_heights({"height": str(tower_top)}, 3.0, 9.0),
        "half": tagged_heights({"height": str(tower_top)}, 3.0, 9.0),
        "high": tagged_heights({"height": str(tower_top), "min_height": "20"}, 3.0, 9.0),
        "low": tagged_heights({"height": str(podium_top - 1)}, 3.0, 9.0),
    }
    roofs = {key: shape if key == "podium" else Roof() for key in heights}
    raised = lifted(found, heights, roofs)
    eaves = volume(found[0].parts[0], heights["podium"], shape).eaves
    assert eaves == pytest.approx(podium_top - roof)
    assert {key: h.base for key, h in raised.items()} == pytest.approx({"tower": eaves})
    assert raised["tower"].top == heights["tower"].top  # the top stays where it was


def test_walls_are_front_back_and_sides() -> None:
    from facadecli.city.sides import facing, sides

    ring = _box(0, 0, 12, 8)  # counter-clockwise: south, east, north, west walls
    walls = [(ring[i], ring[(i + 1) % 4], False) for i in range(4)]
    assert [facing(a, b) for a, b, _ in walls] == pytest.approx([180.0, 90.0, 0.0, 270.0])
    assert sides(walls) == ["front", "side", "back", "side"]
    walls[0] = (*walls[0][:2], True)  # the south wall along a neighbour
    assert sides(walls) == ["party", "front", "side", "back"]  # not parallel to it
    walls[0], walls[1] = (*walls[0][:2], False), (*walls[1][:2], True)  # a terrace's end
    assert sides(walls) == ["front", "party", "back", "side"]  # the long end wall: a side


def test_a_wall_rule_gives_some_walls_another_facade(tmp_path: Path) -> None:
    blank = SPEC.replace("name: plain", "name: blank").replace("#e0d8c8", "#224466")
    blank = blank.replace("render:", "blank_render:").replace(
        "material: render", "material: blank_render"
    )
    (tmp_path / "blank.yaml").write_text(blank)
    rule = (
        "rules:\n  - when: {building: terrace}\n    walls:\n"
        "      - {side: side, facade: blank.yaml}\n"
    )
    report = _run(tmp_path, rule)
    assert _entry(report, "t1")["facades"] == 3
    ends = _model(tmp_path, "t1").geometry
    middle = _model(tmp_path, "t2").geometry
    assert "t1/blank_render" in ends  # its end wall is a side: the blank façade
    assert "t2/blank_render" not in middle  # front and back only: the building's own
    assert "gabled/blank_render" not in _model(tmp_path, "gabled").geometry  # no rule


def test_a_wall_rule_picks_walls_by_the_way_they_face_and_their_length(tmp_path: Path) -> None:
    blank = SPEC.replace("name: plain", "name: blank").replace("render", "blank_render")
    (tmp_path / "blank.yaml").write_text(blank)
    rule = (
        "rules:\n  - when: {building: house}\n    walls:\n"
        "      - {facing: {min: 170, max: 190}, length: {min: 10}, facade: blank.yaml}\n"
    )
    _run(tmp_path, rule)
    scene = _model(tmp_path, "gabled")  # 12 x 8 m: the south wall is 12 m long
    low, high = scene.geometry["gabled/blank_render"].bounds
    assert (low[2], high[2]) == pytest.approx((0.0, 0.0), abs=0.35)  # on the south wall (z=0)
    assert (low[0], high[0]) == pytest.approx((0.0, 12.0), abs=0.01)


def test_outside_corners_get_a_corner_post() -> None:
    from facadecli.city.building import _corner_posts

    ell = [(0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (5.0, 6.0), (5.0, 10.0), (0.0, 10.0)]
    ends, starts = [], {}
    for a, b in zip(ell, ell[1:] + ell[:1], strict=True):
        length = float(np.hypot(b[0] - a[0], b[1] - a[1]))
        starts[a] = (((b[0] - a[0]) / length, (b[1] - a[1]) / length), 0.25, "render")
        ends.append((a, b, 0.25))
    posts = list(_corner_posts(starts, ends, 2.0, 9.0))
    assert len(posts) == 5  # six corners, one of them inside
    corner = next(p for _, p in posts if p.bounds[0][0] > 9.9 and p.bounds[0][2] > -0.1)
    # the corner at map (10, 0): a 25 cm post out east and south (world z is map -y)
    assert corner.bounds.flatten().tolist() == pytest.approx([10.0, 2.0, 0.0, 10.25, 11.0, 0.25])
    assert all(name == "render" for name, _ in posts)


VARIED = SPEC.replace(
    'patterns: {x: "E (W E)^n", y: "F^f"}', 'patterns: {x: "E (W E)^n | E (V E)^n", y: "F^f"}'
)
VARIED = VARIED.replace(
    "symbols: {E: 1.0, W: 1.2, F: 3.0}", "symbols: {E: 1.0, W: 1.2, V: 1.2, F: 3.0}"
)
VARIED = VARIED.replace(
    "shapes: [{match: {x: W}, material: glass, depth: -0.1, thickness: 0.02}]",
    "shapes: [{match: {x: W}, material: glass, depth: -0.1, thickness: 0.02},"
    " {match: {x: V}, material: shutters, depth: 0.05, thickness: 0.05}]",
)
VARIED = VARIED.replace("  glass:", '  shutters: {color: "#3f6b4a"}\n  glass:')


def _varied(tmp_path: Path, seed: int) -> dict[str, Any]:
    tmp_path.mkdir(parents=True, exist_ok=True)
    (tmp_path / "plain.yaml").write_text(VARIED)
    row = [_feature(f"h{i}", _box(i * 20, 0, 10, 8), building="house") for i in range(8)]
    data = {
        "type": "FeatureCollection",
        "features": row,
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}},
    }
    (tmp_path / "tags.geojson").write_text(json.dumps(data))
    extra = (
        f"seed: {seed}\nrules:\n  - when: {{building: house}}\n    variants: 2\n"
        '    palette: ["#ff0000", "#00ff00", "#0000ff"]\n'
    )
    (tmp_path / "tags.yaml").write_text(MANIFEST.format(extra=extra))
    return run_city(load_city(tmp_path / "tags.yaml"), tmp_path / "out")


def _looks(tmp_path: Path, fid: str) -> tuple[tuple[float, ...], bool]:
    document = json.loads(_json_chunk(tmp_path / "out" / building_file(fid)))
    colours = {
        m["name"]: m["pbrMetallicRoughness"]["baseColorFactor"] for m in document["materials"]
    }
    return tuple(round(c, 3) for c in colours["render"][:3]), "shutters" in colours


def test_a_seed_varies_layouts_and_colours_per_building(tmp_path: Path) -> None:
    _varied(tmp_path / "a", 0)
    first = [_looks(tmp_path / "a", f"h{i}") for i in range(8)]
    assert {colour for colour, _ in first} <= {(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)}
    assert len({colour for colour, _ in first}) >= 2  # eight identical houses, not alike
    assert len({shutters for _, shutters in first}) == 2  # both layouts of the alternation
    _varied(tmp_path / "b", 0)
    for i in range(8):  # the same seed: the same files
        a = (tmp_path / "a" / "out" / building_file(f"h{i}")).read_bytes()
        assert a == (tmp_path / "b" / "out" / building_file(f"h{i}")).read_bytes()
    _varied(tmp_path / "c", 1)
    assert [_looks(tmp_path / "c", f"h{i}") for i in range(8)] != first  # another seed


def test_a_city_in_tiles(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    report = _run(tmp_path, "tiles: 50\n")
    index = json.loads((tmp_path / "out" / "tags.tiles.json").read_text())
    assert report["models"] == {
        "merged": "tags.glb",
        "tiles": "tags.tiles.json",
        "georef": "tags.georef.json",
    }
    assert sum(t["buildings"] for t in index["tiles"]) == report["summary"]["ok"]
    names = {(t["column"], t["row"]) for t in index["tiles"]}
    assert names == {(0, 0), (1, 0)}  # centroids at x 4-85 m, y 4-45 m: two 50 m tiles
    first = trimesh.load(tmp_path / "out" / index["tiles"][0]["file"], force="scene")
    assert len(first.graph.nodes_geometry) > 0
    assert index["tiles"][0]["bounds_crs"][:2] == [100000.0, 400000.0]
    # a district too big for one glb: tiles only
    import facadecli.city.tiles as tiles

    monkeypatch.setattr(tiles, "MERGED_GLB_MAX", 1000)
    (tmp_path / "big").mkdir()
    report = _run(tmp_path / "big", "")
    why = report["models"]["merged_left_out"]
    assert why.startswith("the buildings' models hold ") and "MERGED_GLB_MAX" in why
    assert report["models"] == {
        "merged": None,
        "merged_left_out": why,
        "tiles": "tags.tiles.json",
        "georef": "tags.georef.json",
    }
    assert not (tmp_path / "big" / "out" / "tags.glb").exists()


def test_the_report_grows_as_buildings_end(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    lines = (folder / "out" / "tags.report.jsonl").read_text().splitlines()
    assert sorted(json.loads(line)["id"] for line in lines) == sorted(
        b["id"] for b in report["buildings"]
    )


def test_a_bounded_stream_of_tasks_gives_the_same_files(
    district: tuple[Path, dict[str, Any]], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import facadecli.city.run as run

    folder, _ = district
    monkeypatch.setattr(run, "IN_FLIGHT", 1)  # one chunk at a time
    for name in ("plain.yaml", "tags.geojson", "tags.yaml"):
        (tmp_path / name).write_bytes((folder / name).read_bytes())
    run_city(load_city(tmp_path / "tags.yaml"), tmp_path / "out", jobs=2)
    for built in sorted((folder / "out" / "buildings").glob("*/*.glb")):
        path = built.relative_to(folder / "out")
        assert built.read_bytes() == (tmp_path / "out" / path).read_bytes()


def _outlines(rng: random.Random) -> Polygon:
    """A rectangle or an L, 4 to 30 m across."""
    w, d = rng.uniform(4.0, 30.0), rng.uniform(4.0, 25.0)
    if rng.random() < 0.5:
        return Polygon(_box(0, 0, w, d))
    return Polygon([(0, 0), (w, 0), (w, d / 2), (w / 2, d / 2), (w / 2, d), (0, d)])


def test_a_guessed_roof_leaves_the_walls_a_storey_and_a_tagged_one_keeps_its_share() -> None:
    """Over generated footprints, heights, floor heights and roofs: a roof the manifest
    guesses (no ``roof:shape``, no roof height: ``storey`` set) leaves the walls at least
    a storey, or all the building below a storey and MIN_ROOF, under a flat roof; a
    pitched roof below MIN_ROOF is flat. A roof the tags shape is as before: at most
    ROOF_SHARE of the building. Delft's one-storey buildings (2.8-3.2 m, no roof tags)
    had walls of 1.4-1.6 m under a hipped roof as high."""
    rng = random.Random(35)
    flat = low = 0
    for _ in range(400):
        part = _outlines(rng)
        storey = rng.choice((2.7, 3.0, 3.2))
        top = rng.uniform(2.4, 12.0)
        roof = Roof(
            type=rng.choice(("hip", "gable", "pyramidal", "half_hip")), pitch=rng.uniform(20, 50)
        )
        guessed = volume(part, Heights(top, None, 0.0, None, 9.0, storey), roof)
        tagged = volume(part, Heights(top, None, 0.0, None, 9.0), roof)
        assert guessed.top == pytest.approx(top) and tagged.top == pytest.approx(top)
        assert guessed.eaves >= min(storey, top) - 1e-9, (top, storey, guessed.eaves)
        rise = guessed.top - guessed.eaves
        assert guessed.roof.type == "flat" or rise >= MIN_ROOF - 1e-9, (top, storey, rise)
        assert tagged.top - tagged.eaves <= ROOF_SHARE * top + 1e-9
        assert guessed.eaves >= tagged.eaves - 1e-9  # a guess never takes more wall
        flat += guessed.roof.type == "flat"
        low += top < storey + MIN_ROOF
        if top < storey + MIN_ROOF:
            assert guessed.roof.type == "flat" and guessed.eaves == pytest.approx(top)
    assert flat >= low > 20  # the family has low buildings, and they are flat


def test_a_low_building_without_roof_tags_has_a_flat_roof_and_a_shaped_one_keeps_it(
    tmp_path: Path,
) -> None:
    """In a city without a manifest (a hipped roof by default), a 3 m building without
    roof tags is flat on 3 m of wall; one tagged ``roof:shape=gabled`` keeps its gable; a
    5 m one keeps a storey (3 m) of wall under its hipped roof."""
    from facadecli.city.building import party_volumes
    from facadecli.city.default import default_city
    from facadecli.city.run import planned

    features = [
        {
            "type": "Feature",
            "id": ident,
            "properties": tags,
            "geometry": {
                "type": "Polygon",
                "coordinates": [[[85000 + x, 447000 + y] for x, y in [*ring, ring[0]]]],
            },
        }
        for ident, ring, tags in [
            ("low", _box(0, 0, 8, 10), {"building": "yes", "height": 3.0}),
            (
                "gabled",
                _box(20, 0, 8, 10),
                {"building": "yes", "height": 3.0, "roof:shape": "gabled"},
            ),
            ("five", _box(40, 0, 8, 10), {"building": "yes", "height": 5.0}),
        ]
    ]
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}
    path = tmp_path / "low.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "crs": crs, "features": features}))
    volumes = {
        task.footprint.id: party_volumes(task.footprint, task.heights, task.roof, None, 0.3)[0]
        for task in planned(default_city(path), tmp_path / "plan").tasks
    }
    assert (volumes["low"].eaves, volumes["low"].roof.type) == (3.0, "flat")
    assert volumes["gabled"].roof.type == "gable" and volumes["gabled"].eaves == 1.5
    assert volumes["five"].roof.type == "hip"
    assert (volumes["five"].eaves, volumes["five"].top) == pytest.approx((3.0, 5.0))
    report = run_city(default_city(path), tmp_path / "out", jobs=1)
    built = {entry["id"]: entry for entry in report["buildings"]}
    materials = {}
    for ident, entry in built.items():
        document = json.loads(_json_chunk(tmp_path / "out" / entry["file"]))
        materials[ident] = {m["name"] for m in document["materials"]}
    assert "flat_roof" in materials["low"] and "roof" not in materials["low"]
    assert "roof" in materials["gabled"] and "roof" in materials["five"]
