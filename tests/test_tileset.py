"""OGC 3D Tiles 1.1 of a city (issue 36 item 2, issue 35 item 5): ``facade city
--3dtiles`` writes a tileset whose structure holds (checked here against the 3D Tiles 1.1
rules that matter to a viewer), whose boxes hold their content, whose errors fall toward
the leaves, which stands where its footprints are on the globe (checked with PROJ, apart
from the code under test), byte for byte the same for the same input, with LOD1 blocks
lighter than LOD2 roofs, lighter than LOD3 façades."""

from __future__ import annotations

import gc
import itertools
import json
import os
import random
import shlex
import shutil
import struct
import subprocess
import tracemalloc
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urljoin

import numpy as np
import pyproj
import pytest

import facadecli.city.tileset as tileset_module
from facadecli.city.default import default_city
from facadecli.city.georef import Georef
from facadecli.city.lods import feature_of, lod_meshes
from facadecli.city.run import run_city
from facadecli.city.tiles import merge_city
from facadecli.city.tileset import TilesetWriter, chosen_lods, parse_lods, quadtree
from facadecli.errors import SpecError
from facadecli.export.glb_merge import read_glb
from tests import cesium
from tests.browser import BROWSER
from tests.osm_district import METRE_LAT, METRE_LON, ORIGIN, Building, box, write_district
from tests.running import facade

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "specs" / "centred-bay.yaml"
ROOFS = ["gabled", "hipped", "flat", "pyramidal", "skillion"]
SMALL = {1: 6, 2: 3, 3: 2}  # buildings a tile of each LOD holds: a deep tree of 10 houses
GEODETIC = pyproj.CRS.from_epsg(4979)
ECEF = pyproj.CRS.from_epsg(4978)


