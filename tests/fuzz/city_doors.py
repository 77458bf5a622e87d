"""The doors of ``facade city``: its footprints files (OSM XML, compressed or not, OSM PBF,
GeoJSON, GeoPackage) and its manifest. Each case is a small valid district mutated a few
times (bytes flipped, spans cut or repeated, the file truncated; tag values, numbers and
ids replaced by hostile ones; SQL tables and views swapped), built with ``-j 1``. Exit 0
or 2 (3 never happens here, but is allowed), never an internal error, nothing written on
a refusal. See ``tests/fuzz/run.py`` for the protocol."""

from __future__ import annotations

import bz2
import gzip
import json
import random
import sqlite3
import struct
import tempfile
from collections.abc import Callable
from pathlib import Path

from tests.fuzz import FuzzCase

SPEC = b"""\
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
footprints: {footprints}
defaults:
  facade: plain.yaml
  height: 6
  min_facade_width: 2
  floor_height: 3
  roof: {{type: gable, pitch: 30}}
rules:
  - when: {{building: house}}
    roof: {{type: hip}}
  - when: {{levels: {{min: 3}}}}
    height: 12
properties:
  levels: {{name: levels, scale: 1}}
"""
ARGV = ("city", "{dir}/m.yaml", "-o", "{dir}/out", "-j", "1")

LON, LAT = 24.94, 60.17
DEG = 0.0001
BUILDINGS: list[tuple[float, float, float, float, dict[str, str]]] = [  # x, y, w, h in DEG
    (0, 0, 2, 1, {"building": "yes", "height": "12", "roof:shape": "gabled"}),
    (3, 0, 2, 2, {"building": "house", "building:levels": "3", "roof:levels": "1"}),
    (6, 0, 3, 2, {"building": "apartments", "height": "40'", "roof:shape": "hipped"}),
    (6.5, 0.5, 1, 1, {"building:part": "yes", "min_height": "3", "height": "15"}),
]
HOSTILE_VALUES = [
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "1e9",
    "-1",
    "0",
    "",
    " ",
    "40'",
    "12'6\"",
    "1,5",
    "3;4",
    "9223372036854775807",
    "18446744073709551615",
    "1e-320",
    "x" * 300,
    "\u202e",
    "é",
    "0x10",
    "-0",
    "999999999999999999999999",
]
TAG_KEYS = [
    "height",
    "min_height",
    "building:levels",
    "roof:levels",
    "roof:height",
    "roof:angle",
    "roof:direction",
    "roof:shape",
    "building:min_level",
    "levels",
    "building:colour",
    "roof:colour",
    "building",
    "building:part",
    "name",
]
IDS = ["0", "-1", "1", "4611686018427387903", "4611686018427387904", "9223372036854775807"]
IDS += ["18446744073709551615", "-9223372036854775808", "1e3", "abc", ""]
COORDINATES = ["nan", "inf", "91", "-181", "180", "-90", "1e3", "", "+24.94", " 60.17", "0"]
TOKENS = [b"", b"<", b">", b"/>", b'"', b"'", b"&", b"&amp;", b"]]>", b"<!--", b"\x00"]
TOKENS += [b"\xff", b"{", b"}", b"[", b"]", b",", b":", b"null", b"NaN", b"1e999", b"\n"]


def _square(x: float, y: float, w: float, h: float) -> list[tuple[float, float]]:
    x0, y0 = LON + x * DEG, LAT + y * DEG
    x1, y1 = x0 + w * DEG, y0 + h * DEG
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def _tags(rng: random.Random, tags: dict[str, str]) -> dict[str, str]:
    """The tags with, sometimes, a value or two made hostile."""
    tags = dict(tags)
    for _ in range(rng.choice([0, 0, 1, 2])):
        tags[rng.choice(TAG_KEYS)] = rng.choice(HOSTILE_VALUES)
    return tags


# ---------------------------------------------------------------- byte-level mutations


def mutate_bytes(data: bytes, rng: random.Random, edits: int = 3) -> bytes:
    """A few random edits: bytes flipped, spans cut, repeated or swapped, tokens put in,
    the end cut off."""
    for _ in range(rng.randint(1, edits)):
        if not data:
            return rng.choice(TOKENS)
        at = rng.randrange(len(data))
        kind = rng.randrange(6)
        if kind == 0:  # flip a byte's bits
            data = data[:at] + bytes([data[at] ^ (1 << rng.randrange(8))]) + data[at + 1 :]
        elif kind == 1:  # cut a span
            data = data[:at] + data[at + rng.randint(1, 64) :]
        elif kind == 2:  # repeat a span
            span = data[at : at + rng.randint(1, 256)]
            data = data[:at] + span * rng.randint(2, 8) + data[at:]
        elif kind == 3:  # put a token in
            data = data[:at] + rng.choice(TOKENS) + data[at:]
        elif kind == 4:  # a random byte
            data = data[:at] + bytes([rng.randrange(256)]) + data[at + 1 :]
        else:  # truncated
            data = data[:at]
    return data


