"""OSM read as mappers mean it (issue 36): a small OSM XML district of our own
(tests/osm_district.py) builds as Simple 3D Buildings says, checked on the geometry:
roofs at party walls, the roof of a podium round the tower standing on it, one façade on
a wall drawn with extra nodes, no walls under a carport, parts taking their outline's
tags, every roof shape, and what is not understood warned and counted."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import trimesh

from facadecli.city.manifest import load_city
from facadecli.city.run import run_city, safe_name
from facadecli.city.s3db import COLOURS, colour, tag_problems
from facadecli.city.straight import merged_ring
from tests.osm_district import ROOF_SHAPES, box, write_district
from tests.running import facade
from tests.test_s3db import SPEC

MANIFEST = """\
version: 1
name: d
footprints: d.osm
defaults:
  facade: plain.yaml
  roof: {{type: flat}}
{extra}"""


def _district(folder: Path, jobs: int = 1, extra: str = "") -> dict[str, Any]:
    write_district(folder / "d.osm")
    (folder / "plain.yaml").write_text(SPEC)
    (folder / "d.yaml").write_text(MANIFEST.format(extra=extra))
    return run_city(load_city(folder / "d.yaml"), folder / "out", jobs=jobs)


@pytest.fixture(scope="module")
def district(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    folder = tmp_path_factory.mktemp("district")
    return folder, _district(folder)


def _entry(report: dict[str, Any], oid: int) -> dict[str, Any]:
    return next(b for b in report["buildings"] if b["id"] == f"way/{oid}")


def _mesh(folder: Path, oid: int, material: str) -> trimesh.Trimesh:
    scene = trimesh.load(folder / "out" / "buildings" / f"{safe_name(f'way/{oid}')}.glb")
    return scene.geometry[f"way/{oid}/{material}"]


def _ridge_reach(roof: trimesh.Trimesh) -> tuple[float, float]:
    """How far short of the roof's two ends (west, east) its ridge (its highest points)
    stops, along the ridge: 0 where the roof runs on to the end wall at its top. (The
    UTM grid turns the map a little: x is not quite east.)"""
    flat, up = roof.vertices[:, [0, 2]], roof.vertices[:, 1]
    ridge = flat[up > up.max() - 0.01]
    ends = ridge[np.argsort(ridge[:, 0])[[0, -1]]]
    axis = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
    along, on_ridge = flat @ axis, ridge @ axis
    return float(on_ridge.min() - along.min()), float(along.max() - on_ridge.max())


def test_a_terrace_of_hipped_houses_has_no_valleys(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    # the end houses are hipped at their free ends and run on to their party walls; the
    # middle house runs on to both: one ridge along the terrace, no V between roofs
    west, east = _ridge_reach(_mesh(folder, 100, "roof"))
    assert west > 3.0 and east < 0.05
    west, east = _ridge_reach(_mesh(folder, 101, "roof"))
    assert west < 0.05 and east < 0.05
    west, east = _ridge_reach(_mesh(folder, 102, "roof"))
    assert west < 0.05 and east > 3.0
    # the ridges meet at one height
    tops = [_mesh(folder, oid, "roof").vertices[:, 1].max() for oid in (100, 101, 102)]
    assert max(tops) - min(tops) < 1e-6
    assert [_entry(report, oid)["plain"] for oid in (100, 101, 102)] == [
        {"party": 1},
        {"party": 2},
        {"party": 1},
    ]


def test_the_podium_roof_runs_into_the_tower_not_through_it(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, report = district
    tower = _mesh(folder, 503, "render")  # the façades' wall material
    (x0, _, z0), (x1, _, z1) = tower.bounds
    roof = _mesh(folder, 502, "roof")
    middles = roof.triangles_center
    inside = (
        (middles[:, 0] > x0 + 0.2)
        & (middles[:, 0] < x1 - 0.2)
        & (middles[:, 2] > z0 + 0.2)
        & (middles[:, 2] < z1 - 0.2)
    )
    assert not inside.any()  # no piece of the podium's roof inside the tower
    # the tower, 30 m on a 10 m podium, keeps its façades all round
    assert _entry(report, 503)["facades"] == 4 and _entry(report, 503)["party_walls"] == 0


def test_a_wall_drawn_with_nodes_on_a_line_is_one_facade(
    district: tuple[Path, dict[str, Any]], tmp_path: Path
) -> None:
    _, report = district
    assert _entry(report, 300)["facades"] == 4
    assert report["summary"]["collinear_nodes_merged"] == 3
    # with the merging off, every node starts a façade again
    off = _district(tmp_path, extra="  collinear_angle: 0\n")
    assert _entry(off, 300)["facades"] == 7
    assert off["summary"]["collinear_nodes_merged"] == 0


def test_collinear_runs_merge_but_curves_and_shared_nodes_stay() -> None:
    line = [(0.0, 0.0), (10.0, 0.1), (20.0, -0.1), (30.0, 0.0), (30.0, 10.0), (0.0, 10.0)]
    assert merged_ring(line, 3.0) == [(0.0, 0.0), (30.0, 0.0), (30.0, 10.0), (0.0, 10.0)]
    # a node a neighbour shares stays: a party wall's end is a wall's end
    kept = merged_ring(line, 3.0, lambda p: p == (20.0, -0.1))
    assert (20.0, -0.1) in kept and (10.0, 0.1) not in kept
    # a 64-gon turns 5.6° a node: no two of its edges run within 3° of each other
    circle = [
        (10 * math.cos(k * math.tau / 64), 10 * math.sin(k * math.tau / 64)) for k in range(64)
    ]
    assert len(merged_ring(circle, 3.0)) == 64
    # a 720-gon (0.5° a node): runs of 6 or 7 edges, still a round of walls
    fine = [
        (10 * math.cos(k * math.tau / 720), 10 * math.sin(k * math.tau / 720)) for k in range(720)
    ]
    assert 100 <= len(merged_ring(fine, 3.0)) <= 180


def test_a_carport_is_a_roof_on_posts(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    entry = _entry(report, 200)
    assert entry["facades"] == 0 and entry["plain_walls"] == 0 and entry["height"] == 2.5
    walls = _mesh(folder, 200, "render")  # the spec's wall material: nothing but posts
    for post in walls.split(only_watertight=False):
        (x0, _, z0), (x1, _, z1) = post.bounds
        assert x1 - x0 < 0.3 and z1 - z0 < 0.3  # posts, no wall
    assert len(walls.split(only_watertight=False)) >= 4
    roof = _mesh(folder, 200, "flat_roof")  # the manifest's roof: flat
    assert roof.bounds[1][1] == pytest.approx(2.5, abs=1e-3)


def test_parts_take_the_tags_of_their_outline(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    assert _entry(report, 501)["height"] == 12.0  # the outline's height, roof and colours
    assert _entry(report, 502)["height"] == 10.0  # its own
    scene = trimesh.load(folder / "out" / "buildings" / f"{safe_name('way/501')}.glb")
    roof = scene.geometry["way/501/roof"].visual.material  # tiles drawn in papayawhip
    assert list(roof.baseColorFactor[:3]) == [255, 255, 255]  # the colour is in the picture
    drawn = np.asarray(roof.baseColorTexture.convert("RGB"), dtype=float).reshape(-1, 3)
    assert drawn.mean(axis=0) == pytest.approx([255, 239, 213], abs=16)  # #ffefd5, a CSS name
    ridge = scene.geometry["way/501/roof"].vertices[:, 1]
    assert ridge.max() - ridge.min() == pytest.approx(2.0, abs=1e-3)  # roof:height 2


def test_heights_in_feet(district: tuple[Path, dict[str, Any]]) -> None:
    _, report = district
    assert _entry(report, 400)["height"] == pytest.approx(12.192)


def test_every_roof_shape_builds(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    for k, shape in enumerate(ROOF_SHAPES):
        entry = _entry(report, 700 + k)
        assert entry["status"] == "ok", shape
        if shape != "flat":
            roof = _mesh(folder, 700 + k, "roof")
            up = roof.vertices[:, 1]
            assert up.max() - up.min() == pytest.approx(3.0, abs=0.25), shape  # roof:height
    # side_hipped: hipped at one end, a gable at the other
    west, east = _ridge_reach(_mesh(folder, 700 + ROOF_SHAPES.index("side_hipped"), "roof"))
    assert min(west, east) < 0.05 and max(west, east) > 3.0
    west, east = _ridge_reach(_mesh(folder, 700 + ROOF_SHAPES.index("hipped"), "roof"))
    assert min(west, east) > 3.0
    # crosspitched: two gables crossing, their ridges reaching all four walls
    roof = _mesh(folder, 700 + ROOF_SHAPES.index("crosspitched"), "roof")
    flat, up = roof.vertices[:, [0, 2]], roof.vertices[:, 1]
    ridges = flat[up > up.max() - 0.01]
    assert np.ptp(ridges, axis=0) == pytest.approx(np.ptp(flat, axis=0), abs=0.5)  # grid turn
    walls = _mesh(folder, 700 + ROOF_SHAPES.index("crosspitched"), "render")  # as the façades
    heights = walls.vertices[walls.faces][:, :, 1]
    gables = (heights.min(axis=1) >= up.min() - 1e-3) & (heights.max(axis=1) > up.min() + 1e-3)
    assert gables.sum() == 4  # the four gable ends, above the eaves


def test_a_sawtooth_roof_is_sheds_side_by_side(district: tuple[Path, dict[str, Any]]) -> None:
    folder, _ = district
    roof = _mesh(folder, 800, "roof")
    up = roof.vertices[:, 1]
    assert up.max() == pytest.approx(10.0, abs=1e-3) and up.min() == pytest.approx(7.0, abs=1e-3)
    # three teeth over 20 m: three high edges, each above the low edge of the next
    north = -roof.vertices[:, 2]  # the world's z runs south
    highs = np.sort(north[up > 9.99])  # (the UTM grid turns them a little off east)
    assert 1 + int((np.diff(highs) > 2.0).sum()) == 3
    walls = _mesh(folder, 800, "render")  # the façades' wall material, as the gables'
    risers = walls.submesh([walls.vertices[walls.faces][:, :, 1].max(axis=1) > 7.0 + 1e-3])[0]
    # the glazed risers and the sides above the eaves: vertical
    assert np.abs(risers.face_normals[risers.area_faces > 1e-9, 1]).max() < 1e-6
    facing = risers.face_normals[risers.area_faces > 1e-9]
    assert (facing[:, 2] < -0.99).sum() > 0  # some face north (-z): the glazing


def test_what_is_not_understood_is_warned_and_counted(
    district: tuple[Path, dict[str, Any]],
) -> None:
    _, report = district
    warned = {(w["id"], w["warning"].split(" ", 1)[0]) for w in report["warnings"]}
    assert ("way/600", "roof:shape") in warned and ("way/600", "building:colour") in warned
    unbuilt = {"zakomar"}  # built as a dome, warned
    for shape in unbuilt:
        oid = 700 + ROOF_SHAPES.index(shape)
        assert (f"way/{oid}", "roof:shape") in warned
    counts = report["summary"]["warnings_by_tag"]
    assert counts == {"building:colour": 1, "roof:shape": 1 + len(unbuilt)}
    assert report["summary"]["warnings"] == len(report["warnings"]) == sum(counts.values())
    # every other shape S3DB lists is understood: no warning
    for shape in set(ROOF_SHAPES) - unbuilt:
        assert tag_problems({"roof:shape": shape}) == []


def test_every_css_colour_name() -> None:
    assert colour("rebeccapurple") == "#663399" and colour("Papaya Whip") == "#ffefd5"
    css = [name for name in COLOURS if name not in ("cream", "terracotta")]
    assert len(css) == 148 and all(colour(name) == COLOURS[name] for name in css)
    assert tag_problems({"building:colour": "lightgoldenrodyellow"}) == []
    assert tag_problems({"roof:colour": "#12345"})  # neither #rgb nor #rrggbb
    assert tag_problems({"roof:direction": "sideways", "roof:orientation": "diagonal"})


def test_plain_walls_carry_their_reason(tmp_path: Path) -> None:
    report = _district(tmp_path, extra="  min_facade_width: 9.0\n")  # the default: 2 m
    plain = report["summary"]["plain_walls"]
    assert plain["party"] == 6 and plain["too_short"] > 0
    total = sum(b["plain_walls"] for b in report["buildings"])
    assert sum(plain.values()) == total
    for entry in report["buildings"]:
        assert sum(entry["plain"].values()) == entry["plain_walls"]


def test_the_same_district_gives_the_same_bytes_on_one_or_two_workers(
    district: tuple[Path, dict[str, Any]], tmp_path: Path
) -> None:
    folder, report = district
    again = _district(tmp_path, jobs=2)
    assert (tmp_path / "out" / "d.glb").read_bytes() == (folder / "out" / "d.glb").read_bytes()
    for name in ("d.city.json",):
        assert (tmp_path / "out" / name).read_bytes() == (folder / "out" / name).read_bytes()

    def steady(found: dict[str, Any]) -> str:
        found = json.loads(json.dumps(found))
        found["summary"].pop("seconds")
        for entry in found["buildings"]:
            entry.pop("time_ms")
        return json.dumps(found, sort_keys=True)

    assert steady(again) == steady(report)


def test_a_value_not_understood_is_warned_once(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    junk = {"building": "yes", "roof:shape": "banana"}
    write_district(tmp_path / "d.osm", [(k, box(12 * k, 0, 10, 10), junk) for k in range(1, 4)])
    (tmp_path / "plain.yaml").write_text(SPEC)
    (tmp_path / "d.yaml").write_text(MANIFEST.format(extra=""))
    code, _, err = facade(capsys, "city", tmp_path / "d.yaml", "-o", tmp_path / "out", "-j", "1")
    lines = [line for line in err.splitlines() if "banana" in line]
    assert code == 0 and len(lines) == 1, err
    assert lines[0].startswith(f"{tmp_path / 'd.osm'}:") and "(and 2 more features" in lines[0]
    report = json.loads((tmp_path / "out" / "d.report.json").read_text())
    assert report["summary"]["warnings_by_tag"] == {"roof:shape": 3}