def _houses(count: int, seed: int) -> list[Building]:
    """``count`` detached houses of random sizes and roofs on a jittered 25 m grid."""
    rng = random.Random(seed)
    houses: list[Building] = []
    for k in range(count):
        x, y = 25.0 * (k % 4) + rng.uniform(0, 4), 25.0 * (k // 4) + rng.uniform(0, 4)
        tags = {"building": "house", "building:levels": str(rng.randint(1, 3))}
        tags["roof:shape"] = ROOFS[k % len(ROOFS)]
        houses.append((1000 + k, box(x, y, rng.uniform(8, 14), rng.uniform(7, 10)), tags))
    return houses


def _build(folder: Path, jobs: int, lods: tuple[int, ...] = (1, 2, 3)) -> dict[str, Any]:
    district = write_district(folder.parent / f"{folder.name}.osm", _houses(10, seed=3))
    with pytest.MonkeyPatch.context() as patch:  # a deeper tree than the defaults give
        patch.setattr(tileset_module, "CAPACITY", SMALL)
        return run_city(default_city(district, SPEC), folder, jobs=jobs, lods=lods)


@pytest.fixture(scope="module")
def city(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("tiles") / "out"
    report = _build(folder, jobs=1)
    assert report["summary"]["ok"] == 10
    return folder


def _tiles(tile: dict[str, Any], parent: dict[str, Any] | None = None) -> Iterator[Any]:
    yield tile, parent
    for child in tile.get("children", []):
        yield from _tiles(child, tile)


def _tileset(city: Path) -> dict[str, Any]:
    document: dict[str, Any] = json.loads((city / "3dtiles" / "tileset.json").read_text())
    return document


def _corners(box: list[float]) -> tuple[np.ndarray, np.ndarray]:
    centre, axes = np.array(box[:3]), np.array(box[3:]).reshape(3, 3)
    assert np.allclose(axes, np.diag(np.diag(axes)))  # boxes along the tiles' axes here
    half = np.abs(np.diag(axes))
    return centre - half, centre + half


def _content_bounds(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A glb's bounds from its positions, turned z-up as 3D Tiles turns glTF content."""
    document, _ = read_glb(path.read_bytes())
    accessors = document["accessors"]
    positions = [
        accessors[p["attributes"]["POSITION"]] for m in document["meshes"] for p in m["primitives"]
    ]
    low = np.min([a["min"] for a in positions], axis=0)
    high = np.max([a["max"] for a in positions], axis=0)
    return np.array([low[0], -high[2], low[1]]), np.array([high[0], -low[2], high[1]])


def test_the_tileset_is_3d_tiles_1_1(city: Path) -> None:
    document = _tileset(city)
    assert document["asset"]["version"] == "1.1"
    root = document["root"]
    assert document["geometricError"] == root["geometricError"]
    assert len(root["transform"]) == 16 and root["transform"][15] == 1.0
    uris = []
    for tile, parent in _tiles(root):
        assert set(tile) <= {"transform", "boundingVolume", "geometricError", "refine"} | {
            "content",
            "children",
        }
        assert len(tile["boundingVolume"]["box"]) == 12
        assert tile["geometricError"] >= 0 and tile["refine"] in ("REPLACE", "ADD")
        if parent is not None:
            assert "transform" not in tile
        if "content" in tile:
            uri = tile["content"]["uri"]
            uris.append(uri)
            data = (city / "3dtiles" / uri).read_bytes()
            magic, version, length = struct.unpack_from("<III", data)
            assert (magic, version, length) == (0x46546C67, 2, len(data))  # glTF content
    assert len(uris) == len(set(uris))
    for path in _paths(root):  # from the root to each leaf: each LOD once, coarse to fine
        assert [int(t["content"]["uri"][-5]) for t in path if "content" in t] == [1, 2, 3]
    lod3 = [
        node["name"]
        for uri in uris
        if uri.endswith(".lod3.glb")
        for node in read_glb((city / "3dtiles" / uri).read_bytes())[0]["nodes"]
        if "/" in node["name"] and node["name"].count("/") == 1
    ]
    assert sorted(lod3) == sorted(f"way/{1000 + k}" for k in range(10))  # each house once


def _paths(tile: dict[str, Any]) -> Iterator[list[dict[str, Any]]]:
    if not tile.get("children"):
        yield [tile]
    for child in tile.get("children", []):
        for path in _paths(child):
            yield [tile, *path]


def _leaves(root: dict[str, Any]) -> list[dict[str, Any]]:
    return [t for t, _ in _tiles(root) if not t.get("children")]


def test_levels_of_detail_come_coarse_to_fine_with_falling_errors(city: Path) -> None:
    root = _tileset(city)["root"]
    assert "content" not in root and len(root["children"]) > 1  # a quadtree over the tiles
    levels = set()
    for path in _paths(root):
        errors = [t["geometricError"] for t in path]
        assert errors == sorted(errors, reverse=True)  # never rising toward the leaves
        shown = [i for i, t in enumerate(path) if "content" in t]
        empty_above = path[: shown[0] + 1]  # no content yet: all of it missing
        assert all(
            a["geometricError"] > b["geometricError"] for a, b in itertools.pairwise(empty_above)
        )
        by_lod = {int(path[i]["content"]["uri"][-5]): errors[i] for i in shown}
        assert by_lod[1] > by_lod[2] >= 3.0 > by_lod[3] == 0  # LOD2: at least a storey
        levels.update(path[i]["content"]["uri"].split("/")[0] for i in shown)
    assert len(levels) > 1  # coarse LODs in larger squares than the façades
    for tile, parent in _tiles(root):  # a viewer that refined a tile goes on through empty
        if parent is not None and "content" not in tile and "content" in parent:
            assert tile["geometricError"] == parent["geometricError"]  # ones, to content
    for leaf in _leaves(root):
        assert leaf["geometricError"] == 0 and leaf["content"]["uri"].endswith(".lod3.glb")


def test_boxes_hold_their_content_and_their_children(city: Path) -> None:
    for tile, parent in _tiles(_tileset(city)["root"]):
        low, high = _corners(tile["boundingVolume"]["box"])
        if "content" in tile:
            found_low, found_high = _content_bounds(city / "3dtiles" / tile["content"]["uri"])
            assert np.all(found_low >= low) and np.all(found_high <= high)
            assert np.all(found_high - found_low > 0.5 * (high - low))  # and not much more
        if parent is not None:
            outer_low, outer_high = _corners(parent["boundingVolume"]["box"])
            assert np.all(low >= outer_low - 1e-9) and np.all(high <= outer_high + 1e-9)


def _on_globe(transform: list[float], point: tuple[float, float, float]) -> tuple[float, ...]:
    """A tile-frame point through the root transform: lon, lat, height (PROJ's)."""
    matrix = np.array(transform).reshape(4, 4).T  # column-major
    x, y, z, _ = matrix @ np.array([*point, 1.0])
    to = pyproj.Transformer.from_crs(ECEF, GEODETIC, always_xy=True)
    return tuple(float(v) for v in to.transform(x, y, z))


def test_the_root_transform_puts_the_local_frame_on_the_globe(city: Path) -> None:
    frame = json.loads((city / f"{city.name}.georef.json").read_text())
    transform = _tileset(city)["root"]["transform"]
    utm = pyproj.Transformer.from_crs(frame["crs"], GEODETIC, always_xy=True)
    geod = pyproj.Geod(ellps="WGS84")
    for x, y, z in [(0, 0, 0), (120, 0, 0), (0, 90, 0), (80, 70, 15), (-50, 30, 40)]:
        lon, lat, height = _on_globe(transform, (x, y, z))
        want = utm.transform(frame["origin"][0] + x, frame["origin"][1] + y, 0.0)
        _, _, apart = geod.inv(lon, lat, want[0], want[1])
        assert apart < 0.01  # metres, 150 m from the origin
        assert height == pytest.approx(z, abs=0.01)  # up is up: the Earth's curve is cm


def test_each_house_stands_where_its_footprint_is(city: Path) -> None:
    """A house's LOD1 block, through the y-up to z-up turn and the root transform, is
    where the OSM nodes of its footprint are, and as tall as the block is."""
    transform = _tileset(city)["root"]["transform"]
    houses = {1000 + k: ring for k, (_, ring, _) in enumerate(_houses(10, seed=3))}
    document, binary = read_glb(next((city / "3dtiles").rglob("*.lod1.glb")).read_bytes())
    accessor = document["accessors"][
        document["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    ]
    view = document["bufferViews"][accessor["bufferView"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    points = np.frombuffer(binary, "<f4", accessor["count"] * 3, start).reshape(-1, 3)
    top = points[points[:, 1] == points[:, 1].max()]  # the tallest block's lid
    centre = (top[:, 0].mean(), -top[:, 2].mean(), float(top[0, 1]))
    lon, lat, height = _on_globe(transform, centre)
    nearest = min(
        houses.values(),
        key=lambda ring: (
            abs(np.mean([p[0] for p in ring]) * METRE_LON + ORIGIN[0] - lon)
            + abs(np.mean([p[1] for p in ring]) * METRE_LAT + ORIGIN[1] - lat)
        ),
    )
    want_lon = ORIGIN[0] + np.mean([p[0] for p in nearest]) * METRE_LON
    want_lat = ORIGIN[1] + np.mean([p[1] for p in nearest]) * METRE_LAT
    _, _, apart = pyproj.Geod(ellps="WGS84").inv(lon, lat, want_lon, want_lat)
    assert apart < 0.5  # metres: the district's own degrees-to-metres is approximate
    assert height == pytest.approx(centre[2], abs=0.01) and height > 3.0


def test_lod1_is_lighter_than_lod2_lighter_than_lod3(city: Path) -> None:
    report = json.loads((city / f"{city.name}.report.json").read_text())
    tiles = report["models"]["3dtiles"]
    assert tiles["lods"] == [1, 2, 3]
    triangles = tiles["triangles"]
    assert 0 < triangles["lod1"] < triangles["lod2"] < triangles["lod3"]
    sizes = tiles["bytes"]
    assert sizes["lod1"] < sizes["lod2"] < sizes["lod3"]


def test_the_same_city_gives_the_same_tiles(city: Path, tmp_path: Path) -> None:
    _build(tmp_path / "out", jobs=2)
    ours = sorted(p.relative_to(city) for p in (city / "3dtiles").rglob("*") if p.is_file())
    theirs = sorted(
        p.relative_to(tmp_path / "out") for p in (tmp_path / "out" / "3dtiles").rglob("*")
    )
    assert ours == [p for p in theirs if (tmp_path / "out" / p).is_file()]
    for path in ours:
        assert (city / path).read_bytes() == (tmp_path / "out" / path).read_bytes(), path


def test_tile_content_finds_the_runs_pictures_relative_to_its_uri(city: Path) -> None:
    """A LOD3 tile names the pictures the run stored once (``textures/``) by a URI relative
    to its content's URI, as 3D Tiles resolves it: resolved from the tileset's URL, each
    is a file of the run's ``textures/``; LOD1 and LOD2 tiles draw colours only."""
    folder = city / "3dtiles"
    found = 0
    for tile, _ in _tiles(_tileset(city)["root"]):
        if "content" not in tile:
            continue
        content = urljoin("https://example.org/city/3dtiles/tileset.json", tile["content"]["uri"])
        document, _ = read_glb((folder / tile["content"]["uri"]).read_bytes())
        images = document.get("images", [])
        assert all("bufferView" not in image for image in images)
        if ".lod3." not in tile["content"]["uri"]:
            assert not images
        for image in images:
            url = urljoin(content, image["uri"])
            assert url.startswith("https://example.org/city/textures/"), url
            assert (city / "textures" / url.rsplit("/", 1)[1]).is_file()
            found += 1
    assert found


def test_a_run_chooses_its_levels_of_detail(tmp_path: Path) -> None:
    report = _build(tmp_path / "out", jobs=1, lods=(1, 3))
    assert report["models"]["3dtiles"]["lods"] == [1, 3]
    root = _tileset(tmp_path / "out")["root"]
    uris = [t["content"]["uri"] for t, _ in _tiles(root) if "content" in t]
    assert {uri[-8:] for uri in uris} == {"lod1.glb", "lod3.glb"}
    files = {p.name[-8:] for p in (tmp_path / "out" / "3dtiles").rglob("*.glb")}
    assert files == {"lod1.glb", "lod3.glb"}
    # again with blocks only: the tiles the tileset no longer names are gone
    _build(tmp_path / "out", jobs=1, lods=(1,))
    assert {p.name[-8:] for p in (tmp_path / "out" / "3dtiles").rglob("*.glb")} == {"lod1.glb"}


@pytest.mark.parametrize("text", ["", "0", "4", "1,x", "lod1", "1;2"])
def test_a_bad_lod_list_is_refused(text: str) -> None:
    with pytest.raises(SpecError, match="--lod"):
        parse_lods(text)


def test_lod_lists_are_read_coarse_to_fine() -> None:
    assert parse_lods("3,1") == (1, 3)
    assert parse_lods(" 2 , 2,1 ") == (1, 2)


@pytest.mark.parametrize("seed", range(5))
def test_the_quadtree_holds_every_building_once_in_a_leaf_it_lies_in(seed: int) -> None:
    rng = random.Random(seed)
    spread = rng.choice([5.0, 300.0, 20_000.0])
    points = [(rng.uniform(-spread, spread), rng.uniform(0, spread)) for k in range(300)]
    points += [(1.0, 1.0), (1.0, 1.0)]  # one centroid for two
    capacity = rng.choice([1, 8, 32])
    tree = quadtree(points, capacity)
    assert sorted(tree.order.tolist()) == list(range(len(points)))  # each building once
    leaves = []
    stack = [tree.root]
    while stack:
        square = stack.pop()
        children = list(tree.children(square))
        stack.extend(children)
        assert len(children) <= 4
        assert all(c.level == square.level + 1 and c.column >> 1 == square.column for c in children)
        members = tree.members(square)
        assert members == sorted(members)  # in the run's order
        assert members == sorted(k for child in children for k in tree.members(child)) or (
            not children
        )
        if not children:
            leaves.append(square)
            assert square.count <= capacity or square.level == tileset_module.MAX_LEVEL
    assert sum(leaf.count for leaf in leaves) == len(points)
    for position, point in enumerate(points):  # the leaf found again from its centroid
        *_, leaf = tree.path(point)
        assert position in tree.members(leaf) and not list(tree.children(leaf))
        assert tree.find(leaf.level, leaf.column, leaf.row) == leaf
    *_, twin = tree.path(points[-1])
    assert {len(points) - 2, len(points) - 1} <= set(tree.members(twin))


# Outside tools, where they are installed: the 3D Tiles validator and CesiumJS

VALIDATOR = os.environ.get("FACADE_3DTILES_VALIDATOR")  # e.g. "npx 3d-tiles-validator"


@pytest.mark.skipif(not VALIDATOR, reason="set FACADE_3DTILES_VALIDATOR to a validator command")
def test_the_3d_tiles_validator_finds_nothing(city: Path) -> None:
    tileset = city / "3dtiles" / "tileset.json"
    done = subprocess.run(
        [*shlex.split(str(VALIDATOR)), "--tilesetFile", str(tileset)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    found = json.loads(done.stdout[done.stdout.index("{") :])
    assert (found["numErrors"], found["numWarnings"]) == (0, 0), done.stdout


@pytest.mark.slow
@pytest.mark.skipif(BROWSER is None, reason="no Chromium installed")
@pytest.mark.skipif(
    not cesium.installed(),
    reason="no CesiumJS: make test installs it, or set FACADE_CESIUM to npm cesium's Build/Cesium",
)
def test_cesium_shows_the_tiles_where_the_footprints_are(city: Path, tmp_path: Path) -> None:
    """CesiumJS in headless Chromium loads every tile it needs, with the pictures they
    name in the run's textures/ (served with the run's folder, as a user serves it), and
    flies to the tileset; the centre of the bounding sphere it computed is where PROJ puts
    the root box's centre, within a centimetre, and the picture shows the houses on the
    globe."""
    asked: list[str] = []
    missing: list[str] = []
    shot, dom = cesium.open_tiles(city, tmp_path, asked, missing)
    title = cesium.title(dom)
    assert title.startswith("loaded"), title
    assert [path for path in missing if not path.endswith("favicon.ico")] == []
    pictures = {p.name for p in (city / "textures").glob("*.png")}
    named = set()
    for glb in (city / "3dtiles").rglob("*.lod3.glb"):
        named |= {Path(i["uri"]).name for i in read_glb(glb.read_bytes())[0].get("images", [])}
    assert named and named <= pictures  # the LOD3 tiles name the run's pictures
    fetched = {Path(path).name for path in asked if path.startswith("/run/textures/")}
    assert fetched and fetched <= named  # and CesiumJS fetched them from there
    lon, lat, height = (float(v) for v in title.split()[1:])
    document = _tileset(city)
    low, high = _corners(document["root"]["boundingVolume"]["box"])
    want = _on_globe(document["root"]["transform"], tuple((low + high) / 2))
    _, _, apart = pyproj.Geod(ellps="WGS84").inv(lon, lat, want[0], want[1])
    assert apart < 0.01 and height == pytest.approx(want[2], abs=0.01)
    houses = np.array([p for _, ring, _ in _houses(10, seed=3) for p in ring])
    middle = (houses.min(axis=0) + houses.max(axis=0)) / 2  # metres east, north of ORIGIN
    _, _, off = pyproj.Geod(ellps="WGS84").inv(
        lon, lat, ORIGIN[0] + middle[0] * METRE_LON, ORIGIN[1] + middle[1] * METRE_LAT
    )
    assert off < 1.0  # metres: the footprints' own middle, from the OSM degrees
    from PIL import Image

    with Image.open(shot) as image:
        pixels = np.asarray(image.convert("RGB"), dtype=int)[150:450, 300:700]
    globe = np.array(cesium.GLOBE)
    houses_drawn = int((np.abs(pixels - globe).sum(axis=2) > 40).sum())
    assert houses_drawn > 0.2 * pixels.shape[0] * pixels.shape[1]  # a fifth of the middle


def test_the_command_line_refuses_a_bad_lod_before_any_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    town = ROOT / "samples" / "town.osm"
    code, _, err = facade(capsys, "city", town, "-o", tmp_path / "out", "--3dtiles", "--lod", "4")
    assert code == 2 and "--lod" in err and "1 (blocks)" in err
    code, _, err = facade(capsys, "city", town, "-o", tmp_path / "out", "--lod", "1,3")
    assert code == 2 and "merged glb takes one" in err and "--3dtiles" in err
    assert not (tmp_path / "out").exists()


def test_lod_chooses_the_tiles_levels_and_the_merged_glbs() -> None:
    assert chosen_lods(None, False) == ((), 3)  # the façades, no tiles
    assert chosen_lods("2", False) == ((), 2)
    assert chosen_lods(None, True) == ((1, 2, 3), 3)
    assert chosen_lods("1,2", True) == ((1, 2), 2)  # the merged glb: the finest
    with pytest.raises(SpecError, match="takes one"):
        chosen_lods("1,2", False)


@pytest.mark.parametrize("lod", [1, 2, 3])
def test_the_merged_glb_is_at_the_level_of_detail_asked(city: Path, lod: int) -> None:
    """``--lod`` chooses the merged glb's level: every building under its own node, as
    blocks (the wall material only), walls and roofs, or the buildings' own glb files;
    the coarser levels are the 3D Tiles' own meshes, and the same input gives the same
    bytes."""
    frame = json.loads((city / f"{city.name}.georef.json").read_text())
    georef = Georef(frame["crs"], tuple(frame["origin"][:2]))
    glbs = sorted((city / "buildings").rglob("*.glb"))  # in their shard folders

    def buildings() -> list[tuple[str, Path, tuple[float, float]]]:
        return [(glb.stem, glb, (0.0, 0.0)) for glb in glbs]

    written = [
        merge_city(buildings, city.parent / f"lod{lod}-{k}", "town", None, georef, lod=lod)
        for k in range(2)
    ]
    merged = [city.parent / f"lod{lod}-{k}" / w["merged"] for k, w in enumerate(written)]
    assert merged[0].read_bytes() == merged[1].read_bytes()
    document, _ = read_glb(merged[0].read_bytes())
    scene = document["scenes"][0]
    assert [document["nodes"][n]["name"] for n in scene["nodes"]] == [g.stem for g in glbs]
    materials = {m["name"] for m in document["materials"]}
    triangles = sum(
        document["accessors"][p["indices"]]["count"] // 3
        for mesh in document["meshes"]
        for p in mesh["primitives"]
    )
    if lod == 3:
        assert len(materials) > 2  # the façades' own
        assert triangles == sum(_stored_triangles(glb) for glb in glbs)
    else:
        assert materials == ({"wall"} if lod == 1 else {"wall", "roof"})
        meshes = [lod_meshes(feature_of(glb), lod) for glb in glbs]
        assert triangles == sum(len(m.faces) for found in meshes for m in found.values())


def _stored_triangles(glb: Path) -> int:
    document, _ = read_glb(glb.read_bytes())
    return _stored_triangles_of(document)


def _stored_triangles_of(document: dict[str, Any]) -> int:
    return sum(
        document["accessors"][p["indices"]]["count"] // 3
        for mesh in document["meshes"]
        for p in mesh["primitives"]
    )


def test_a_leaf_is_written_when_its_last_building_is_done(city: Path, tmp_path: Path) -> None:
    """The tiles stream: a leaf's files appear with its last building, before the others
    are done, and tileset.json only at the end."""
    frame = json.loads((city / f"{city.name}.georef.json").read_text())
    georef = Georef(frame["crs"], tuple(frame["origin"][:2]))
    glbs = sorted((city / "buildings").glob("*/*.glb"))
    places = [(100.0 * (k % 2), 0.0) for k, _ in enumerate(glbs)]  # two leaves
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(tileset_module, "CAPACITY", dict.fromkeys((1, 2, 3), len(glbs) // 2))
        writer = TilesetWriter(tmp_path, georef, (1, 2, 3), places)
    east = [(k, glb) for k, glb in enumerate(glbs) if k % 2]
    west = [(k, glb) for k, glb in enumerate(glbs) if not k % 2]
    for k, glb in east[:-1]:
        writer.done(k, glb.stem, glb)
    assert not list((tmp_path / "3dtiles").rglob("*.glb"))
    writer.done(east[-1][0], east[-1][1].stem, east[-1][1])
    assert len(list((tmp_path / "3dtiles").rglob("*.glb"))) == 3  # LOD1, 2, 3 of one leaf
    for k, glb in west[:-1]:
        writer.done(k, glb.stem, glb)
    writer.done(west[-1][0], west[-1][1].stem, None)  # a failed building: left out
    assert len(list((tmp_path / "3dtiles").rglob("*.glb"))) == 6
    assert not (tmp_path / "3dtiles" / "tileset.json").exists()
    summary = writer.close("streamed")
    assert summary["tiles"] == 6 and (tmp_path / "3dtiles" / "tileset.json").is_file()


def test_a_resumed_run_writes_the_same_tiles(city: Path, tmp_path: Path) -> None:
    copy = tmp_path / "out"
    shutil.copytree(city, copy)
    shutil.rmtree(copy / "3dtiles")
    district = city.parent / f"{city.name}.osm"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(tileset_module, "CAPACITY", SMALL)
        report = run_city(default_city(district, SPEC), copy, resume=True, lods=(1, 2, 3))
    assert all(b.get("resumed") for b in report["buildings"])
    for path in sorted((city / "3dtiles").rglob("*")):
        if path.is_file():
            assert path.read_bytes() == (copy / path.relative_to(city)).read_bytes(), path


def test_a_viewer_goes_on_through_empty_squares_to_the_content_below(
    city: Path, tmp_path: Path
) -> None:
    """Blocks and roofs for all ten houses at the root, façades a house a tile: the
    squares between have no content, and each takes the error of the tile above with
    content, or a viewer would stop refining at them and show nothing there."""
    frame = json.loads((city / f"{city.name}.georef.json").read_text())
    georef = Georef(frame["crs"], tuple(frame["origin"][:2]))
    glbs = sorted((city / "buildings").glob("*/*.glb"))
    places = [(37.0 * k % 100, 11.0 * k) for k, _ in enumerate(glbs)]
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(tileset_module, "CAPACITY", {1: 10, 2: 10, 3: 1})
        writer = TilesetWriter(tmp_path, georef, (1, 2, 3), places)
    for k, glb in enumerate(glbs):
        writer.done(k, glb.stem, glb)
    writer.close("deep")
    root = _tileset(tmp_path)["root"]
    assert root["content"]["uri"].endswith("lod1.glb")
    lod2 = root["children"][0]
    empty = 0
    for path in _paths(root):
        for above, tile in itertools.pairwise(path):
            if "content" not in tile:
                empty += 1
                assert tile["geometricError"] == lod2["geometricError"] > 0
            assert tile["geometricError"] <= above["geometricError"]
    assert empty > 0


@pytest.mark.parametrize("lod", [1, 2])
def test_a_coarser_run_solves_no_facade_and_gives_the_same_models(
    city: Path, tmp_path: Path, lod: int
) -> None:
    """``--lod 1`` or ``2`` alone needs no façade: no axis is solved (the solver raises
    here), yet each building's CityJSON feature, the city's CityJSON and the merged glb
    are those a full run makes of the same buildings at that level; each building's glb
    is that level's (the merged glb's part), and a full run resumed over it rebuilds."""
    name = city.name  # the district's, as the full run's fixture names it
    district = write_district(tmp_path / f"{name}.osm", _houses(10, seed=3))

    def refuse(*_: Any, **__: Any) -> Any:
        raise AssertionError("a coarser run solved an axis")

    out = tmp_path / "coarse"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("facadecli.city.building.solve_axis_alternatives", refuse)
        report = run_city(default_city(district, SPEC), out, merged_lod=lod)
    assert report["summary"]["ok"] == 10
    assert all(entry["lod"] == lod and "facades" not in entry for entry in report["buildings"])
    full = sorted((city / "buildings").rglob("*.city.jsonl"))  # beside the full run's glb
    coarse = sorted((out / "buildings").rglob("*.city.jsonl"))
    assert [f.name for f in coarse] == [f.name for f in full]
    assert [f.read_bytes() for f in coarse] == [f.read_bytes() for f in full]
    assert (out / f"{name}.city.json").read_bytes() == (city / f"{name}.city.json").read_bytes()
    document, _ = read_glb((out / f"{name}.glb").read_bytes())
    meshes = [
        lod_meshes(feature_of(f.with_name(f.name.replace(".city.jsonl", ".glb"))), lod)
        for f in full
    ]
    assert _stored_triangles_of(document) == sum(
        len(m.faces) for found in meshes for m in found.values()
    )
    for glb in sorted((out / "buildings").rglob("*.glb")):  # each building at the level
        document, _ = read_glb(glb.read_bytes())
        assert {m["name"] for m in document["materials"]} == (
            {"wall"} if lod == 1 else {"wall", "roof"}
        )
    again = run_city(default_city(district, SPEC), out, resume=True)
    assert not any(entry.get("resumed") for entry in again["buildings"])
    assert all(entry["facades"] >= 0 for entry in again["buildings"])


def _tileset_memory(folder: Path, glb: Path, count: int) -> tuple[int, int]:
    """For ``count`` buildings a tile apiece, on a jittered grid, each built into ``glb``:
    what a :class:`TilesetWriter` holds once every tile is written (Python's live
    allocations made in tileset.py, tracemalloc, the garbage collected: not the
    interpreter's own tables, such as its interned strings, whose one-off growth would
    be counted), and the peak of Python's allocations while ``tileset.json`` is written
    after."""
    rng = random.Random(count)
    places = [(10.0 * (k % 97) + rng.uniform(0, 3), 10.0 * (k // 97)) for k in range(count)]
    gc.collect()
    tracemalloc.start()
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(tileset_module, "CAPACITY", {1: 64, 2: 8, 3: 1})
            writer = TilesetWriter(folder / str(count), georef_of(glb), (3,), places)
        for k in range(count):
            writer.done(k, f"b{k}", glb)
        gc.collect()
        mine = tracemalloc.Filter(True, tileset_module.__file__)
        held = sum(t.size for t in tracemalloc.take_snapshot().filter_traces([mine]).traces)
        tracemalloc.reset_peak()
        start = tracemalloc.get_traced_memory()[0]
        writer.close("memory")
        return held, tracemalloc.get_traced_memory()[1] - start
    finally:
        tracemalloc.stop()


@pytest.fixture(scope="module")
def streamed(city: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[int, Any]:
    """:func:`_tileset_memory` at 300 and 1,200 buildings, and the folder of their outputs."""
    glb = sorted((city / "buildings").glob("*/*.glb"))[0]
    folder = tmp_path_factory.mktemp("streamed")
    return {"folder": folder, **{n: _tileset_memory(folder, glb, n) for n in (300, 1200)}}


def georef_of(glb: Path) -> Georef:
    """The georeference of the run a building's glb belongs to."""
    frame = json.loads(next(glb.parents[2].glob("*.georef.json")).read_text())
    return Georef(frame["crs"], tuple(frame["origin"][:2]))


def test_writing_the_tileset_holds_no_tile_of_it(streamed: dict[int, Any]) -> None:
    """tileset.json is written as it is made: its peak memory barely grows with 4 times
    as many tiles (as one JSON document it held 2.9 KiB a tile: 60 MiB at 100,000
    buildings), and its text is json.dumps' of the same tree, indent of one."""
    small, large = streamed[300][1], streamed[1200][1]
    # 900 tiles more: 2.6 MiB more as one document; the squares' records on disk now
    assert large - small < 256 * 1024, (small, large)
    for count in (300, 1200):
        text = (streamed["folder"] / str(count) / "3dtiles" / "tileset.json").read_text()
        assert text == json.dumps(json.loads(text), indent=1) + "\n"
        assert len(list(_tiles(json.loads(text)["root"]))) > count


def test_the_squares_tiles_are_spilled_to_disk_as_they_are_written(
    streamed: dict[int, Any],
) -> None:
    """While the buildings end, a 3D Tiles writer keeps of each square its place in the
    tree's arrays and its chain and count (42 bytes), not what its tiles leave for
    tileset.json: their boxes and errors go to a record at the square's place in an
    unnamed temporary file (:class:`.SquareRecords`), read back in the tree's order when
    tileset.json is written. What it holds a building more from 300 to 1,200 buildings,
    a tile each, every tile written (tracemalloc, what tileset.py allocated): 69 bytes;
    715 with each square a Python object keeping its tiles' entries and box. No file is
    left beside the tiles."""
    slope = (streamed[1200][0] - streamed[300][0]) / 900
    assert slope < 160, slope
    for count in (300, 1200):
        folder = streamed["folder"] / str(count) / "3dtiles"
        assert {p.name for p in folder.iterdir() if p.is_file()} == {"tileset.json"}
