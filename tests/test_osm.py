"""Footprints from an OpenStreetMap extract (issue 16): a small .osm.pbf and .osm written by
the tests build the same buildings as the equivalent GeoJSON."""

from __future__ import annotations

import json
from pathlib import Path

import osmium
import pytest
from osmium.osm.mutable import Node, Relation, Way

from facadecli.city.footprints import read_footprints
from tests.running import facade
from tests.test_city_inputs import MANIFEST, SPEC
from tests.towns import planning_slope, write_town

ROOT = Path(__file__).resolve().parents[1]

DEG = 0.0001  # about 11 m of latitude, 5.5 m of longitude at 60° N
ORIGIN = (24.94, 60.17)


def _ring(x: float, y: float, w: float, h: float) -> list[tuple[float, float]]:
    x0, y0 = ORIGIN[0] + x * DEG, ORIGIN[1] + y * DEG
    x1, y1 = x0 + w * DEG, y0 + h * DEG
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


BUILDINGS = [  # (kind, id, outer ring, hole, tags)
    ("way", 10, _ring(0, 0, 2, 1), None, {"building": "yes", "height": "12", "name": "A"}),
    ("way", 11, _ring(4, 0, 3, 1), None, {"building": "apartments", "building:levels": "4"}),
    ("relation", 20, _ring(9, 0, 4, 2), _ring(10, 0.5, 2, 1), {"building": "yes"}),
]


def extract(path: Path) -> Path:
    """The buildings as OSM objects (and a road, which is not read), .osm or .osm.pbf."""
    writer = osmium.SimpleWriter(str(path))
    node = 0
    way_ids = {}
    for kind, oid, outer, hole, tags in BUILDINGS:
        rings = [outer] if hole is None else [outer, hole]
        for k, ring in enumerate(rings):
            ids = []
            for lon, lat in ring:
                node += 1
                writer.add_node(Node(id=node, location=(lon, lat)))
                ids.append(node)
            way = oid if kind == "way" else 100 + oid * 2 + k
            way_ids[(oid, k)] = way
            writer.add_way(Way(id=way, nodes=[*ids, ids[0]], tags=tags if kind == "way" else {}))
    writer.add_way(Way(id=999, nodes=[1, 2], tags={"highway": "residential"}))
    for kind, oid, _, _, tags in BUILDINGS:
        if kind == "relation":
            members = [("w", way_ids[(oid, 0)], "outer"), ("w", way_ids[(oid, 1)], "inner")]
            writer.add_relation(
                Relation(id=oid, members=members, tags={"type": "multipolygon", **tags})
            )
    writer.close()
    return path


def geojson(path: Path) -> Path:
    features = []
    for kind, oid, outer, hole, tags in BUILDINGS:
        rings = [[*outer, outer[0]]] + ([[*hole, hole[0]]] if hole else [])
        features.append(
            {
                "type": "Feature",
                "id": f"{kind}/{oid}",
                "properties": tags,
                "geometry": {"type": "Polygon", "coordinates": [list(map(list, r)) for r in rings]},
            }
        )
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.mark.parametrize("name", ["town.osm.pbf", "town.osm"])
def test_an_extract_gives_the_footprints_of_the_same_geojson(tmp_path: Path, name: str) -> None:
    from_osm = read_footprints(extract(tmp_path / name))
    from_json = read_footprints(geojson(tmp_path / "town.geojson"))
    assert [f.id for f in from_osm.footprints] == ["way/10", "way/11", "relation/20"]
    for a, b in zip(from_json.footprints, from_osm.footprints, strict=True):
        assert (
            a.parts[0].equals_exact(b.parts[0], 1e-6)
            or a.parts[0].symmetric_difference(b.parts[0]).area < 1e-6
        )
        assert a.properties == b.properties
    assert len(from_osm.footprints[2].parts[0].interiors) == 1  # the courtyard


