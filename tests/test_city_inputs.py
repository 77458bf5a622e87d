"""``facade city`` on hostile and broken inputs: a feature that cannot be built is rejected
by id and line and the rest is built; a file that is not GeoJSON, duplicate ids or an
unusable output folder are exit 2 with their place, before anything is written."""

from __future__ import annotations

import gc
import itertools
import json
import math
import os
import tracemalloc
from pathlib import Path
from typing import Any

import pytest

from facadecli.city.folders import shard
from facadecli.city.footprints import MAX_VERTICES, read_footprints
from facadecli.city.manifest import load_city
from facadecli.city.run import plan, run_city, safe_name
from tests.running import facade

SPEC = """\
version: 1
name: plain
canvas: {width: 6, height: 6}
symbol_defaults: {opaque: true}
symbols: {A: 1, H: 3}
counters: {n: {min: 1}, m: {min: 1}}
patterns: {x: A^n, y: H^m}
layers: [{name: wall, x: x, y: y}]
"""
MANIFEST = """\
version: 1
name: town
footprints: f.geojson
defaults: {facade: plain.yaml, height: 6, min_facade_width: 2}
"""
RD_NEW = '{"type": "name", "properties": {"name": "EPSG:28992"}}'


def square(fid: str, x: float = 0.0, side: float = 8.0, **properties: object) -> str:
    ring = [[x, 0], [x + side, 0], [x + side, side], [x, side], [x, 0]]
    geometry = {"type": "Polygon", "coordinates": [ring]}
    feature = {"type": "Feature", "id": fid, "properties": properties, "geometry": geometry}
    return json.dumps(feature)


def town(tmp_path: Path, features: list[str]) -> Path:
    """A manifest and its GeoJSON (in metres), one feature a line from line 3 on."""
    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "m.yaml").write_text(MANIFEST)
    head = f'{{"type": "FeatureCollection", "crs": {RD_NEW},'
    text = head + '\n"features": [\n' + ",\n".join(features) + "\n]}\n"
    (tmp_path / "f.geojson").write_text(text)
    return tmp_path / "m.yaml"


def city(capsys: pytest.CaptureFixture[str], manifest: Path, *more: str) -> tuple[int, str, str]:
    return facade(capsys, "city", manifest, "-o", manifest.parent / "out", "-j", "1", *more)


def report(manifest: Path) -> Any:
    return json.loads((manifest.parent / "out" / "town.report.json").read_text())


def polygon(coordinates: str) -> str:
    """Feature 'h' with a Polygon of these coordinates (JSON text: Infinity, NaN allowed)."""
    return feature("{}", f'{{"type": "Polygon", "coordinates": {coordinates}}}')


def feature(properties: str = "{}", geometry: str = "null") -> str:
    return f'{{"type": "Feature", "id": "h", "properties": {properties}, "geometry": {geometry}}}'