def _case(name: str, content: bytes, note: str, manifest: str | None = None) -> FuzzCase:
    text = manifest if manifest is not None else MANIFEST.format(footprints=name)
    return FuzzCase(
        files={"plain.yaml": SPEC, "m.yaml": text.encode("utf-8", "surrogatepass"), name: content},
        argv=ARGV,
        outputs=("out",),
        note=note,
    )


# ---------------------------------------------------------------- OSM XML


def osm_xml(rng: random.Random) -> str:
    """A small extract: the buildings as ways (the last one sometimes a multipolygon), a
    road, and now and then hostile ids, coordinates, missing nodes or members."""
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm version="0.6" generator="fuzz">']
    node = 0
    ways = []
    for index, (x, y, w, h, tags) in enumerate(BUILDINGS):
        refs = []
        for lon, lat in _square(x, y, w, h):
            node += 1
            lon_text, lat_text = f"{lon:.7f}", f"{lat:.7f}"
            if rng.random() < 0.03:
                lon_text = rng.choice(COORDINATES)
            if rng.random() < 0.03:
                lat_text = rng.choice(COORDINATES)
            lines.append(f'  <node id="{node}" version="1" lat="{lat_text}" lon="{lon_text}"/>')
            refs.append(node)
        refs.append(refs[0])
        if rng.random() < 0.05:
            refs[rng.randrange(len(refs))] = rng.choice([99999, -5, node + 1])
        wid = str(100 + index)
        if rng.random() < 0.04:
            wid = rng.choice(IDS)
        ways.append((wid, refs, _tags(rng, tags)))
    relation = rng.random() < 0.3
    for number, (wid, refs, tags) in enumerate(ways):
        body = "".join(f'<nd ref="{r}"/>' for r in refs)
        if not (relation and number == len(ways) - 1):
            body += "".join(f'<tag k="{_xml(k)}" v="{_xml(v)}"/>' for k, v in tags.items())
        lines.append(f'  <way id="{wid}" version="1">{body}</way>')
    lines.append('  <way id="900"><nd ref="1"/><nd ref="2"/><tag k="highway" v="path"/></way>')
    if relation:
        wid, _, tags = ways[-1]
        outer = wid if rng.random() < 0.8 else "77777"
        members = f'<member type="way" ref="{_xml(outer)}" role="outer"/>'
        if rng.random() < 0.2:
            members += '<member type="way" ref="88888" role="inner"/>'
        tag_text = "".join(f'<tag k="{_xml(k)}" v="{_xml(v)}"/>' for k, v in tags.items())
        lines.append(
            f'  <relation id="500">{members}<tag k="type" v="multipolygon"/>{tag_text}</relation>'
        )
    lines.append("</osm>")
    return "\n".join(lines) + "\n"


def _xml(text: str) -> str:
    return text.replace("&", "&amp;").replace('"', "&quot;").replace("<", "&lt;")


def osm_xml_case(seed: int) -> FuzzCase:
    rng = random.Random(seed)
    data = osm_xml(rng).encode("utf-8", "surrogatepass")
    if rng.random() < 0.6:
        data = mutate_bytes(data, rng, edits=2)
    kind = rng.choice(["osm", "osm", "osm", "osm.gz", "osm.bz2"])
    if kind == "osm.gz":
        data = gzip.compress(data, mtime=0)
    elif kind == "osm.bz2":
        data = bz2.compress(data)
    if kind != "osm" and rng.random() < 0.3:
        data = mutate_bytes(data, rng, edits=1)
    return _case(f"f.{kind}", data, f"OSM XML ({kind})")


# ---------------------------------------------------------------- OSM PBF


