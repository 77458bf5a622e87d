"""Footprints from a Shapefile or a FlatGeobuf through pyogrio (issue 16): the same
buildings as from the equivalent GeoJSON."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely

from facadecli.city.footprints import read_footprints
from tests.running import facade
from tests.test_city_inputs import MANIFEST, SPEC, square, town
from tests.towns import planning_slope, write_town

ROOT = Path(__file__).resolve().parents[1]

pyogrio_raw = pytest.importorskip("pyogrio.raw", reason="pyogrio is a test dependency")

FEATURES = [
    square("0", 0.0, name="corner", height=9.0),
    square("1", 20.0, 10.0, name="middle", height=12.5),
    square("2", 40.0, 6.0, name="end", height=7.5),
]


def write(path: Path, driver: str, crs: str | None = "EPSG:28992") -> Path:
    features = [json.loads(f) for f in FEATURES]
    geometries = np.array(
        [shapely.to_wkb(shapely.from_geojson(json.dumps(f["geometry"]))) for f in features],
        dtype=object,
    )
    names = np.array([f["properties"]["name"] for f in features], dtype=object)
    heights = np.array([f["properties"]["height"] for f in features])
    pyogrio_raw.write(
        path,
        geometries,
        field_data=[names, heights],
        fields=["name", "height"],
        crs=crs,
        driver=driver,
        geometry_type="Polygon",
    )
    return path


@pytest.mark.parametrize(("name", "driver"), [("f.shp", "ESRI Shapefile"), ("f.fgb", "FlatGeobuf")])
def test_a_shapefile_or_flatgeobuf_gives_the_footprints_of_the_geojson(
    tmp_path: Path, name: str, driver: str
) -> None:
    manifest = town(tmp_path, FEATURES)
    from_json = read_footprints(manifest.parent / "f.geojson")
    from_file = read_footprints(write(tmp_path / name, driver))
    assert from_file.crs == "EPSG:28992"
    assert sorted(f.id for f in from_file.footprints) == ["0", "1", "2"]
    by_name = {f.properties["name"]: f for f in from_file.footprints}  # FlatGeobuf reorders
    for a in from_json.footprints:
        b = by_name[a.properties["name"]]
        assert a.parts[0].symmetric_difference(b.parts[0]).area < 1e-6
        assert b.properties == {"name": a.properties["name"], "height": a.properties["height"]}


def test_facade_city_reads_a_shapefile_and_refuses_one_without_a_crs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "plain.yaml").write_text(SPEC)
    write(tmp_path / "f.shp", "ESRI Shapefile")
    (tmp_path / "m.yaml").write_text(MANIFEST.replace("f.geojson", "f.shp"))
    code, _, err = facade(capsys, "city", tmp_path / "m.yaml", "-o", tmp_path / "out", "-j", "1")
    assert code == 0, err
    report = json.loads((tmp_path / "out" / "town.report.json").read_text())
    assert sorted(round(b["height"], 2) for b in report["buildings"]) == [7.5, 9.0, 12.5]
    (tmp_path / "f.prj").unlink()
    code, _, err = facade(capsys, "city", tmp_path / "m.yaml", "-o", tmp_path / "o2", "-j", "1")
    assert code == 2 and "no CRS" in err and "Traceback" not in err


def test_planning_a_shapefile_holds_no_record_of_it(tmp_path: Path) -> None:
    """The layer's records are given to the survey a batch at a time: planning a
    generated town of 1,600 terraces peaks at a few hundred bytes a building more than
    one of 400 (tracemalloc; 1,978 B when the whole layer was read first, about 200 B
    now, as the same town as GeoJSON)."""
    slope = planning_slope(ROOT, tmp_path, "shp")
    assert slope < 600, slope


@pytest.mark.parametrize("batch", [1, 7])
def test_a_layer_read_in_batches_is_the_layer_read_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, batch: int
) -> None:
    from facadecli.city import ogr

    path = write_town(tmp_path / "t", 30, "shp")
    whole = read_footprints(path)
    monkeypatch.setattr(ogr, "BATCH", batch)
    again = read_footprints(path)
    assert len(whole.footprints) == 30
    assert [(f.id, f.properties, f.parts) for f in again.footprints] == [
        (f.id, f.properties, f.parts) for f in whole.footprints
    ]
