"""A generated town (:func:`facadecli.city.demo.terraces`) written in the other formats
``facade city`` reads: OSM XML and PBF, GeoPackage, Shapefile. For the tests that compare
the client's memory at two sizes, and for ``city_large_bench.py`` (FACADE_BENCH_FORMAT).

The OSM extract is in lon/lat (the terraces' RD New metres projected), its nodes shared
where houses share a corner, every ENTRANCE_EVERY-th house with an entrance node in the
middle of its front wall, and every RELATION_EVERY-th house a multipolygon relation of an
untagged way (its entrance then read from its outer way)."""

from __future__ import annotations

import json
import sqlite3
import struct
from collections.abc import Iterable
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import pyproj
import shapely

from facadecli.city.demo import terraces
from tests.fuzz.city_doors import GPKG_SCHEMA

RD_NEW = 28992
ENTRANCE_EVERY = 7  # houses: one in this many has an entrance node on its front wall
RELATION_EVERY = 11  # houses: one in this many is a multipolygon relation, not a way
FORMATS = ("geojson", "osm", "pbf", "gpkg", "shp")
SUFFIXES = {"geojson": "geojson", "osm": "osm", "pbf": "osm.pbf", "gpkg": "gpkg", "shp": "shp"}


def _ring(feature: dict[str, Any]) -> list[tuple[float, float]]:
    """A terrace's outer ring without its closing point."""
    coordinates = feature["geometry"]["coordinates"][0]
    return [(float(x), float(y)) for x, y in coordinates[:-1]]


def _text(value: object) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def write_osm(path: Path, features: Iterable[dict[str, Any]]) -> Path:
    """The features as an OSM XML extract, written a line at a time (see the module)."""
    project = pyproj.Transformer.from_crs(RD_NEW, 4326, always_xy=True).transform
    nodes: dict[tuple[float, float], int] = {}
    doors: list[tuple[int, float, float]] = []  # node id, lon, lat
    ways: list[tuple[int, list[int], dict[str, Any]]] = []
    relations: list[tuple[int, int, dict[str, Any]]] = []  # id, outer way, tags
    next_node = 1
    for number, feature in enumerate(features, start=1):
        ring = _ring(feature)
        refs = []
        for k, (x, y) in enumerate(ring):
            key = (round(x, 3), round(y, 3))
            if key not in nodes:
                nodes[key] = next_node
                next_node += 1
            refs.append(nodes[key])
            if k == 0 and number % ENTRANCE_EVERY == 0:  # the front wall's middle
                (x1, y1) = ring[1]
                lon, lat = project((x + x1) / 2, (y + y1) / 2)
                doors.append((next_node, lon, lat))
                refs.append(next_node)
                next_node += 1
        tags = feature["properties"]
        if number % RELATION_EVERY == 0:
            ways.append((number, [*refs, refs[0]], {}))
            relations.append((number, number, tags))
        else:
            ways.append((number, [*refs, refs[0]], tags))
    with path.open("w", encoding="utf-8") as out:
        out.write('<?xml version="1.0" encoding="UTF-8"?>\n<osm version="0.6" generator="towns">\n')
        located = [(nid, *project(x, y), "") for (x, y), nid in nodes.items()]
        located += [(nid, lon, lat, "entrance") for nid, lon, lat in doors]
        for nid, lon, lat, kind in sorted(located):
            tag = '><tag k="entrance" v="main"/></node>' if kind else "/>"
            out.write(f'  <node id="{nid}" version="1" lat="{lat:.9f}" lon="{lon:.9f}"{tag}\n')
        for oid, refs, tags in ways:
            out.write(f'  <way id="{oid}" version="1">\n')
            out.writelines(f'    <nd ref="{ref}"/>\n' for ref in refs)
            out.writelines(
                f"    <tag k={quoteattr(k)} v={quoteattr(_text(v))}/>\n" for k, v in tags.items()
            )
            out.write("  </way>\n")
        for oid, way, tags in relations:
            out.write(f'  <relation id="{oid}" version="1">\n')
            out.write(f'    <member type="way" ref="{way}" role="outer"/>\n')
            out.write('    <tag k="type" v="multipolygon"/>\n')
            out.writelines(
                f"    <tag k={quoteattr(k)} v={quoteattr(_text(v))}/>\n" for k, v in tags.items()
            )
            out.write("  </relation>\n")
        out.write("</osm>\n")
    return path


def write_pbf(path: Path, xml: Path) -> Path:
    """An OSM XML extract converted to PBF with pyosmium."""
    import osmium

    writer = osmium.SimpleWriter(str(path))
    try:
        for item in osmium.FileProcessor(str(xml)):
            writer.add(item)
    finally:
        writer.close()
    return path


GPKG_TABLES = (
    GPKG_SCHEMA
    + """
CREATE TABLE buildings (fid INTEGER PRIMARY KEY, geom BLOB, building TEXT,
    "building:levels" TEXT, height REAL, "roof:shape" TEXT);
"""
)
COLUMNS = ("building", "building:levels", "height", "roof:shape")


