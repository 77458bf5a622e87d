"""Small and low buildings get façades: a city without a manifest puts the cottage (one
storey, more where taller) on every wall its building's own façade does not fit, from
1.2 m long and 2.2 m high, in the building's wall material; shorter walls stay plain
(``too_short``), party walls blind. On generated footprints: a row of sheds, a short
wall, a tall narrow one."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from facadecli.city.default import default_city
from facadecli.city.run import run_city
from facadecli.export.glb_merge import read_glb

CRS = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}
X0, Y0 = 85000.0, 447000.0  # somewhere in the Netherlands, in metres


def _feature(ident: str, ring: list[tuple[float, float]], **tags: Any) -> dict[str, Any]:
    closed = [[X0 + x, Y0 + y] for x, y in [*ring, ring[0]]]
    return {
        "type": "Feature",
        "id": ident,
        "properties": tags,
        "geometry": {"type": "Polygon", "coordinates": [closed]},
    }


def _box(x: float, y: float, width: float, depth: float) -> list[tuple[float, float]]:
    return [(x, y), (x + width, y), (x + width, y + depth), (x, y + depth)]


def _run(folder: Path, features: list[dict[str, Any]]) -> dict[str, Any]:
    folder.mkdir(parents=True, exist_ok=True)
    footprints = folder / "sheds.geojson"
    collection = {"type": "FeatureCollection", "crs": CRS, "features": features}
    footprints.write_text(json.dumps(collection))
    report = run_city(default_city(footprints), folder / "out", jobs=1)
    assert report["summary"]["ok"] == len(features)
    return {entry["id"]: entry for entry in report["buildings"]}


def _sheds(count: int, height: float = 3.0) -> list[dict[str, Any]]:
    """A row of ``count`` sheds 4 m wide, 6 m deep, side by side (party walls between)."""
    return [
        _feature(f"shed-{k}", _box(4.0 * k, 0.0, 4.0, 6.0), building="shed", height=height)
        for k in range(count)
    ]


def test_a_row_of_low_sheds_gets_facades_on_every_free_wall(tmp_path: Path) -> None:
    built = _run(tmp_path, _sheds(4))
    for ident, entry in built.items():
        end = ident in ("shed-0", "shed-3")
        party = 1 if end else 2
        assert entry["plain"] == {"party": party}, (ident, entry["plain"])
        assert entry["facades"] == 4 - party, ident


def test_a_short_wall_gets_a_facade_and_a_shorter_one_stays_plain(tmp_path: Path) -> None:
    narrow = _feature("narrow", _box(0.0, 0.0, 2.0, 6.0), building="yes", height=3.0)
    # a 1 m jog: two walls of 1.0 m, too short for any layout
    jog = [(20.0, 0.0), (28.0, 0.0), (28.0, 5.0), (27.0, 5.0), (27.0, 6.0), (20.0, 6.0)]
    stepped = _feature("stepped", jog, building="yes", height=3.0)
    built = _run(tmp_path, [narrow, stepped])
    assert built["narrow"]["plain"] == {} and built["narrow"]["facades"] == 4
    assert built["stepped"]["plain"] == {"too_short": 2}
    assert built["stepped"]["facades"] == 4


def test_a_tall_narrow_wall_gets_a_storey_of_windows_a_floor(tmp_path: Path) -> None:
    tower = _feature("tower", _box(0.0, 0.0, 2.0, 12.0), building="yes", height=9.0)
    built = _run(tmp_path, [tower])
    assert built["tower"]["plain"] == {} and built["tower"]["facades"] == 4


def test_a_fallback_wall_wears_its_buildings_wall_material(tmp_path: Path) -> None:
    """A block of flats one storey high (the terraced house's render) gets the cottage in
    render, not in the cottage's own brick: one material for the whole building's walls."""
    flats = _feature("flats", _box(0.0, 0.0, 10.0, 6.0), building="apartments", height=3.0)
    built = _run(tmp_path, [flats])
    assert built["flats"]["facades"] == 4
    document, _ = read_glb((tmp_path / "out" / built["flats"]["file"]).read_bytes())
    names = {material["name"] for material in document["materials"]}
    assert "render" in names and "brick" not in names, names


@pytest.mark.parametrize("seed", [0, 3])
def test_low_buildings_give_the_same_bytes_for_the_same_seed(tmp_path: Path, seed: int) -> None:
    runs = []
    for run in range(2):
        folder = tmp_path / f"run{run}"
        _run(folder, _sheds(3, height=2.6 + 0.1 * seed))
        runs.append((folder / "out" / "sheds.glb").read_bytes())
    assert runs[0] == runs[1]
