"""Land cover read beside the buildings (facadecli.city.landcover, issue 35): the kinds of
a seeded district's parks, water, woods and car parks, from OSM XML, PBF and GeoJSON
alike; a multipolygon's hole; the clipping to the district; kinds not drawn warned and
counted; ``<name>.ground.geojson`` written georeferenced and the same bytes each run; the
viewer drawing it."""

from __future__ import annotations

import json
import re
import shutil
from html import unescape
from pathlib import Path

import pyproj
import pytest
import shapely
from shapely.geometry import box as rectangle
from shapely.geometry import shape

from facadecli.city.footprints import read_footprints
from facadecli.city.landcover import DISTRICT_MARGIN, cover_kind, is_cover
from tests.browser import BROWSER, browse
from tests.landcover_town import lon_lat, town, write_geojson, write_osm
from tests.running import facade, facade_output

FORMS = ["t.osm", "t.osm.pbf", "t.geojson"]
KINDS = {
    "way/200": "park",
    "relation/300": "water",
    "way/400": "water",
    "way/500": "wood",
    "way/600": "parking",
}


def _written(tmp_path: Path, name: str, seed: int) -> Path:
    district = town(seed)
    path = tmp_path / name
    return write_geojson(path, district) if name.endswith("json") else write_osm(path, district)


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("name", FORMS)
def test_the_kinds_of_a_districts_land_cover_are_read_from_every_form(
    tmp_path: Path, name: str, seed: int
) -> None:
    """Each area of its kind, none taken for a building; the multi-storey car park (a
    building tagged amenity=parking) stays a building; the railway yard is warned, the
    residential land use counted as the town's own."""
    found = read_footprints(_written(tmp_path, name, seed))
    assert {area.id: area.kind for area in found.ground} == KINDS
    houses = len(town(seed).buildings)
    assert len(found.footprints) == houses and "way/150" in {f.id for f in found.footprints}
    assert [(w.id, w.reason.split(" ", 1)[0]) for w in found.ignored] == [("way/700", "landuse")]
    assert found.built_up == 1 and not found.rejected


@pytest.mark.parametrize("name", FORMS)
def test_a_multipolygons_hole_is_kept_and_the_wood_clipped_to_the_district(
    tmp_path: Path, name: str
) -> None:
    """The pond is 2a x a with a 4 m island (a hole); the wood, 400 m long northward, is
    cut at DISTRICT_MARGIN past the buildings; what lies inside keeps its area."""
    district = town(2)
    found = read_footprints(_written(tmp_path, name, 2))
    areas = {area.id: area for area in found.ground}
    pond = areas["relation/300"]
    (part,) = pond.parts
    assert len(part.interiors) == 1
    side = district.cover[1].outer[1][0] - district.cover[1].outer[0][0]  # 2a
    assert part.area == pytest.approx(side * side / 2 - 16, rel=0.01)
    transform = pyproj.Transformer.from_crs(4326, found.crs, always_xy=True).transform
    corners = [lon_lat(point) for point in district.cover[3].outer]
    wood = shapely.Polygon(
        [(x - found.origin[0], y - found.origin[1]) for x, y in (transform(*p) for p in corners)]
    )
    built = shapely.union_all([part for f in found.footprints for part in f.parts]).bounds
    grown = rectangle(*(v + d for v, d in zip(built, (-50, -50, 50, 50), strict=True)))
    expected = wood.intersection(grown).area
    assert DISTRICT_MARGIN == 50
    assert sum(p.area for p in areas["way/500"].parts) == pytest.approx(expected, rel=1e-3)
    assert wood.area > 3 * expected  # most of it was cut off
    top = max(y for p in areas["way/500"].parts for _, y in p.exterior.coords)
    assert top == pytest.approx(built[3] + DISTRICT_MARGIN, abs=0.05)


def test_the_tags_that_make_land_cover() -> None:
    """A building key wins; a polygon of another format than OSM with no cover key, or
    only an amenity or leisure of no kind drawn, is a footprint (exports of buildings
    often carry no building tag); later kinds win (a pond tagged leisure=park is water)."""
    assert not is_cover({"building": "yes", "leisure": "park"})
    assert not is_cover({"measuredHeight": 9.5}) and not is_cover({})
    assert not is_cover({"amenity": "school"}) and not is_cover({"leisure": "sports_centre"})
    assert is_cover({"landuse": "residential"})  # the town's land use, counted
    assert is_cover({"landuse": "railway"}) and cover_kind({"landuse": "railway"}) is None
    assert cover_kind({"leisure": "park", "natural": "water"}) == "water"
    assert cover_kind({"landuse": "residential"}) == "built_up"
    assert cover_kind({"natural": "scrub"}) == "wood"


def _city(capsys: pytest.CaptureFixture[str] | None, source: Path, out: Path) -> dict:
    """The report of ``facade city`` building ``source`` into ``out``, its output taken
    by ``capsys`` (or without it: for the module's fixture)."""
    args = ("city", source, "-o", out, "-j", "1")
    code, said, err = facade(capsys, *args) if capsys else facade_output(*args)
    assert code == 0, err
    assert "landuse 'railway' is not a land cover drawn here: ignored" in err
    assert said.rstrip().endswith(f"{out}/t.report.json, {out}/t.ground.geojson")  # named
    return json.loads((out / "t.report.json").read_text())