def osm_pbf(rng: random.Random) -> bytes:
    """The buildings written as a PBF by pyosmium, with hostile ids, tags, missing nodes."""
    import osmium
    from osmium.osm.mutable import Node, Relation, Way

    with tempfile.TemporaryDirectory(prefix="facade-fuzz-pbf-") as folder:
        path = Path(folder) / "f.osm.pbf"
        writer = osmium.SimpleWriter(str(path))
        try:
            node = 0
            ways = []
            for index, (x, y, w, h, tags) in enumerate(BUILDINGS):
                refs = []
                for lon, lat in _square(x, y, w, h):
                    node += 1
                    if rng.random() < 0.03:
                        lon = rng.choice([180.0, -180.0, 214.0, 0.0])
                    writer.add_node(Node(id=node, location=(lon, lat)))
                    refs.append(node)
                refs.append(refs[0])
                if rng.random() < 0.08:
                    refs[rng.randrange(len(refs))] = rng.choice([99999, -5])
                wid = 100 + index
                if rng.random() < 0.08:
                    wid = rng.choice([2**62 - 1, 2**62, 2**63 - 2, -(2**62), 0, -1])
                tags = _tags(rng, tags)
                if rng.random() < 0.05:
                    tags["name"] = "x" * rng.choice([255, 256, 1000])
                ways.append((wid, refs, tags))
            relation = rng.random() < 0.3
            for number, (wid, refs, tags) in enumerate(ways):
                last = relation and number == len(ways) - 1
                writer.add_way(Way(id=wid, nodes=refs, tags={} if last else tags))
            if relation:
                wid, _, tags = ways[-1]
                outer = wid if rng.random() < 0.8 else 77777
                members = [("w", outer, "outer")]
                writer.add_relation(
                    Relation(id=500, members=members, tags={"type": "multipolygon", **tags})
                )
        finally:
            writer.close()
        return path.read_bytes()


def osm_pbf_case(seed: int) -> FuzzCase:
    rng = random.Random(seed)
    data = osm_pbf(rng)
    if rng.random() < 0.5:
        data = mutate_bytes(data, rng, edits=2)
    return _case("f.osm.pbf", data, "OSM PBF")


# ---------------------------------------------------------------- GeoJSON


def geojson(rng: random.Random) -> dict[str, object]:
    features = []
    for index, (x, y, w, h, tags) in enumerate(BUILDINGS):
        ring = [list(p) for p in _square(x, y, w, h)]
        properties: dict[str, object] = dict(_tags(rng, tags))
        if rng.random() < 0.2:
            properties[rng.choice(TAG_KEYS)] = rng.choice([1e308, -1.0, 0, 10**30, True, None])
        features.append(
            {
                "type": "Feature",
                "id": f"b{index}",
                "properties": properties,
                "geometry": {"type": "Polygon", "coordinates": [[*ring, ring[0]]]},
            }
        )
    return {"type": "FeatureCollection", "features": features}


JSON_VALUES: list[object] = [None, [], {}, "x", "", 1e308, -1e308, -1, 0, True, [[1, 2]]]
JSON_VALUES += [[[[0, 0]]], {"type": "Point", "coordinates": [0, 0]}, {"type": "Nonsense"}]
JSON_VALUES += [[None], "EPSG:0", {"type": "name", "properties": {"name": "EPSG:99999"}}]
JSON_VALUES += [10**30, float("nan"), float("inf")]


def _places(node: object) -> list[tuple[object, object]]:
    found: list[tuple[object, object]] = []
    if isinstance(node, dict):
        items: list[tuple[object, object]] = list(node.items())
    elif isinstance(node, list):
        items = list(enumerate(node))
    else:
        items = []
    for key, value in items:
        found.append((node, key))
        found.extend(_places(value))
    return found


def geojson_case(seed: int) -> FuzzCase:
    rng = random.Random(seed)
    document = geojson(rng)
    if rng.random() < 0.5:
        for _ in range(rng.randint(1, 2)):
            parent, key = rng.choice(_places(document))
            parent[key] = json.loads(json.dumps(rng.choice(JSON_VALUES)))  # type: ignore[index]
    data = json.dumps(document).encode()
    if rng.random() < 0.4:
        data = mutate_bytes(data, rng, edits=2)
    return _case("f.geojson", data, "GeoJSON")


# ---------------------------------------------------------------- GeoPackage

GPKG_SCHEMA = """
CREATE TABLE gpkg_spatial_ref_sys (srs_name TEXT, srs_id INTEGER PRIMARY KEY,
    organization TEXT, organization_coordsys_id INTEGER, definition TEXT, description TEXT);
CREATE TABLE gpkg_contents (table_name TEXT PRIMARY KEY, data_type TEXT, identifier TEXT,
    description TEXT, last_change TEXT, min_x REAL, min_y REAL, max_x REAL, max_y REAL,
    srs_id INTEGER);
CREATE TABLE gpkg_geometry_columns (table_name TEXT, column_name TEXT,
    geometry_type_name TEXT, srs_id INTEGER, z TINYINT, m TINYINT);
"""
VIEWS = [
    "WITH RECURSIVE c(fid) AS (SELECT 1 UNION ALL SELECT fid + 1 FROM c) "
    "SELECT fid, NULL AS geom FROM c",
    "WITH RECURSIVE c(fid) AS (SELECT 1 UNION ALL SELECT fid + 1 FROM c) "
    "SELECT fid, NULL AS geom FROM c ORDER BY fid DESC",
    "SELECT fid, geom, printf('%.*c', 1000000, 'x') AS name FROM t",
    "SELECT 1 AS fid, zeroblob(100000000) AS geom",
    "SELECT fid, geom, height FROM t",
    "SELECT * FROM t, t AS u",
]


