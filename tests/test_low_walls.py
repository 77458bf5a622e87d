"""Small and low buildings get façades: a city without a manifest puts the cottage (one
storey, more where taller) on every wall its building's own façade does not fit, from
1.2 m long and 2.2 m high, in the building's wall material; shorter walls stay plain
(``too_short``), party walls blind. On generated footprints: a row of sheds, a short
wall, a tall narrow one."""

from __future__ import annotations

import json
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import pytest

import facadecli.city.run as city_run
from facadecli.city.building import AxisCache, Slot, rung
from facadecli.city.default import FALLBACK, default_city
from facadecli.city.run import planned, run_city
from facadecli.export.glb_merge import read_glb
from tests.khronos import VALIDATOR, validates
from tests.osm_district import box

ROOT = Path(__file__).resolve().parent.parent
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
        _feature(f"shed-{k}", box(4.0 * k, 0.0, 4.0, 6.0), building="shed", height=height)
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
    narrow = _feature("narrow", box(0.0, 0.0, 2.0, 6.0), building="yes", height=3.0)
    # a 1 m jog: two walls of 1.0 m, too short for any layout
    jog = [(20.0, 0.0), (28.0, 0.0), (28.0, 5.0), (27.0, 5.0), (27.0, 6.0), (20.0, 6.0)]
    stepped = _feature("stepped", jog, building="yes", height=3.0)
    built = _run(tmp_path, [narrow, stepped])
    assert built["narrow"]["plain"] == {} and built["narrow"]["facades"] == 4
    assert built["stepped"]["plain"] == {"too_short": 2}
    assert built["stepped"]["facades"] == 4


def test_a_tall_narrow_wall_gets_a_storey_of_windows_a_floor(tmp_path: Path) -> None:
    tower = _feature("tower", box(0.0, 0.0, 2.0, 12.0), building="yes", height=9.0)
    built = _run(tmp_path, [tower])
    assert built["tower"]["plain"] == {} and built["tower"]["facades"] == 4


def test_a_fallback_wall_wears_its_buildings_wall_material(tmp_path: Path) -> None:
    """A block of flats one storey high (the terraced house's render) gets the cottage in
    render, not in the cottage's own brick: one material for the whole building's walls."""
    flats = _feature("flats", box(0.0, 0.0, 10.0, 6.0), building="apartments", height=3.0)
    built = _run(tmp_path, [flats])
    assert built["flats"]["facades"] == 4
    document, _ = read_glb((tmp_path / "out" / built["flats"]["file"]).read_bytes())
    names = {material["name"] for material in document["materials"]}
    assert "render" in names and "brick" not in names, names


@pytest.mark.parametrize("height", [2.6, 2.9])
def test_low_buildings_give_the_same_bytes_on_every_run(tmp_path: Path, height: float) -> None:
    """The same footprints (and the default city's seed, 0) give the same bytes."""
    runs = []
    for run in range(2):
        folder = tmp_path / f"run{run}"
        _run(folder, _sheds(3, height=height))
        runs.append((folder / "out" / "sheds.glb").read_bytes())
    assert runs[0] == runs[1]


def test_a_manifest_naming_a_missing_fallback_is_refused_at_its_line(tmp_path: Path) -> None:
    from facadecli.city.manifest import load_city
    from facadecli.errors import SpecError

    (tmp_path / "sheds.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "crs": CRS, "features": _sheds(1)})
    )
    manifest = tmp_path / "city.yaml"
    townhouse = ROOT / "specs" / "townhouse.yaml"
    manifest.write_text(
        "version: 1\nname: sheds\nfootprints: sheds.geojson\ndefaults:\n"
        f"  facade: {townhouse}\n  fallback_facade: nowhere/cottage.yaml\n"
    )
    with pytest.raises(SpecError) as raised:
        load_city(manifest)
    text = str(raised.value)
    assert f"{manifest}:6:20" in text and "nowhere/cottage.yaml" in text, text


def test_rays_at_35_degrees_meet_every_low_building(tmp_path: Path) -> None:
    """The cottage's windows are backed like every window: no ray at 35° from eight
    directions passes through a shed, a short-walled house or a narrow tall one."""
    from tests.rays import city_leaks

    narrow = _feature("narrow", box(30.0, 0.0, 2.5, 6.0), building="yes", height=9.0)
    flats = _feature("flats", box(40.0, 0.0, 10.0, 6.0), building="apartments", height=3.4)
    _run(tmp_path, [*_sheds(3), narrow, flats])
    count, leaks = city_leaks(tmp_path / "out" / "sheds.glb")
    assert count == 5
    assert not leaks, leaks[:5]


