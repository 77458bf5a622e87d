"""Cities: footprints, manifests, whole buildings, a run (SPEC 5). Small fixtures only."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from facadecli import SpecError
from facadecli.city.demo import district, write_demo
from facadecli.city.footprints import read_footprints
from facadecli.city.manifest import City, Roof, load_city
from facadecli.city.report import CityReport
from facadecli.city.roofs import roof_meshes
from facadecli.city.run import axes_solved_while_building, run_city, safe_name
from facadecli.city.s3db import tagged_heights, volume

ROOT = Path(__file__).resolve().parent.parent


def _geojson(tmp_path: Path, features: list[dict[str, object]], crs: str | None = None) -> Path:
    data: dict[str, object] = {"type": "FeatureCollection", "features": features}
    if crs:
        data["crs"] = {"type": "name", "properties": {"name": crs}}
    path = tmp_path / "f.geojson"
    path.write_text(json.dumps(data))
    return path


def _square(fid: str, x: float, y: float, side: float, **properties: object) -> dict[str, object]:
    ring = [[x, y], [x + side, y], [x + side, y + side], [x, y + side], [x, y]]
    return {
        "type": "Feature",
        "id": fid,
        "properties": properties,
        "geometry": {"type": "Polygon", "coordinates": [ring]},
    }


def test_lon_lat_is_projected_to_metres(tmp_path: Path) -> None:
    # 0.001 degrees of latitude is about 111 m; of longitude at 60 N about 55.8 m
    side = 0.001
    found = read_footprints(_geojson(tmp_path, [_square("way/1", 26.95, 60.52, side)]))
    (part,) = found.footprints[0].parts
    width = part.bounds[2] - part.bounds[0]
    height = part.bounds[3] - part.bounds[1]
    assert width == pytest.approx(111_320 * side * math.cos(math.radians(60.5205)), rel=0.01)
    assert height == pytest.approx(111_200 * side, rel=0.01)
    assert part.exterior.is_ccw


def test_a_projected_crs_is_used_as_it_is(tmp_path: Path) -> None:
    path = _geojson(tmp_path, [_square("a", 85000, 447000, 12.5)], "urn:ogc:def:crs:EPSG::28992")
    found = read_footprints(path)
    assert found.footprints[0].parts[0].area == pytest.approx(156.25)
    assert found.origin == (85000, 447000)


def test_broken_footprints_are_reported_not_raised(tmp_path: Path) -> None:
    bowtie = {
        "type": "Feature",
        "id": "bow",
        "properties": {},
        "geometry": {
            "type": "Polygon",
            "coordinates": [[[0, 0], [10, 10], [10, 0], [0, 10], [0, 0]]],
        },
    }
    sliver = _square("tiny", 50, 50, 0.1)
    point = {
        "type": "Feature",
        "id": "pt",
        "properties": {},
        "geometry": {"type": "Point", "coordinates": [0, 0]},
    }
    broken = {"type": "Feature", "id": "bad", "properties": {}, "geometry": {"type": "Polygon"}}
    found = read_footprints(_geojson(tmp_path, [bowtie, sliver, point, broken], "EPSG:3857"))
    assert [f.id for f in found.footprints] == ["bow"] and found.footprints[0].repaired
    assert {r.id for r in found.rejected} == {"tiny", "pt", "bad"}


@pytest.mark.parametrize(
    ("properties", "height"),
    [
        ({"height": "12.5"}, 12.5),
        ({"measuredHeight": 6}, 6.0),
        ({"building:levels": "2.5"}, 7.5),
        ({"levels": 4}, 12.0),
        ({"building:levels": "3;4"}, 9.0),
        ({}, 9.0),
        ({"height": "tall"}, 9.0),
    ],
)
def test_heights_from_properties(properties: dict[str, object], height: float) -> None:
    part = Polygon([(0, 0), (10, 0), (10, 8), (0, 8)])
    heights = tagged_heights(properties, 3.0, 9.0)
    assert volume(part, heights, Roof(type="flat")).top == pytest.approx(height)


def test_safe_names_never_collide() -> None:
    assert safe_name("way/123") != safe_name("way_123")
    assert "/" not in safe_name("relation/9") and safe_name("plain-1") == "plain-1"


def test_a_manifest_naming_a_missing_or_bad_spec_is_rejected_first(tmp_path: Path) -> None:
    manifest = write_demo(tmp_path / "city", ROOT / "specs", blocks=1)
    text = manifest.read_text().replace("terraced-house.yaml", "missing.yaml")
    manifest.write_text(text)
    with pytest.raises(SpecError) as caught:
        load_city(manifest)
    messages = " ".join(p.message for p in caught.value.problems)
    assert "missing.yaml" in messages
    manifest.write_text(text + "  - when: {building: yes}\n    roof: {type: igloo}\n")
    with pytest.raises(SpecError) as caught:
        load_city(manifest)
    assert "roof.type" in caught.value.problems[0].message
    assert all(p.line for p in caught.value.problems)


def _seen_colour(material: trimesh.visual.material.PBRMaterial) -> np.ndarray:
    """A material's mean base colour, 0-255: its factor times its picture's mean, if any."""
    colour = np.asarray(material.baseColorFactor[:3], dtype=float)
    if material.baseColorTexture is not None:  # a library material: the colour is drawn
        picture = np.asarray(material.baseColorTexture.convert("RGB"), dtype=float)
        colour = colour * picture.reshape(-1, 3).mean(axis=0) / 255.0
    return colour


@pytest.fixture(scope="module")
def one_block(tmp_path_factory: pytest.TempPathFactory) -> tuple[City, Path, CityReport]:
    """The demo district of one block built by two local processes: the city, its outputs'
    folder and the report. The build the test below resumes (in a copy) and the local run
    a Dask cluster's files are compared with: one build for both (each built it)."""
    folder = tmp_path_factory.mktemp("one-block")
    city = load_city(write_demo(folder / "city", ROOT / "specs", blocks=1))
    return city, folder / "local", run_city(city, folder / "local", jobs=2)