TRIANGLE = '{"type": "Polygon", "coordinates": [[[20,0],[28,0],[28,8],[20,0]]]}'
HOSTILE = {  # a feature's JSON text, and what the report says of it
    "null geometry": (feature(), "no geometry (null)"),
    "a number, not a feature": ("42", "not a GeoJSON Feature but a number"),
    "a string, not a feature": ('"h"', "not a GeoJSON Feature but a string"),
    "properties a list": (feature("[1, 2]", TRIANGLE), "'properties' is a list, not an object"),
    "properties a string": (feature('"tall"', TRIANGLE), "'properties' is a string"),
    "unknown geometry type": (feature("{}", '{"type": "Blob"}'), 'unknown geometry type "Blob"'),
    "a point": (
        feature("{}", '{"type": "Point", "coordinates": [1, 2]}'),
        "a Point, not a polygon",
    ),
    "Infinity": (polygon("[[[20,0],[Infinity,0],[28,8],[20,0]]]"), "[Infinity, 0] is not a"),
    "NaN": (polygon("[[[20,0],[NaN,0],[28,8],[20,0]]]"), "[NaN, 0] is not a position"),
    "1e308": (polygon("[[[20,0],[1e308,0],[1e308,1e308],[20,0]]]"), "coordinates beyond"),
    "far away": (polygon("[[[5e6,0],[5.1e6,0],[5.1e6,8],[5e6,0]]]"), "km from the middle"),
    "strings for numbers": (polygon('[[["20","0"],[28,0],[28,8],["20","0"]]]'), "not a position"),
    "booleans for numbers": (polygon("[[[true,0],[28,0],[28,8],[true,0]]]"), "not a position"),
    "a huge integer": (polygon(f"[[[20,0],[{'9' * 400},0],[28,8],[20,0]]]"), "not a position"),
    "two points": (polygon("[[[20,0],[28,0],[20,0]]]"), "fewer than 3 distinct points"),
    "a point repeated": (polygon("[[[20,0],[28,0],[28,0],[20,0]]]"), "fewer than 3 distinct"),
    "null coordinates": (polygon("null"), "not a list of rings"),
    "a sliver": (square("h", x=20, side=0.5), "no part of at least 1 m²"),
}


@pytest.mark.parametrize("hostile", sorted(HOSTILE))
def test_a_feature_that_cannot_be_built_is_rejected_by_id_and_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, hostile: str
) -> None:
    text, reason = HOSTILE[hostile]
    manifest = town(tmp_path, [square("good"), text])
    code, out, err = city(capsys, manifest)
    assert code == 0, err
    assert "1 of 1 buildings built, 1 footprints rejected" in out
    (entry,) = report(manifest)["rejected"]
    fid = "feature-1" if "not a feature" in hostile else "h"
    assert (entry["id"], entry["feature"], entry["line"], entry["column"]) == (fid, 1, 4, 1)
    assert reason in entry["error"]
    assert f"{tmp_path / 'f.geojson'}:4:1: rejected: feature '{fid}': {entry['error']}" in err
    summary = report(manifest)["summary"]
    assert summary == {**summary, "buildings": 1, "ok": 1, "failed": 0, "rejected": 1}
    built = sorted(p.name for p in (tmp_path / "out" / "buildings" / shard("good")).iterdir())
    assert built == ["good.city.jsonl", "good.glb"]
    assert [p.name for p in (tmp_path / "out" / "buildings").iterdir()] == [shard("good")]


NOT_GEOJSON = {
    "not JSON": ('{"type": "FeatureCollection",\n "features": [}\n', (2, 15)),
    "a list": ("[1, 2]", (1, 1)),
    "a bare polygon": ('{"type": "Polygon", "coordinates": []}', (1, 1)),
    "features an object": ('{"type": "FeatureCollection",\n  "features": {}}', (2, 15)),
    "unknown CRS": (
        '{"type": "FeatureCollection",\n "crs": {"type": "name", "properties": '
        '{"name": "EPSG:99999999"}}, "features": []}',
        (2, 9),
    ),
    "CRS a string": ('{"type": "FeatureCollection", "crs": "EPSG:28992", "features": []}', (1, 38)),
    "CRS geocentric": (
        '{"crs": {"properties": {"name": "EPSG:4978"}}, "features": []}',
        (1, 9),
    ),
    "nested too deeply": ("[" * 100_000 + "]" * 100_000, None),
    "not UTF-8": (b'{"features": [\n"\xff"]}', (2, 2)),
    "empty": ("", (1, 1)),
}


@pytest.mark.parametrize("name", sorted(NOT_GEOJSON))
def test_a_file_that_is_not_geojson_is_exit_2_with_its_place(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str
) -> None:
    manifest = town(tmp_path, [])
    text, place = NOT_GEOJSON[name]
    path = tmp_path / "f.geojson"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    code, _, err = city(capsys, manifest)
    assert code == 2
    where = f"{path}:{place[0]}:{place[1]}: error: " if place else f"{path}: error: "
    assert where in err and "(" in err  # a hint in brackets
    assert not (tmp_path / "out").exists()