def test_a_low_building_passes_the_khronos_validator(tmp_path: Path) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    built = _run(tmp_path, _sheds(2))
    for glb in [
        tmp_path / "out" / "sheds.glb",
        *(tmp_path / "out" / e["file"] for e in built.values()),
    ]:
        validates(glb)


def test_the_cottage_has_a_layout_at_every_rung_a_city_solves_from_the_shortest_wall() -> None:
    """A city solves a wall at the nearest of a ladder of lengths 2 % apart: every rung
    from the one nearest ``MIN_FACADE_WIDTH`` up has a layout of the cottage, across and
    up (a minimum of exactly 1.2 m left the rung of 1.195 m, walls of 1.2 to 1.207 m,
    without one: a wall of Delft's was ``no_layout``)."""
    from facadecli import load_spec
    from facadecli.city.building import rung, rung_length, solve_rung
    from facadecli.city.default import MIN_FACADE_WIDTH

    spec = load_spec(ROOT / "specs" / "cottage.yaml")
    for axis, top in (("x", 20.0), ("y", 12.0)):
        steps = range(rung(MIN_FACADE_WIDTH), rung(top) + 1)
        missing = [rung_length(s) for s in steps if not solve_rung(spec, axis, rung_length(s))]
        assert not missing, (axis, missing)


def test_the_cottages_storeys_are_a_storey_high_on_every_wall_height() -> None:
    """On every rung of wall heights from 2.2 to 12 m the cottage's storeys are at least
    2 m apart, and a wall up to 4 m (a one-storey building under a flat roof, its walls
    full height) has one: at 3.6 to 4.25 m it drew two rows of windows 1.8 m apart, and
    four on a 9 m wall."""
    from facadecli import load_spec
    from facadecli.city.building import rung_length, solve_rung

    spec = load_spec(ROOT / "specs" / "cottage.yaml")
    for step in range(rung(2.2), rung(12.0) + 1):
        height = rung_length(step)
        (layout,) = solve_rung(spec, "y", height)
        storeys = [letter.symbol for letter in layout.letters[0]].count("G")
        assert height / storeys >= 2.0, (height, storeys)
        assert height > 4.0 or storeys == 1, (height, storeys)


class _Asked(AxisCache):
    """An axis cache that remembers every axis a building asks it for."""

    def __init__(self, axes: dict[Slot, Any]) -> None:
        super().__init__(axes=dict(axes))
        self.asked: set[Slot] = set()

    def _layouts(self, key: str, spec: Any, axis: str, length: float, variants: int) -> Any:
        self.asked.add((key, axis, rung(length), variants))
        return super()._layouts(key, spec, axis, length, variants)


def _now(function: Any, *args: Any) -> Future[Any]:
    """A pool's submit, run here and now."""
    done: Future[Any] = Future()
    done.set_result(function(*args))
    return done


def test_a_run_solves_ahead_the_fallbacks_axes_only_for_walls_that_need_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Solved ahead (a run of several processes), the fallback's axes are those of the
    walls their own façade does not fit, not of every wall (the houses' walls all fit the
    townhouse), and they are all the buildings ask for: none is solved while building."""
    features = [
        _feature(f"house-{k}", box(20.0 * k, 0.0, 9.0 + k, 11.0), building="house", height=9.0)
        for k in range(3)
    ]
    features += _sheds(2, height=3.0)
    features.append(_feature("tower", box(0.0, 30.0, 2.0, 12.0), building="yes", height=9.0))
    folder = tmp_path / "in"
    folder.mkdir()
    footprints = folder / "town.geojson"
    footprints.write_text(
        json.dumps({"type": "FeatureCollection", "crs": CRS, "features": features})
    )
    tasks = list(planned(default_city(footprints), tmp_path / "out").tasks)
    solved = city_run._presolve(_now, tasks, 2)
    cache = _Asked(solved)
    monkeypatch.setitem(city_run._CACHE, "axes", cache)
    for task in tasks:
        assert city_run.build(task)["status"] == "ok"
    assert cache.solved == 0  # every axis a building asked for was solved ahead
    fallback = {slot for slot in solved if Path(slot[0].split("#")[0]).stem == FALLBACK}
    assert fallback, "the sheds and the tower take the cottage"
    assert fallback <= cache.asked, sorted(fallback - cache.asked)