def test_a_small_city_builds_and_resumes(
    tmp_path: Path, one_block: tuple[City, Path, CityReport]
) -> None:
    city, local, report = one_block
    out = tmp_path / "out"
    shutil.copytree(local, out)  # resumed here: the module's build stays as it was made
    assert report["summary"] == {**report["summary"], "buildings": 4, "ok": 4, "failed": 0}
    merged = trimesh.load(out / "demo-district.glb", force="scene")
    assert len(list((out / "buildings").glob("*/*.glb"))) == 4  # in their shards
    low, high = merged.bounds
    assert low[1] == pytest.approx(-0.01, abs=1e-3)  # the ground
    assert high[1] >= 9.0  # the tallest building's roof
    looks = [g.visual.material for g in merged.geometry.values()]
    # the recesses behind windows show a room's picture (the specs' `interior: {library:
    # rooms}`), about mid-grey as rooms seen from a daylit street read (134 of 255 now;
    # 118 drew them as dark holes), darker than a pale wall
    interiors = [m for m in looks if m.name == "interior"]
    assert interiors and all(m.baseColorTexture is not None for m in interiors)
    assert all(max(_seen_colour(m)) < 145 for m in interiors)
    written = (out / "demo-district.report.json").read_bytes()
    first = json.loads(written)["buildings"][0]
    assert first["facades"] >= 4 and first["id"] == "way/1000"
    # the times are null in the file (the same bytes every run), kept in the object, and
    # written with --timings
    assert first["time_ms"] is None and json.loads(written)["summary"]["seconds"] is None
    assert report["buildings"][0]["time_ms"] > 0 and report["summary"]["seconds"] > 0
    timed = json.loads("".join(dataclasses.replace(report, timings=True).chunks()))
    assert timed["buildings"][0]["time_ms"] > 0 and timed["summary"]["seconds"] > 0
    again = run_city(city, out, jobs=1, resume=True)
    assert all(b.get("resumed") for b in again["buildings"])
    serial = run_city(city, tmp_path / "serial", jobs=1)
    built = sorted(
        p.relative_to(out)
        for folder in ("buildings", "textures")
        for p in (out / folder).rglob("*")
        if p.is_file()
    )
    assert built and all(
        (out / path).read_bytes() == (tmp_path / "serial" / path).read_bytes() for path in built
    )
    assert serial["summary"]["ok"] == 4
    assert (tmp_path / "serial" / "demo-district.report.json").read_bytes() == written


def test_the_demo_district_is_deterministic() -> None:
    assert district(2, seed=1) == district(2, seed=1)
    assert len(district(2)["features"]) == 16  # type: ignore[arg-type]


def test_a_dask_cluster_gives_the_same_files_as_local_processes(
    tmp_path: Path, one_block: tuple[City, Path, CityReport]
) -> None:
    from distributed import Client

    from tests.dask_cluster import two_workers

    city, local, _ = one_block
    with two_workers() as cluster:
        report = run_city(city, tmp_path / "dask", scheduler=cluster.scheduler_address)
        with Client(cluster) as client:  # the axes came solved ahead: none while building
            assert list(client.run(axes_solved_while_building).values()) == [0, 0]
    assert report["summary"]["ok"] == 4
    assert all(b["facades"] >= 4 for b in report["buildings"])  # they needed axes
    built = sorted(p.relative_to(local) for p in local.rglob("*.glb"))
    assert built == sorted(
        p.relative_to(tmp_path / "dask") for p in (tmp_path / "dask").rglob("*.glb")
    )
    pictures = sorted(p.relative_to(local) for p in local.rglob("*.png"))
    assert pictures == sorted(
        p.relative_to(tmp_path / "dask") for p in (tmp_path / "dask").rglob("*.png")
    )
    for path in built + pictures:
        assert (local / path).read_bytes() == (tmp_path / "dask" / path).read_bytes()