def test_no_usable_feature_at_all_is_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    manifest = town(
        tmp_path, [HOSTILE["null geometry"][0], HOSTILE["a point"][0].replace('"h"', '"p"')]
    )
    code, _, err = city(capsys, manifest)
    assert code == 2 and "no feature is a usable footprint" in err
    assert f"{tmp_path / 'f.geojson'}:3:1: error: feature 'h' is not a footprint" in err
    assert not (tmp_path / "out").exists()


def test_duplicate_ids_are_exit_2_naming_both_features(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    manifest = town(tmp_path, [square("a"), square("b", x=20), square("a", x=40)])
    code, _, err = city(capsys, manifest)
    assert code == 2
    assert f"{tmp_path / 'f.geojson'}:5:1: error: features[2] has the id 'a' of features[0] " in err
    assert "(line 3)" in err
    assert not (tmp_path / "out").exists()


def test_long_ids_sharing_a_prefix_get_files_of_their_own(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    prefix = "way/" + "7" * 146
    manifest = town(tmp_path, [square(prefix + "1"), square(prefix + "2", x=20)])
    code, _, err = city(capsys, manifest)
    assert code == 0, err
    files = sorted((tmp_path / "out" / "buildings").glob("*/*.glb"))
    assert len(files) == 2 and all(len(f.name) <= 125 for f in files)
    ids = ["way/1", "way_1", "way:1", "Way/1", "WAY/1", "way_1~x", "", ".", prefix, prefix + "x"]
    names = [safe_name(i) for i in ids]
    assert len({n.lower() for n in names}) == len(ids)  # case-insensitive file systems too
    assert all(n and "/" not in n and not n.startswith(".") for n in names)
    assert safe_name("plain-1") == "plain-1"


def dense_rectangle(fid: str, vertices: int) -> str:
    """A 20 x 10 m rectangle with ``vertices`` points along its sides."""
    corners = [(0, 0), (20, 0), (20, 10), (0, 10), (0, 0)]
    per_side = vertices // 4
    ring = [
        [x0 + (x1 - x0) * i / per_side, y0 + (y1 - y0) * i / per_side]
        for (x0, y0), (x1, y1) in itertools.pairwise(corners)
        for i in range(per_side)
    ]
    geometry = {"type": "Polygon", "coordinates": [[*ring, ring[0]]]}
    return json.dumps({"type": "Feature", "id": fid, "properties": {}, "geometry": geometry})


def test_a_dense_footprint_is_simplified_and_gets_its_walls(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    manifest = town(tmp_path, [dense_rectangle("dense", 100_000)])
    code, _, err = city(capsys, manifest)
    assert code == 0, err
    (building,) = report(manifest)["buildings"]
    assert building["facades"] == 4 and building["plain_walls"] == 0
    assert building["simplified"] == {
        "vertices_before": 100_000,
        "vertices_after": 4,
        "tolerance_m": 0.05,
    }


def test_walls_close_even_when_every_edge_is_shorter_than_a_sliver(tmp_path: Path) -> None:
    # under MAX_VERTICES: not simplified; its 7 cm edges merge into walls of at least
    # MIN_EDGE instead of being skipped (they once left a roof on no walls)
    assert MAX_VERTICES >= 900
    ring = [
        [10 * math.cos(i * math.tau / 900), 10 * math.sin(i * math.tau / 900)] for i in range(900)
    ]
    geometry = {"type": "Polygon", "coordinates": [[*ring, ring[0]]]}
    manifest = town(
        tmp_path, [json.dumps({"type": "Feature", "id": "round", "geometry": geometry})]
    )
    text = manifest.read_text().replace("defaults: {", "defaults: {collinear_angle: 0, ")
    manifest.write_text(text)  # every node a corner, as drawn
    report = run_city(load_city(manifest), tmp_path / "out", jobs=1)
    (building,) = report["buildings"]
    assert "simplified" not in building and building["plain_walls"] > 300


def test_a_lone_feature_is_a_city_of_one(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    manifest = town(tmp_path, [])
    (tmp_path / "f.geojson").write_text(square("a", x=85000))  # lon/lat: out of range
    code, _, err = city(capsys, manifest)
    assert code == 2 and f"{tmp_path / 'f.geojson'}:1:1: error: feature 'a'" in err
    (tmp_path / "f.geojson").write_text(square("a", x=5.0, side=0.0001))
    code, out, err = city(capsys, manifest)
    assert code == 0 and out.startswith("1 of 1 buildings built in "), err


def test_rejected_footprints_do_not_fail_the_run_and_limit_counts_buildings(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    features = [square("a"), square("tiny", x=20, side=0.5), square("b", x=40), square("c", x=60)]
    manifest = town(tmp_path, features)
    code, out, _ = city(capsys, manifest, "--limit", "2")
    assert code == 0
    assert out.startswith("2 of 2 buildings built, 1 footprints rejected in ")
    summary = report(manifest)["summary"]
    assert {k: summary[k] for k in ("buildings", "ok", "failed", "rejected")} == {
        "buildings": 2,
        "ok": 2,
        "failed": 0,
        "rejected": 1,
    }


@pytest.mark.parametrize("case", ["a file", "under a file", "not writable", "glb a folder"])
def test_the_output_folder_is_checked_before_any_building(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    case: str,
) -> None:
    manifest = town(tmp_path, [square("a")])
    blocker = tmp_path / "blocker"
    outdir = {"a file": blocker, "under a file": blocker / "out"}.get(case, tmp_path / "out")
    if case in ("a file", "under a file"):
        blocker.write_text("")
    if case == "not writable":
        monkeypatch.setattr(os, "access", lambda path, mode, **kwargs: not mode & os.W_OK)
    if case == "glb a folder":
        (outdir / "town.glb").mkdir(parents=True)
    code, _, err = facade(capsys, "city", manifest, "-o", outdir, "-j", "1")
    assert code == 2 and err.startswith("--output: error: ") and "(" in err, err
    assert not (tmp_path / "out" / "buildings").exists()


def test_workers_get_absolute_paths(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    manifest = town(tmp_path, [square("a")])
    monkeypatch.chdir(tmp_path)
    loaded = load_city(Path("m.yaml"))
    found = read_footprints(loaded.footprints)
    (task,), _ = plan(loaded, list(found.footprints), Path("relative/out"))
    assert task.target == tmp_path / "relative" / "out" / "buildings" / shard("a") / "a.glb"
    assert task.spec_dir == manifest.parent and task.spec_dir.is_absolute()


def test_a_footprints_file_beyond_the_limit_is_refused_before_it_is_read(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from facadecli.city import geojson

    monkeypatch.setattr(geojson, "GEOJSON_BYTES_MAX", 100)
    manifest = town(tmp_path, [square("a"), square("b", x=20)])
    code, _, err = city(capsys, manifest)
    assert code == 2 and "longer than 100 bytes" in err and "f.geojson" in err
    assert not (tmp_path / "out").exists()


def test_a_feature_collection_is_read_one_feature_at_a_time(tmp_path: Path) -> None:
    from facadecli.city.geojson import Features, read_geojson

    features = [square(f"b{i}", x=20 * i) for i in range(3)]
    path = tmp_path / "f.geojson"
    path.write_text('{"type": "FeatureCollection",\n "features": [\n' + ",\n".join(features) + "]}")
    document = read_geojson(path)
    assert isinstance(document.features, Features)  # decoded when read, not all at once
    assert list(document.features) == json.loads(path.read_text())["features"]
    assert document.features[1:] == json.loads(path.read_text())["features"][1:]
    assert document.places.feature(2) == (5, 1)


@pytest.mark.parametrize("chunk", [1, 7, 100])
def test_a_streamed_collection_reads_as_the_whole_text_at_any_cut(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, chunk: int
) -> None:
    """The file is read a chunk at a time (geojson.CHUNK bytes): wherever a chunk ends (in
    a number, a string, a character of several bytes, the BOM, a CR LF), the features,
    the members and every feature's line and column are those of the text read whole."""
    from facadecli.city import geojson

    monkeypatch.setattr(geojson, "CHUNK", chunk)
    features = [square(f"b{i}", x=123.25 * i, name="é ☃ \\u00e9", levels=10**i) for i in range(9)]
    body = ",\r\n  ".join(features[:4]) + ",\n\n" + ", ".join(features[4:])
    text = (
        '{"type": "FeatureCollection", "name": "Liège ☃",\r\n "bbox": [1e2, -3.5, 12345678, 0],'
        f'\n"features": [],\n "crs": {RD_NEW}, "features": [\n  {body} ]\n}}  \n'
    )
    path = tmp_path / "f.geojson"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    document = geojson.read_geojson(path)
    assert isinstance(document.features, geojson.Features)
    assert list(document.features) == json.loads(text)["features"]
    whole = geojson.Places(text)
    places = [document.places.feature(i) for i in range(len(features) + 1)]
    assert places == [whole.feature(i) for i in range(len(features) + 1)]
    assert places[0] == (5, 3) and places[4] == (10, 1) and places[5][0] == 10
    assert places[-1] is None
    assert document.places.member("crs") == whole.member("crs") == (4, 9)
    assert document.crs.to_epsg() == 28992


def test_a_streamed_collection_holds_neither_its_text_nor_its_features(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Reading a FeatureCollection and going through its features holds a window of the
    file and a feature at a time, not the file's text (tracemalloc's peak: 1.3 MB of
    text read whole before, here 16 KiB chunks)."""
    from facadecli.city import geojson

    monkeypatch.setattr(geojson, "CHUNK", 1 << 14, raising=False)
    features = [square(f"b{i}", x=20 * i, building="house", height=9.5) for i in range(6000)]
    path = tmp_path / "f.geojson"
    path.write_text('{"type": "FeatureCollection", "features": [\n' + ",\n".join(features) + "]}")
    size = path.stat().st_size
    count = 0
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    try:
        for _ in geojson.read_geojson(path).features:
            count += 1
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert count == 6000 and size > 1_000_000
    assert peak < size / 8, (peak, size)


def test_a_footprints_file_changed_between_its_two_reads_is_an_error(tmp_path: Path) -> None:
    from facadecli.city.geojson import read_geojson
    from facadecli.errors import SpecError

    path = tmp_path / "f.geojson"
    path.write_text('{"type": "FeatureCollection", "features": [' + square("a") + "]}")
    document = read_geojson(path)
    path.write_text('{"type": "FeatureCollection", "features": [' + square("a", x=100) + "]}  ")
    with pytest.raises(SpecError, match="changed while it was read"):
        list(document.features)


def test_a_bad_value_far_into_a_streamed_file_is_named_at_its_line_and_column(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Past the first chunks, a JSON error is still at its line and column, and a
    feature that is not a footprint is listed at its own."""
    from facadecli.city import geojson

    monkeypatch.setattr(geojson, "CHUNK", 64)
    features = [square(f"b{i}", x=20 * i) for i in range(40)]
    manifest = town(tmp_path, [*features, square("c", x=900).replace("0]]", "0]]]]", 1)])
    code, _, err = city(capsys, manifest)
    assert code == 2 and "f.geojson:43:" in err, err
    assert not (tmp_path / "out").exists()
    manifest = town(tmp_path, [*features, feature('{"building": "yes"}')])
    code, _, _ = city(capsys, manifest)
    rejected = report(manifest)["rejected"]
    assert code == 0 and [(r["line"], r["column"]) for r in rejected] == [(43, 1)], rejected