def write_gpkg(path: Path, features: Iterable[dict[str, Any]]) -> Path:
    """The features as a GeoPackage of one feature table in RD New (sqlite3, no GDAL)."""
    db = sqlite3.connect(path)
    try:
        db.executescript(GPKG_TABLES)
        db.execute(
            "INSERT INTO gpkg_spatial_ref_sys VALUES ('RD New', ?, 'EPSG', ?, '', '')",
            (RD_NEW, RD_NEW),
        )
        db.execute(
            "INSERT INTO gpkg_contents VALUES ('buildings', 'features', 'b', '', '', "
            "0, 0, 0, 0, ?)",
            (RD_NEW,),
        )
        db.execute(
            "INSERT INTO gpkg_geometry_columns VALUES ('buildings', 'geom', 'POLYGON', ?, 0, 0)",
            (RD_NEW,),
        )
        head = b"GP" + bytes([0, 0b00000001]) + struct.pack("<i", RD_NEW)
        for number, feature in enumerate(features, start=1):
            blob = head + shapely.to_wkb(shapely.Polygon(_ring(feature)))
            values = [feature["properties"].get(name) for name in COLUMNS]
            db.execute("INSERT INTO buildings VALUES (?, ?, ?, ?, ?, ?)", (number, blob, *values))
        db.commit()
    finally:
        db.close()
    return path


def write_shp(path: Path, features: Iterable[dict[str, Any]]) -> Path:
    """The features as a Shapefile in RD New (pyogrio: GDAL). Its columns are the tags
    DBF can name (10 characters): building, levels, height, roof."""
    import numpy as np
    import pyogrio.raw

    found = list(features)
    geometries = np.array([shapely.to_wkb(shapely.Polygon(_ring(f))) for f in found], dtype=object)
    columns = [
        np.array([str(f["properties"].get(name) or "") for f in found], dtype=object)
        for name in ("building", "building:levels", "roof:shape")
    ]
    heights = np.array([float(f["properties"].get("height") or 0.0) for f in found])
    pyogrio.raw.write(
        path,
        geometries,
        field_data=[columns[0], columns[1], heights, columns[2]],
        fields=["building", "levels", "height", "roof_shape"],
        crs=f"EPSG:{RD_NEW}",
        driver="ESRI Shapefile",
        geometry_type="Polygon",
    )
    return path


def write_town(folder: Path, count: int, form: str, seed: int = 0) -> Path:
    """:func:`terraces` of ``count`` houses in the format ``form`` (FORMATS) in
    ``folder``; returns the file."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"footprints.{SUFFIXES[form]}"
    if form == "geojson":
        crs = '{"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}'
        with path.open("w", encoding="utf-8") as out:
            out.write(f'{{"type": "FeatureCollection", "crs": {crs}, "features": [\n')
            out.write(",\n".join(json.dumps(f) for f in terraces(count, seed)))
            out.write("\n]}\n")
        return path
    if form == "osm":
        return write_osm(path, terraces(count, seed))
    if form == "pbf":
        xml = write_osm(folder / "footprints.osm", terraces(count, seed))
        write_pbf(path, xml)
        xml.unlink()
        return path
    if form == "gpkg":
        return write_gpkg(path, terraces(count, seed))
    if form == "shp":
        return write_shp(path, terraces(count, seed))
    raise ValueError(f"no format {form!r}: one of {', '.join(FORMATS)}")


PLANNING_PEAK = """
import gc, json, sys, tracemalloc
from pathlib import Path
from facadecli.city import ogr, osmxml
from facadecli.city.manifest import load_city
from facadecli.city.run import planned
from tests.towns import write_town_manifest
root, folder, form = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
osmxml.CHUNK, ogr.BATCH = 1 << 14, 64  # the readers' buffers, the same at any size
planned(load_city(write_town_manifest(folder / "town-50", root, 50, form)), folder / "out")
peaks = []
for count in COUNTS:
    loaded = load_city(write_town_manifest(folder / f"town-{count}", root, count, form))
    gc.collect()
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    ahead = planned(loaded, folder / "out")
    peaks.append(tracemalloc.get_traced_memory()[1] - before)
    tracemalloc.stop()
    del ahead
print(json.dumps(peaks))
"""
PLANNED = (400, 1600)  # buildings of the two towns PLANNING_PEAK plans


def write_town_manifest(folder: Path, root: Path, count: int, form: str, seed: int = 1) -> Path:
    """The demo's manifest (:func:`facadecli.city.demo.write_terraces`) of a town of
    ``count`` terraces written as ``form`` (FORMATS)."""
    from facadecli.city.demo import write_terraces

    manifest = write_terraces(folder, root / "specs", count, seed)
    if form != "geojson":
        (folder / "footprints.geojson").unlink()
        written = write_town(folder, count, form, seed)
        manifest.write_text(manifest.read_text().replace("footprints.geojson", written.name))
    return manifest


def planning_slope(root: Path, folder: Path, form: str) -> float:
    """Bytes a building more at the peak of Python's allocations (tracemalloc) planning a
    town of PLANNED[1] terraces than one of PLANNED[0], their footprints in ``form``; in
    a fresh Python (a test worker's leftovers would be counted), a town of 50 planned
    first (the one-off caches and imports)."""
    import subprocess
    import sys

    script = PLANNING_PEAK.replace("COUNTS", repr(PLANNED))
    run = subprocess.run(
        [sys.executable, "-c", script, str(root), str(folder), form],
        capture_output=True,
        text=True,
        check=True,
        cwd=root,
    )
    peaks = json.loads(run.stdout.splitlines()[-1])
    return float((peaks[1] - peaks[0]) / (PLANNED[1] - PLANNED[0]))