AWKWARD = {
    "rectangle": Polygon([(0, 0), (10, 0), (10, 6), (0, 6)]),
    "concave": Polygon([(0, 0), (10, 0), (10, 10), (5, 4), (0, 10)]),
    "L": Polygon([(0, 0), (10, 0), (10, 4), (4, 4), (4, 10), (0, 10)]),
    "T": Polygon([(0, 0), (12, 0), (12, 4), (8, 4), (8, 10), (4, 10), (4, 4), (0, 4)]),
    "U": Polygon([(0, 0), (12, 0), (12, 10), (8, 10), (8, 4), (4, 4), (4, 10), (0, 10)]),
    "courtyard": Polygon(
        [(0, 0), (20, 0), (20, 20), (0, 20)], [[(5, 5), (5, 15), (15, 15), (15, 5)]]
    ),
}


@pytest.mark.parametrize("kind", ["shed", "gable", "hip"])
@pytest.mark.parametrize("name", sorted(AWKWARD))
def test_sloped_roofs_cover_any_footprint(kind: str, name: str) -> None:
    part = orient(AWKWARD[name], sign=1.0)
    roof, walls = roof_meshes(part, 9.0, Roof(type=kind, pitch=30))
    plan = trimesh.Trimesh(
        np.column_stack([roof.vertices[:, :2], np.zeros(len(roof.vertices))]), roof.faces
    )
    assert plan.area == pytest.approx(part.area, rel=1e-6)  # covered once, no gaps or overlaps
    assert (roof.face_normals[:, 2] > 0).all()  # every face looks up
    assert roof.bounds[0][2] == pytest.approx(9.0, abs=1e-6)  # down to the eaves
    if kind == "hip" or (kind == "gable" and name in ("concave", "courtyard")):
        assert not walls  # at the eaves all round: a hip, or a gable without wing ends
    else:
        assert walls and all(w.bounds[0][2] == pytest.approx(9.0) for w in walls)


def test_roof_heights_follow_the_pitch() -> None:
    rectangle = orient(AWKWARD["rectangle"], sign=1.0)  # 10 x 6 m
    rise = math.tan(math.radians(30))
    assert roof_meshes(rectangle, 9.0, Roof(type="hip"))[0].bounds[1][2] == pytest.approx(
        9 + 3 * rise
    )
    assert roof_meshes(rectangle, 9.0, Roof(type="gable"))[0].bounds[1][2] == pytest.approx(
        9 + 3 * rise
    )
    assert roof_meshes(rectangle, 9.0, Roof(type="shed"))[0].bounds[1][2] == pytest.approx(
        9 + 6 * rise
    )


def test_osm_roof_tags_pick_the_roof(tmp_path: Path) -> None:
    city = load_city(write_demo(tmp_path / "city", ROOT / "specs", blocks=1))
    roof = city.choose({"roof:shape": "hipped", "roof:angle": "40", "building:levels": "3"}).roof
    assert (roof.type, roof.pitch) == ("hip", 40.0)
    assert city.choose({"roof:shape": "skillion"}).roof.type == "shed"
    assert city.choose({"roof:shape": "onion"}).roof.type == "onion"
    assert city.choose({"roof:shape": "igloo"}).roof.type == "gable"  # the manifest's default


def test_broken_geojson_files_are_located(tmp_path: Path) -> None:
    path = tmp_path / "f.geojson"
    path.write_text('{"type": "FeatureCollection",\n "features": [}\n')
    with pytest.raises(SpecError) as caught:
        read_footprints(path)
    assert (caught.value.problems[0].line, caught.value.problems[0].col) == (2, 15)
    path.write_text("[1, 2]")
    with pytest.raises(SpecError, match="FeatureCollection"):
        read_footprints(path)


def test_mesh_files_of_a_spec_are_found_next_to_the_spec(tmp_path: Path) -> None:
    specs = tmp_path / "specs"
    specs.mkdir()
    trimesh.creation.box(extents=(1, 1, 1)).export(specs / "block.obj")
    (specs / "plain.yaml").write_text(
        "version: 1\nname: plain\ncanvas: {width: 6, height: 6}\nsymbol_defaults: {opaque: true}\n"
        "symbols: {A: 1, H: 3}\ncounters: {n: {min: 1}, m: {min: 1}}\npatterns: {x: A^n, y: H^m}\n"
        "layers: [{name: wall, x: x, y: y}]\ndefaults: {mesh: block.obj}\n"
    )
    (tmp_path / "city").mkdir()
    (tmp_path / "city" / "f.geojson").write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "crs": {"type": "name", "properties": {"name": "EPSG:28992"}},
                "features": [_square("a", 0, 0, 8, height=6)],
            }
        )
    )
    (tmp_path / "city" / "m.yaml").write_text(
        "version: 1\nname: m\nfootprints: f.geojson\ndefaults: {facade: ../specs/plain.yaml}\n"
    )
    report = run_city(load_city(tmp_path / "city" / "m.yaml"), tmp_path / "out", jobs=1)
    (building,) = report["buildings"]
    assert building["status"] == "ok" and building["facades"] == 4, building
