"""``facade city`` at its doors, as a hostile user tries them (issue 37): OSM XML with
values libosmium refuses, references to what the file lacks, compressed bombs; numbers
in tags no building has; GeoPackages whose feature table never ends; leftovers of a
killed run. Each ends in a clear exit 2 with its place, or a warning, never an internal
error, and a refused input leaves nothing written."""

from __future__ import annotations

import bz2
import gzip
import json
import os
import sqlite3
from pathlib import Path
from typing import Any

import pytest

from facadecli.city.folders import shard
from facadecli.city.footprints import checked_properties, length
from facadecli.limits import OSM_INFLATION_MAX, OSM_TEXT_CHARS_MAX
from tests.running import facade, files
from tests.test_city_inputs import MANIFEST, SPEC

LON, LAT = 24.94, 60.17
SQUARE = [(LON, LAT), (LON + 0.0002, LAT), (LON + 0.0002, LAT + 0.0001), (LON, LAT + 0.0001)]


def nodes(first: int = 1, square: list[tuple[float, float]] = SQUARE) -> str:
    return "".join(
        f'  <node id="{first + i}" lat="{lat}" lon="{lon}"/>\n'
        for i, (lon, lat) in enumerate(square)
    )


def way(wid: int | str, refs: list[int], **tags: str) -> str:
    text = "".join(f'<nd ref="{r}"/>' for r in refs)
    text += "".join(f'<tag k="{k.replace("_", ":")}" v="{v}"/>' for k, v in tags.items())
    return f'  <way id="{wid}">{text}</way>\n'


def osm(body: str) -> str:
    return f'<?xml version="1.0"?>\n<osm version="0.6">\n{body}</osm>\n'


GOOD = nodes() + way(10, [1, 2, 3, 4, 1], building="yes")
GOOD_FAR = nodes(101, [(x + 0.001, y) for x, y in SQUARE]) + way(
    11, [101, 102, 103, 104, 101], building="yes"
)


def town(tmp_path: Path, name: str, content: str | bytes) -> Path:
    """A manifest naming the footprints file ``name`` holding ``content``."""
    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "m.yaml").write_text(MANIFEST.replace("f.geojson", name))
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return tmp_path / "m.yaml"


def city(capsys: pytest.CaptureFixture[str], manifest: Path) -> tuple[int, str, str]:
    return facade(capsys, "city", manifest, "-o", manifest.parent / "out", "-j", "1")


def report(manifest: Path) -> Any:
    return json.loads((manifest.parent / "out" / "town.report.json").read_text())