@pytest.fixture(scope="module")
def sample_town(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The district of seed 1 (the sample's) as ``t.osm``, built into ``a/``: built once
    for the tests below that read its outputs (each built it before)."""
    folder = tmp_path_factory.mktemp("town")
    _city(None, write_osm(folder / "t.osm", town(1)), folder / "a")
    return folder


def test_a_city_writes_its_land_cover_georeferenced_and_the_same_bytes_each_run(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, sample_town: Path
) -> None:
    """``t.ground.geojson`` beside the models, named in the report's models, counted by
    kind in its summary with the railway yard under ``warnings_by_tag``; its coordinates
    the city's CRS (local metres plus the georeference's origin); the same bytes again."""
    source = sample_town / "t.osm"
    report = json.loads((sample_town / "a" / "t.report.json").read_text())
    assert report["models"]["ground"] == "t.ground.geojson"
    summary = report["summary"]
    assert summary["ground"] == {"wood": 1, "park": 1, "parking": 1, "water": 2, "built_up": 1}
    assert summary["warnings_by_tag"] == {"landuse": 1}
    assert [w["id"] for w in report["warnings"]] == ["way/700"]
    assert report["warnings"][0]["line"] is not None  # its element's line in the XML
    written = (sample_town / "a" / "t.ground.geojson").read_bytes()
    ground = json.loads(written)
    assert ground["crs"]["properties"]["name"] == "urn:ogc:def:crs:" + report["crs"].replace(
        ":", "::"
    )
    assert ground["origin"] == report["origin"]
    kinds = [f["properties"]["kind"] for f in ground["features"]]
    assert kinds == ["wood", "park", "parking", "water", "water"]  # in the order drawn
    found = read_footprints(source)
    local = {a.id: sum(p.area for p in a.parts) for a in found.ground}
    for feature in ground["features"]:
        assert shape(feature["geometry"]).area == pytest.approx(
            local[feature["id"]], rel=1e-3
        )  # to cm
    _city(capsys, source, tmp_path / "b")
    assert (tmp_path / "b" / "t.ground.geojson").read_bytes() == written


def test_a_city_without_land_cover_writes_no_ground_file(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, sample_town: Path
) -> None:
    """Buildings alone: no ground file, an earlier run's removed, no ``ground`` model."""
    district = town(1)
    source = tmp_path / "t.osm"
    shutil.copy(sample_town / "t.osm", source)
    out = tmp_path / "out"
    shutil.copytree(sample_town / "a", out)  # the earlier run's outputs, its ground file
    assert (out / "t.ground.geojson").exists()
    bare = type(district)(district.buildings, [], district.district)
    write_osm(source, bare)
    code, _, err = facade(capsys, "city", source, "-o", out, "-j", "1")
    assert code == 0, err
    report = json.loads((out / "t.report.json").read_text())
    assert "ground" not in report["models"] and report["summary"]["ground"] == {}
    assert not (out / "t.ground.geojson").exists()


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
def test_the_viewer_draws_the_land_cover_with_trees_in_the_wood_and_none_on_water(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, sample_town: Path
) -> None:
    """The page inlines the ground file and draws a mesh for each of its four kinds; the
    wood and the park get their trees; no street tree, dash or lamp of the footprint rules
    stands where land cover is mapped; the river shows as dark water."""
    city = sample_town / "a"
    page = tmp_path / "city.html"
    assert facade(capsys, "view", city, "-o", page)[0] == 0
    assert 'id="glb-0-ground"' in page.read_text()
    _shot, dom = browse(tmp_path, page.as_uri() + "?bare&view=-70,35")
    found = re.search(r'data-cover="([^"]+)"', dom)
    assert found, "the page reports no land cover"
    cover = json.loads(unescape(found.group(1)))
    assert cover["meshes"] == 4 and cover["trees"] > 20, cover
    ground = json.loads(unescape(re.search(r'data-ground="([^"]+)"', dom).group(1)))  # type: ignore[union-attr]
    georef = json.loads((city / "t.georef.json").read_text())
    origin = georef["origin"]
    mapped = shapely.union_all(
        [
            shape(f["geometry"])
            for f in json.loads((city / "t.ground.geojson").read_text())["features"]
        ]
    )
    trees = [shapely.Point(origin[0] + x, origin[1] - z) for x, _, z in ground["trees"]]
    assert trees and not any(mapped.contains(tree) for tree in trees)


def test_the_sample_is_the_district_the_tests_write(tmp_path: Path) -> None:
    """samples/park-town.osm is written by ``python -m tests.landcover_town``, never by
    hand: the same bytes as the district of seed 1."""
    sample = Path(__file__).resolve().parents[1] / "samples" / "park-town.osm"
    assert sample.read_bytes() == write_osm(tmp_path / "p.osm", town(1)).read_bytes()


@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
@pytest.mark.parametrize("seed", [2, 3])
def test_the_land_cover_past_the_buildings_reads_through_the_haze_from_above(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, seed: int
) -> None:
    """Seen from 35° up, the land past the buildings (the picture's band 12-35% from its
    top: the wood north of the district, the river, lawns) keeps its colours: the haze
    began at the district's middle and swallowed the wood 40 m past the buildings (mean
    HSV saturation of the band 14.7% on the sample, 26.5% since it begins at the scene's
    far edge, its land cover's too)."""
    from PIL import Image, ImageStat

    source = write_osm(tmp_path / "t.osm", town(seed))
    _city(capsys, source, tmp_path / "city")
    page = tmp_path / "city.html"
    assert facade(capsys, "view", tmp_path / "city", "-o", page)[0] == 0
    shot, _dom = browse(tmp_path, page.as_uri() + "?bare&view=-70,35")
    with Image.open(shot) as image:
        hsv = image.convert("RGB").convert("HSV")
        band = hsv.crop((0, round(0.12 * hsv.height), hsv.width, round(0.35 * hsv.height)))
        saturation = ImageStat.Stat(band).mean[1] / 255
    assert saturation > 0.2, saturation