def _wkb_polygon(ring: list[tuple[float, float]]) -> bytes:
    points = [*ring, ring[0]]
    data = struct.pack("<BII", 1, 3, 1) + struct.pack("<I", len(points))
    return data + b"".join(struct.pack("<dd", x, y) for x, y in points)


def geopackage(rng: random.Random) -> bytes:
    """A GeoPackage in EPSG:4326 of the buildings; now and then a view for a table, a
    hostile value or a geometry blob with bits flipped."""
    with tempfile.TemporaryDirectory(prefix="facade-fuzz-gpkg-") as folder:
        path = Path(folder) / "f.gpkg"
        db = sqlite3.connect(path)
        try:
            db.executescript(GPKG_SCHEMA)
            db.execute(
                "CREATE TABLE t (fid INTEGER PRIMARY KEY, geom BLOB, height TEXT, "
                "levels TEXT, building TEXT, name TEXT)"
            )
            srs = rng.choice([4326] * 8 + [0, -1, 99999, 28992])
            db.execute(
                "INSERT INTO gpkg_spatial_ref_sys VALUES ('WGS 84', ?, 'EPSG', ?, '', '')",
                (srs, rng.choice([4326] * 8 + [0, 999999])),
            )
            table = "t"
            if rng.random() < 0.15:
                table = "v"
                db.execute(f"CREATE VIEW v AS {rng.choice(VIEWS)}")
            db.execute(
                "INSERT INTO gpkg_contents VALUES (?, 'features', 'b', '', '', 0, 0, 0, 0, ?)",
                (table if rng.random() < 0.95 else "missing", srs),
            )
            column = "geom" if rng.random() < 0.95 else rng.choice(["height", "nope", ""])
            db.execute(
                "INSERT INTO gpkg_geometry_columns VALUES (?, ?, 'POLYGON', ?, 0, 0)",
                (table, column, srs),
            )
            for index, (x, y, w, h, tags) in enumerate(BUILDINGS):
                blob = b"GP\x00\x01" + struct.pack("<i", srs) + _wkb_polygon(_square(x, y, w, h))
                if rng.random() < 0.1:
                    blob = mutate_bytes(blob, rng, edits=2)
                tags = _tags(rng, tags)
                height: object = tags.get("height")
                if rng.random() < 0.1:
                    height = rng.choice([1e308, -1.0, 10**18, b"\x00", None])
                db.execute(
                    "INSERT INTO t VALUES (?, ?, ?, ?, ?, ?)",
                    (index + 1, blob, height, tags.get("building:levels"), "yes", tags.get("name")),
                )
            db.commit()
        finally:
            db.close()
        return path.read_bytes()


def geopackage_case(seed: int) -> FuzzCase:
    rng = random.Random(seed)
    data = geopackage(rng)
    if rng.random() < 0.3:
        data = mutate_bytes(data, rng, edits=2)
    return _case("f.gpkg", data, "GeoPackage")


# ---------------------------------------------------------------- manifest

YAML_TOKENS = ["", " ", "\n", ":", "- ", "{", "}", "[", "]", ",", '"', "'", "#", "&a ", "*a"]
YAML_TOKENS += ["!!python/object/apply:os.system ", "!!set ", "\x00", "~", "null", "true"]
YAML_TOKENS += [".inf", "-.inf", ".nan", "1e308", "-1", "0", "99999999999999999999", "é"]
YAML_TOKENS += ["../", "/dev/zero", "f.geojson", "plain.yaml", "levels", "height", "roof"]


def mutate_text(text: str, rng: random.Random, edits: int = 3) -> str:
    for _ in range(rng.randint(1, edits)):
        if not text:
            return rng.choice(YAML_TOKENS)
        at = rng.randrange(len(text))
        kind = rng.randrange(5)
        if kind == 0:
            text = text[:at] + text[at + rng.randint(1, 20) :]
        elif kind == 1:
            text = text[:at] + rng.choice(YAML_TOKENS) + text[at + 1 :]
        elif kind == 2:
            text = text[:at] + rng.choice(YAML_TOKENS) + text[at:]
        elif kind == 3:
            lines = text.split("\n")
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
        else:
            text = text[:at]
    return text


def manifest_case(seed: int) -> FuzzCase:
    rng = random.Random(seed)
    manifest = mutate_text(MANIFEST.format(footprints="f.geojson"), rng)
    data = json.dumps(geojson(random.Random(seed + 1))).encode()
    return _case("f.geojson", data, "manifest", manifest)


DOORS: dict[str, Callable[[int], FuzzCase]] = {
    "city-osm-xml": osm_xml_case,
    "city-osm-pbf": osm_pbf_case,
    "city-geojson": geojson_case,
    "city-geopackage": geopackage_case,
    "city-manifest": manifest_case,
}