def test_facade_city_builds_the_same_from_an_extract(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    built = {}
    for name in ("town.osm.pbf", "town.geojson"):
        folder = tmp_path / name.replace(".", "_")
        folder.mkdir()
        (folder / "plain.yaml").write_text(SPEC)
        source = extract(folder / name) if "osm" in name else geojson(folder / name)
        (folder / "m.yaml").write_text(MANIFEST.replace("f.geojson", source.name))
        code, _, err = facade(capsys, "city", folder / "m.yaml", "-o", folder / "out", "-j", "1")
        assert code == 0, err
        report = json.loads((folder / "out" / "town.report.json").read_text())
        built[name] = sorted(
            (b["id"], b["status"], round(b["height"], 3), b["facades"]) for b in report["buildings"]
        )
    assert built["town.osm.pbf"] == built["town.geojson"] and len(built["town.geojson"]) == 3


def test_a_file_that_is_not_an_extract_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "bad.osm.pbf").write_bytes(b"this is no protocol buffer")
    (tmp_path / "m.yaml").write_text(MANIFEST.replace("f.geojson", "bad.osm.pbf"))
    code, _, err = facade(capsys, "city", tmp_path / "m.yaml", "-o", tmp_path / "out")
    assert code == 2 and "not an OSM extract" in err and "Traceback" not in err


def test_a_bounding_box_keeps_the_footprints_inside_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "plain.yaml").write_text(SPEC)
    extract(tmp_path / "town.osm.pbf")
    (tmp_path / "m.yaml").write_text(MANIFEST.replace("f.geojson", "town.osm.pbf"))
    west = ORIGIN[0] + 3.5 * DEG  # between the first building and the second
    box = f"{west},{ORIGIN[1] - DEG},{ORIGIN[0] + 20 * DEG},{ORIGIN[1] + 5 * DEG}"
    code, _, err = facade(
        capsys, "city", tmp_path / "m.yaml", "-o", tmp_path / "out", "--bbox", box
    )
    assert code == 0, err
    report = json.loads((tmp_path / "out" / "town.report.json").read_text())
    assert sorted(b["id"] for b in report["buildings"]) == ["relation/20", "way/11"]
    assert report["summary"]["outside_bbox"] == 1
    code, _, err = facade(
        capsys, "city", tmp_path / "m.yaml", "-o", tmp_path / "o2", "--bbox", "1,2,3"
    )
    assert code == 2 and "WEST,SOUTH,EAST,NORTH" in err


@pytest.mark.parametrize("form", ["osm", "pbf"])
def test_planning_an_extract_holds_no_feature_of_it(tmp_path: Path, form: str) -> None:
    """The extract's buildings are given to the survey one at a time as libosmium draws
    them, not gathered as a document first: planning a generated town of 1,600 terraces
    (with entrances and multipolygons) peaks at a few hundred bytes a building more than
    one of 400 (tracemalloc; 2,608 B for XML and 2,453 B for PBF when the reader built
    every feature's dict first, about 450 B now, 211 B for the same town as GeoJSON)."""
    slope = planning_slope(ROOT, tmp_path, form)
    assert slope < 600, slope


def test_a_generated_extract_gives_its_entrances_and_multipolygons(tmp_path: Path) -> None:
    """The generated town as OSM (tests/towns.py): every building, the multipolygons'
    entrances read from their untagged outer ways, as from its PBF."""
    xml = write_town(tmp_path / "xml", 154, "osm")
    pbf = write_town(tmp_path / "pbf", 154, "pbf")
    found = read_footprints(xml)
    assert len(found.footprints) == 154 and not found.rejected
    doors = {f.id: f.entrances for f in found.footprints if f.entrances}
    assert len(doors) == 22 and "relation/77" in doors and "relation/154" in doors
    again = read_footprints(pbf)
    assert [(f.id, f.entrances) for f in again.footprints] == [
        (f.id, f.entrances) for f in found.footprints
    ]