REFUSED = {  # an extract's body, and where and what the error says
    "lon nan": (
        nodes().replace('lon="24.9402"', 'lon="nan"', 1) + way(10, [1, 2, 3, 4, 1], building="yes"),
        ":4:3: error: node 2: lon 'nan' is not a longitude",
    ),
    "id int64 max": (
        nodes(9223372036854775804) + way(10, [1], building="yes"),
        ":3:3: error: node 9223372036854775804: id '9223372036854775804' is not an OSM id",
    ),
    "id uint64 max": (
        nodes() + way(18446744073709551615, [1, 2, 3, 4, 1], building="yes"),
        ":7:3: error: way 18446744073709551615: id '18446744073709551615' is not an OSM id",
    ),
    "a reference at int64 max": (
        nodes() + way(10, [1, 2, 9223372036854775807, 1], building="yes"),
        ":7:42: error: a <nd> of way 10: ref '9223372036854775807' is not an OSM id",
    ),
    "a tag of 3,000,000 characters": (
        nodes() + way(10, [1, 2, 3, 4, 1], building="yes", name="x" * 3_000_000),
        f"error: a <tag> of way 10: a tag value of 3,000,000 characters (limit: "
        f"{OSM_TEXT_CHARS_MAX}",
    ),
    "a timestamp": (
        nodes().replace('id="1"', 'id="1" timestamp="yesterday"')
        + way(10, [1, 2, 3, 4, 1], building="yes"),
        ":3:3: error: node 1: timestamp 'yesterday' is not a time",
    ),
    "an element libosmium does not take": (
        nodes() + way(10, [1, 2, 3, 4, 1], building="yes").replace("</way>", "<member/></way>"),
        ":7:108: error: a <member> of way 10: libosmium takes only <nd> and <tag> inside <way>",
    ),
    "ways out of libosmium's order": (
        nodes() + way(-1, [1, 2, 3, 4, 1], building="yes") + way(0, [1, 2, 3, 4, 1]),
        ":8:3: error: way 0 comes after way -1: the extract is not sorted",
    ),
    "not XML": (GOOD.replace("<way", "<way <"), ":7:8: error: not OSM XML: not well-formed"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_osm_xml_libosmium_refuses_is_exit_2_naming_the_element(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, case: str
) -> None:
    body, expected = REFUSED[case]
    manifest = town(tmp_path, "f.osm", osm(body))
    code, _, err = city(capsys, manifest)
    assert code == 2 and expected in err and f"{tmp_path / 'f.osm'}" in err, err
    assert "(" in err  # a hint
    assert not (tmp_path / "out").exists()


def test_osm_references_to_what_is_missing_are_rejected_per_feature(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    relation = (
        '  <relation id="20"><member type="way" ref="77" role="outer"/>'
        '<tag k="type" v="multipolygon"/><tag k="building" v="yes"/></relation>\n'
    )
    missing_node = nodes(201, [(x + 0.002, y) for x, y in SQUARE])
    missing_node += way(12, [201, 202, 203, 99, 201], building="yes")
    manifest = town(tmp_path, "f.osm", osm(GOOD + missing_node + relation))
    code, out, err = city(capsys, manifest)
    assert code == 0, err
    assert "1 of 1 buildings built, 2 footprints rejected" in out
    path = tmp_path / "f.osm"
    assert f"{path}:12:3: rejected: feature 'way/12': node 99 is not in the file" in err
    assert f"{path}:13:3: rejected: feature 'relation/20': its outer way 77 is not in" in err
    assert report(manifest)["summary"]["rejected"] == 2
    # nothing usable left: exit 2, as for GeoJSON
    manifest = town(tmp_path, "f.osm", osm(missing_node + relation))
    code, _, err = city(capsys, manifest)
    assert code == 2 and "no feature is a usable footprint" in err
    assert "feature 'way/12' is not a footprint: node 99 is not in the file" in err


def test_a_pbf_with_a_missing_node_names_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import osmium
    from osmium.osm.mutable import Node, Way

    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "m.yaml").write_text(MANIFEST.replace("f.geojson", "f.osm.pbf"))
    writer = osmium.SimpleWriter(str(tmp_path / "f.osm.pbf"))
    for i, location in enumerate(SQUARE):
        writer.add_node(Node(id=i + 1, location=location))
    writer.add_way(Way(id=10, nodes=[1, 2, 3, 99, 1], tags={"building": "yes"}))
    writer.close()
    code, _, err = city(capsys, tmp_path / "m.yaml")
    assert code == 2 and "feature 'way/10' is not a footprint: node 99 is not in the file" in err


@pytest.mark.parametrize("kind", ["gz", "bz2"])
def test_a_compressed_bomb_is_refused_while_it_inflates(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, kind: str
) -> None:
    compress = gzip.compress if kind == "gz" else bz2.compress
    head = osm(GOOD).removesuffix("</osm>\n").encode()
    bomb = compress(head + b"<!-- " + b" " * 20_000_000 + b" -->\n</osm>\n")
    limit = max(16 * 1024 * 1024, OSM_INFLATION_MAX * len(bomb))
    manifest = town(tmp_path, f"f.osm.{kind}", bomb)
    code, _, err = city(capsys, manifest)
    assert code == 2 and f"the extract inflates to more than {limit:,} bytes" in err, err
    assert not (tmp_path / "out").exists()
    manifest = town(tmp_path, f"f.osm.{kind}", compress(osm(GOOD + GOOD_FAR).encode()))
    code, _, err = city(capsys, manifest)
    assert code == 0, err


def test_a_pbf_bomb_is_refused_from_its_block_headers(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import zlib

    def field(number: int, payload: bytes | int) -> bytes:
        if isinstance(payload, int):
            return bytes([number << 3]) + varint(payload)
        return bytes([number << 3 | 2]) + varint(len(payload)) + payload

    def varint(value: int) -> bytes:
        out = b""
        while value > 0x7F:
            out += bytes([value & 0x7F | 0x80])
            value >>= 7
        return out + bytes([value])

    raw = b"\0" * (32 * 1024 * 1024)
    blob = field(2, len(raw)) + field(3, zlib.compress(raw, 9))
    header = field(1, b"OSMData") + field(3, len(blob))
    block = len(header).to_bytes(4, "big") + header + blob
    manifest = town(tmp_path, "f.osm.pbf", block * 4)
    code, _, err = city(capsys, manifest)
    assert code == 2 and "the extract inflates to more than" in err, err


@pytest.mark.parametrize(
    ("tags", "height", "warnings"),
    [
        ({"roof:levels": "1e9", "roof:shape": "gabled"}, 6.0, ["roof:levels '1e9' is more"]),
        (
            {"height": "1e308", "building:levels": "nan"},
            6.0,
            ["height '1e308' is more than a building's 1000 m", "building:levels 'nan' is not"],
        ),
        ({"height": "40'"}, 12.192, []),
        ({"height": "12'6&quot;"}, 3.81, []),
        ({"height": "-3"}, 6.0, ["height '-3' is below 0: ignored"]),
    ],
)
def test_numbers_from_tags_pass_the_caps_or_are_ignored_with_a_warning(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    tags: dict[str, str],
    height: float,
    warnings: list[str],
) -> None:
    body = nodes() + way(10, [1, 2, 3, 4, 1], building="yes").replace(
        "</way>", "".join(f'<tag k="{k}" v="{v}"/>' for k, v in tags.items()) + "</way>"
    )
    manifest = town(tmp_path, "f.osm", osm(body))
    code, _, err = city(capsys, manifest)
    assert code == 0, err
    built = report(manifest)
    assert built["buildings"][0]["height"] == pytest.approx(height)
    assert built["summary"]["warnings"] == len(warnings)
    for warning, entry in zip(warnings, built["warnings"], strict=True):
        assert warning in entry["warning"] and entry["line"] == 7
        assert f"{tmp_path / 'f.osm'}:7:3: warning: feature 'way/10': {warning}" in err


def test_feet_and_inches_and_the_manifest_scale() -> None:
    assert length("40'") == pytest.approx(12.192)
    assert length("12'6\"") == pytest.approx(3.81)
    assert length("40 ft") == pytest.approx(12.192)
    assert length("12.5 m") == 12.5 and length("1e999") is None and length("nan") is None
    kept, warnings = checked_properties({"H": "400", "height": "9"}, {"height": ("H", 10.0)})
    assert kept == {"height": "9"} and warnings == [
        "H '400' is more than a building's 1000 m: ignored"
    ]


VIEWS = {  # a feature table that is a view, and what the error says
    "never ends": (
        "WITH RECURSIVE c(fid) AS (SELECT 1 UNION ALL SELECT fid + 1 FROM c) "
        "SELECT fid, NULL AS geom FROM c",
        "the feature table 'buildings' has more than 1,000,000 rows",
    ),
    "sorts what never ends": (
        "WITH RECURSIVE c(fid) AS (SELECT 1 UNION ALL SELECT fid + 1 FROM c) "
        "SELECT fid, NULL AS geom FROM c ORDER BY fid DESC",
        "reading the feature table takes more than",
    ),
    "makes megabytes a row": (
        "WITH RECURSIVE c(fid) AS (SELECT 1 UNION ALL SELECT fid + 1 FROM c LIMIT 100) "
        "SELECT fid, NULL AS geom, printf('%.*c', 1000000, 'x') AS name FROM c",
        "reading the feature table 'buildings' makes more than",
    ),
    "a value longer than the file": (
        "SELECT 1 AS fid, zeroblob(100000000) AS geom",
        "a value of the feature table is longer than the file",
    ),
}


@pytest.mark.parametrize("case", sorted(VIEWS))
def test_a_geopackage_view_that_never_ends_is_exit_2_naming_the_limit(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    case: str,
) -> None:
    from facadecli.city import geopackage as module
    from tests.test_geopackage import geopackage

    if case == "sorts what never ends":
        monkeypatch.setattr(module, "GPKG_STEPS_FREE", 5_000_000)  # the same check, sooner
    view, expected = VIEWS[case]
    path = geopackage(tmp_path / "f.gpkg", [])
    db = sqlite3.connect(path)
    db.executescript(f"DROP TABLE buildings; CREATE VIEW buildings AS {view};")
    db.commit()
    db.close()
    assert path.stat().st_size < 40_000
    manifest = town(tmp_path, "f.gpkg", path.read_bytes())
    code, _, err = city(capsys, manifest)
    assert code == 2 and f"{path}: error: {expected}" in err, err
    assert f"{path}: error: " in err and "(" in err
    assert not (tmp_path / "out").exists()


def test_a_run_cleans_what_a_killed_run_left_and_nothing_else(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import tempfile

    from tests.test_city_inputs import square

    manifest = town(tmp_path, "f.geojson", "")
    features = ",\n".join(square(f"b{i}", x=20.0 * i) for i in range(2))
    crs = '{"type": "name", "properties": {"name": "EPSG:28992"}}'
    (tmp_path / "f.geojson").write_text(
        f'{{"type": "FeatureCollection", "crs": {crs}, "features": [\n{features}\n]}}'
    )
    code, _, err = city(capsys, manifest)
    assert code == 0, err
    out = tmp_path / "out"
    before = set(files(out))
    made = []  # what a run killed at any point leaves: named as the writers name them
    for folder, prefix, suffix in [
        (out, ".town.glb.", ".bin"),
        (out, ".town.glb.", ".tmp"),
        (out, ".town.city.json.", ".objects"),
        (out, ".town.city.json.", ".vertices"),
        (out, ".town.city.json.", ".ids"),
        (out, ".town.report.json.", ".tmp"),
        (out / "buildings", ".b0.glb.", ".tmp"),  # where runs before the shards wrote
        (out / "buildings" / shard("b0"), ".b0.glb.", ".tmp"),
        (out / "buildings" / shard("b1"), ".b1.city.jsonl.", ".tmp"),
        (out / "tiles", ".town_0_-1.glb.", ".bin"),
        (out / "textures", f".{'0' * 32}.png.", ".tmp"),  # a picture, stored once
    ]:
        folder.mkdir(exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=folder)
        os.write(fd, b"half")
        os.close(fd)
        made.append(Path(name))
    others = [  # someone else's: kept
        out / ".town.glb.keep",
        out / "notes.tmp",
        out / ".other.glb.abcdefgh.tmp",
        out / "buildings" / ".b0.glb.tmp",
        out / "buildings" / "b0.glb.abcdefgh.tmp",
        out / "buildings" / shard("b0") / "b0.glb.abcdefgh.tmp",
    ]
    for path in others:
        path.write_text("mine")
    (out / ".town.glb.zzzzzzzz.tmp").symlink_to(tmp_path / "f.geojson")
    code, _, err = facade(capsys, "city", manifest, "-o", out, "-j", "1", "--resume")
    assert code == 0, err
    assert not any(path.exists() for path in made)
    assert all(path.read_text() == "mine" for path in others)
    assert (out / ".town.glb.zzzzzzzz.tmp").is_symlink()
    assert set(files(out)) == before | {p.name for p in others} | {
        ".town.glb.zzzzzzzz.tmp",
        "tiles",
        "textures",
    }


def test_an_unsorted_extract_or_one_with_an_object_twice_is_exit_2_at_its_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    ways_first = way(10, [1, 2, 3, 4, 1], building="yes") + nodes()  # Overpass's 'out; >;'
    manifest = town(tmp_path, "f.osm", osm(ways_first))
    code, _, err = city(capsys, manifest)
    assert code == 2 and ":3:3: error: feature 'way/10' is not a footprint: node 1 comes " in err
    assert "the extract is not sorted (osmium sort FILE -o SORTED.osm)" in err
    manifest = town(tmp_path, "f.osm", osm(GOOD + way(10, [1, 2, 3, 4, 1], building="yes")))
    code, _, err = city(capsys, manifest)
    assert code == 2 and ":8:3: error: way 10 is in the file twice" in err
    assert not (tmp_path / "out").exists()


def test_ways_out_of_order_are_exit_2_with_the_fix(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    body = nodes() + way(11, [1, 2, 3, 4, 1], building="yes") + way(10, [1, 2, 3, 4, 1])
    manifest = town(tmp_path, "f.osm", osm(body))
    code, _, err = city(capsys, manifest)
    assert code == 2 and ":8:3: error: way 10 comes after way 11: the extract is not sorted" in err
    assert "(sort it: osmium sort FILE -o SORTED.osm)" in err


def test_huge_ids_of_missing_nodes_are_not_looked_up() -> None:
    from facadecli.city.osm import _present_nodes

    assert _present_nodes("no such file", {-5, 2**62, 2**63 - 1}) == set()
