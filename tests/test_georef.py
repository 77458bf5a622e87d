"""Georeferenced outputs (issue 36): lon/lat input lands in the UTM zone of its middle,
named in the CityJSON, the merged glbs' extras, ``<name>.georef.json`` and the tile
index, so every output goes back on the map where its footprints came from."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pyproj
import pytest

from facadecli.city.cityjson import cityjson_header
from facadecli.city.footprints import read_footprints
from facadecli.city.georef import Georef, georeference, utm_epsg
from facadecli.export.glb_merge import read_glb

ROOT = Path(__file__).resolve().parent.parent
TOWN = ROOT / "samples" / "town.osm"
LON_LAT = pyproj.CRS.from_epsg(4326)


def _projected(epsg: int, points: list[tuple[float, float]]) -> np.ndarray:
    to = pyproj.Transformer.from_crs(LON_LAT, pyproj.CRS.from_epsg(epsg), always_xy=True)
    return np.array([to.transform(lon, lat) for lon, lat in points])


def _town_nodes() -> list[tuple[float, float]]:
    """(lon, lat) of every node of a building way of samples/town.osm."""
    root = ET.parse(TOWN).getroot()
    nodes = {n.get("id"): (float(n.get("lon", 0)), float(n.get("lat", 0))) for n in root}
    used = {
        nd.get("ref")
        for way in root.iter("way")
        if any(tag.get("k") == "building" for tag in way.iter("tag"))
        for nd in way.iter("nd")
    }
    return [nodes[ref] for ref in sorted(used, key=lambda r: int(r or 0))]


@pytest.mark.parametrize(
    ("lon", "lat", "epsg"),
    [
        (10.0, 45.0, 32632),  # samples/town.osm
        (24.94, 60.17, 32635),  # Helsinki
        (-58.38, -34.6, 32721),  # Buenos Aires: south, 327NN
        (151.21, -33.87, 32756),  # Sydney
        (5.32, 60.39, 32632),  # Bergen: the Norwegian exception (31V by longitude)
        (15.6, 78.2, 32633),  # Longyearbyen: Svalbard's 33X
        (180.0, 0.5, 32660),  # the antimeridian is zone 60, not 61
        (-179.9, -0.5, 32701),
        (0.0, 85.0, 5041),  # beyond UTM: UPS North
        (0.0, -85.0, 5042),
    ],
)
def test_the_utm_zone_of_a_place(lon: float, lat: float, epsg: int) -> None:
    assert utm_epsg(lon, lat) == epsg


def _square(fid: str, lon: float, lat: float, side: float) -> dict[str, Any]:
    ring = [[lon, lat], [lon + side, lat], [lon + side, lat + side], [lon, lat + side]]
    return {
        "type": "Feature",
        "id": fid,
        "properties": {},
        "geometry": {"type": "Polygon", "coordinates": [ring + ring[:1]]},
    }


def test_south_of_the_equator_across_a_zone_edge_the_middle_zone_is_kept(
    tmp_path: Path,
) -> None:
    # 12° E is the edge of zones 32 and 33; the middle (median of the centres) is west of it
    side = 0.0002
    corners = {"w": (11.9990, -33.9), "m": (11.9996, -33.9), "e": (12.0004, -33.9)}
    features = [_square(fid, lon, lat, side) for fid, (lon, lat) in corners.items()]
    path = tmp_path / "edge.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    found = read_footprints(path)
    assert found.crs == "EPSG:32732"  # zone 32, south
    header = cityjson_header(found.crs, found.origin, "edge")
    assert header["metadata"]["referenceSystem"] == "https://www.opengis.net/def/crs/EPSG/0/32732"
    ox, oy = header["transform"]["translate"][:2]
    for footprint, (lon, lat) in zip(found.footprints, corners.values(), strict=True):
        ring = [(lon, lat), (lon + side, lat), (lon + side, lat + side), (lon, lat + side)]
        expected = _projected(32732, ring)
        (part,) = footprint.parts
        got = np.array(part.exterior.coords[:-1]) + np.array([ox, oy])
        gaps = np.linalg.norm(got[None, :, :] - expected[:, None, :], axis=2).min(axis=1)
        assert gaps.max() < 0.01  # east of 12° E too
    georef = Georef(found.crs, found.origin, found.unit)
    west, south, east, north = georef.bounds_lonlat((0.0, 0.0, 200.0, 50.0))
    assert west <= 11.9990 and east >= 12.0006 and south <= -33.9 and north >= -33.9 + side
    frame = georeference(georef)
    back = pyproj.Transformer.from_crs(pyproj.CRS.from_epsg(32732), LON_LAT, always_xy=True)
    assert frame["origin_lonlat"][:2] == pytest.approx(back.transform(ox, oy), abs=1e-8)
    assert 0.9996 < frame["scale_factor"] < 1.0011  # 3° from the central meridian
    assert frame["grid_north_bearing"] == pytest.approx(-3 * math.sin(math.radians(33.9)), abs=0.02)


def test_a_projected_crs_keeps_its_own_frame(tmp_path: Path) -> None:
    ring = [[85000, 447000], [85010, 447000], [85010, 447010], [85000, 447010], [85000, 447000]]
    data = {
        "type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "EPSG:28992"}},
        "features": [
            {
                "type": "Feature",
                "id": "a",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring]},
            }
        ],
    }
    path = tmp_path / "rd.geojson"
    path.write_text(json.dumps(data))
    found = read_footprints(path)
    assert (found.crs, found.origin) == ("EPSG:28992", (85000, 447000))
    frame = georeference(Georef(found.crs, found.origin, found.unit))
    assert frame["crs_url"] == "https://www.opengis.net/def/crs/EPSG/0/28992"
    assert frame["origin"] == [85000, 447000, 0.0]


@pytest.fixture(scope="module")
def town(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """samples/town.osm built with 100 m tiles (one tile holds it all)."""
    folder = tmp_path_factory.mktemp("town")
    manifest = (ROOT / "samples" / "town.yaml").read_text()
    manifest = manifest.replace("footprints: town.osm", f"footprints: {TOWN}")
    manifest = manifest.replace("../specs/", f"{ROOT / 'specs'}/") + "tiles: 100\n"
    (folder / "town.yaml").write_text(manifest)
    command = ["city", folder / "town.yaml", "-o", folder / "out", "-j", "1", "-q"]
    done = subprocess.run(
        [sys.executable, "-m", "facadecli", *map(str, command)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return folder / "out"


def test_the_cityjson_vertices_come_back_to_the_osm_nodes(town: Path) -> None:
    document = json.loads((town / "town.city.json").read_text())
    assert document["metadata"]["referenceSystem"] == (
        "https://www.opengis.net/def/crs/EPSG/0/32632"
    )
    transform = document["transform"]
    real = np.array(document["vertices"]) * transform["scale"] + transform["translate"]
    ground = real[np.abs(real[:, 2]) < 1e-6][:, :2]
    nodes = _projected(32632, _town_nodes())
    gaps = np.linalg.norm(ground[None, :, :] - nodes[:, None, :], axis=2).min(axis=1)
    assert gaps.max() < 0.01  # every node is a ground corner, within a centimetre


def test_cjio_reads_the_reference_system(town: Path) -> None:
    cjio = Path(sys.executable).parent / "cjio"
    if not cjio.exists() and shutil.which("cjio") is None:
        pytest.skip("cjio is not installed")
    command = str(cjio) if cjio.exists() else "cjio"
    out = subprocess.run(
        [command, str(town / "town.city.json"), "info"], capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    assert "EPSG = 32632" in out.stdout


def test_the_merged_glbs_and_the_sidecar_carry_the_origin(town: Path) -> None:
    cityjson = json.loads((town / "town.city.json").read_text())
    sidecar = json.loads((town / "town.georef.json").read_text())
    assert sidecar["crs"] == "EPSG:32632"
    assert sidecar["origin"][:2] == cityjson["transform"]["translate"][:2]
    assert pyproj.CRS.from_wkt(sidecar["crs_wkt"]).to_epsg() == 32632
    index = json.loads((town / "town.tiles.json").read_text())
    for glb in [town / "town.glb", *(town / t["file"] for t in index["tiles"])]:
        document, binary = read_glb(glb.read_bytes())
        extras = document["scenes"][0]["extras"]["georeference"]
        assert extras == {k: v for k, v in sidecar.items() if k != "crs_wkt"}
    # the glb's ground corners are the OSM nodes too: easting = E0 + x, northing = N0 - z
    document, binary = read_glb((town / "town.glb").read_bytes())
    points = []
    for accessor in document["accessors"]:
        if accessor.get("type") != "VEC3" or "min" not in accessor or accessor["min"][1] > 0.01:
            continue
        view = document["bufferViews"][accessor["bufferView"]]
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        stride = view.get("byteStride", 12)
        for n in range(accessor["count"]):
            points.append(np.frombuffer(binary, "<f4", 3, start + n * stride))
    xyz = np.array(points, dtype=float)
    ground = xyz[np.abs(xyz[:, 1]) < 0.02]
    east = sidecar["origin"][0] + ground[:, 0]
    north = sidecar["origin"][1] - ground[:, 2]
    mapped = np.stack([east, north], axis=1)
    nodes = _projected(32632, _town_nodes())
    gaps = np.linalg.norm(mapped[None, :, :] - nodes[:, None, :], axis=2).min(axis=1)
    assert gaps.max() < 0.05


def test_the_tile_index_is_in_the_named_crs_and_in_lon_lat(town: Path) -> None:
    index = json.loads((town / "town.tiles.json").read_text())
    assert index["crs"] == "EPSG:32632"
    assert index["crs_url"] == "https://www.opengis.net/def/crs/EPSG/0/32632"
    (tile,) = index["tiles"]
    ox, oy = index["origin"]
    assert tile["bounds_crs"] == [ox, oy, ox + 100.0, oy + 100.0]
    west, south, east, north = tile["bounds_lonlat"]
    for lon, lat in _town_nodes():
        assert west <= lon <= east and south <= lat <= north
    report = json.loads((town / "town.report.json").read_text())
    assert report["crs"] == "EPSG:32632"
    assert report["georeference"]["origin"][:2] == [ox, oy]
    assert report["models"]["georef"] == "town.georef.json"
