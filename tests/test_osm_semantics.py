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
import shapely
import trimesh

from facadecli.city.building import ROOF_NAME
from facadecli.city.folders import building_file
from facadecli.city.lods import feature_of, lod_meshes
from facadecli.city.manifest import load_city
from facadecli.city.run import run_city
from facadecli.city.s3db import COLOURS, colour, tag_problems
from facadecli.city.straight import merged_ring
from tests.osm_district import ROOF_SHAPES, box, write_district
from tests.running import facade
from tests.test_cityjson import _check_valid
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
    scene = trimesh.load(folder / "out" / building_file(f"way/{oid}"))
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


def _above(mesh: trimesh.Trimesh, height: float) -> trimesh.Trimesh:
    """The triangles of a mesh that rise above ``height`` from it (the walls over the
    eaves, where the façades' wall material also dresses the façades below them)."""
    heights = mesh.vertices[mesh.faces][:, :, 1]
    keep = (heights.min(axis=1) >= height - 1e-3) & (heights.max(axis=1) > height + 1e-3)
    return mesh.submesh([np.flatnonzero(keep)], append=True)


def _pieces(mesh: trimesh.Trimesh) -> list[trimesh.Trimesh]:
    """The mesh's pieces whose triangles share edges (pieces touching at a point apart)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    keys = np.round(mesh.vertices, 4)
    _, ids = np.unique(keys, axis=0, return_inverse=True)
    faces = ids.reshape(-1)[mesh.faces]
    edges = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, edge_ids = np.unique(edges, axis=0, return_inverse=True)
    owner = np.repeat(np.arange(len(faces)), 3)
    graph = coo_matrix((np.ones(len(owner)), (owner, edge_ids.reshape(-1))))
    both = graph @ graph.T  # faces sharing an edge
    count, label = connected_components(both, directed=False)
    return [mesh.submesh([np.flatnonzero(label == k)], append=True) for k in range(count)]


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


def test_the_terrace_s_lod2_roofs_know_their_party_walls_too(
    district: tuple[Path, dict[str, Any]],
) -> None:
    """The CityJSON solids (and so the LOD1/LOD2 models and 3D Tiles made from them)
    take their party walls from where the glb's roofs do: one ridge along the terrace,
    the same as the glb's, each solid closed, its gable end at the party wall a wall."""
    folder, _ = district
    for oid, (west_free, east_free) in {
        100: (True, False),
        101: (False, False),
        102: (False, True),
    }.items():
        feature = feature_of(folder / "out" / building_file(f"way/{oid}"))
        (solid,) = [g for o in feature["CityObjects"].values() for g in o.get("geometry", [])]
        assert solid["type"] == "Solid"
        roof = lod_meshes(feature, 2)[ROOF_NAME]
        west, east = _ridge_reach(roof)
        assert (west > 3.0, east > 3.0) == (west_free, east_free), (oid, west, east)
        assert (west < 0.05, east < 0.05) == (not west_free, not east_free), (oid, west, east)
        glb = _mesh(folder, oid, "roof")
        assert roof.vertices[:, 1].max() == pytest.approx(glb.vertices[:, 1].max(), abs=2e-3)
        assert roof.area == pytest.approx(glb.area, rel=1e-3)


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
    # the tower, 30 m on a 10 m podium, keeps its façades all round, from the podium's
    # eaves (10 m less its 2 m hipped roof) up: none inside the podium
    assert _entry(report, 503)["facades"] == 4 and _entry(report, 503)["party_walls"] == 0
    # (less the centimetre of its underside, which wears the wall material too)
    assert tower.bounds[0][1] == pytest.approx(8.0 - 0.01, abs=1e-3)
    assert tower.bounds[1][1] == pytest.approx(30.0, abs=0.3)


def test_a_tower_part_on_a_flat_podium_part_starts_on_its_roof(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, report = district
    # 12 levels of 3 m on a podium of 3: façades from 9 m to 36 m, none inside the podium
    facades = _mesh(folder, 902, "render")
    assert facades.bounds[0][1] == pytest.approx(9.0 - 0.01, abs=1e-3)  # and its underside
    assert _entry(report, 902)["facades"] == 4
    # its pyramid 13'6" high
    roof = _mesh(folder, 902, "roof").vertices[:, 1]
    assert roof.max() - roof.min() == pytest.approx(13.5 * 0.3048, abs=1e-3)
    assert _entry(report, 902)["height"] == pytest.approx(36 + 13.5 * 0.3048, abs=1e-3)
    # the podium's flat roof is left out under the tower
    podium = _mesh(folder, 901, "flat_roof")
    (x0, _, z0), (x1, _, z1) = facades.bounds
    middles = podium.triangles_center
    inside = (middles[:, 0] > x0 + 0.5) & (middles[:, 0] < x1 - 0.5)
    inside &= (middles[:, 2] > z0 + 0.5) & (middles[:, 2] < z1 - 0.5)
    assert not inside.any()
    document = json.loads((folder / "out" / "d.city.json").read_text())
    tower = document["CityObjects"]["way/900"]
    assert tower["attributes"]["name"] == "Tower" and tower["children"] == ["way/901", "way/902"]


@pytest.mark.parametrize(
    ("podium", "tower", "cover", "tower_area"),
    [(502, 503, "roof", 64.0), (901, 902, "flat_roof", 100.0)],
)
def test_the_podium_s_lod2_roof_leaves_the_tower_out_as_the_glb_s_does(
    district: tuple[Path, dict[str, Any]], podium: int, tower: int, cover: str, tower_area: float
) -> None:
    """The podium's CityJSON solid (and so its LOD2 model and 3D Tiles) has the glb's
    roof: none of it inside the tower standing on it, the same area; the solid is closed
    at the podium's eaves under the tower by a ClosureSurface, which the LOD2 model does
    not draw (the tower stands on it)."""
    folder, _ = district
    feature = feature_of(folder / "out" / building_file(f"way/{podium}"))
    (solid,) = [g for o in feature["CityObjects"].values() for g in o.get("geometry", [])]
    assert solid["type"] == "Solid"
    kinds = [surface["type"] for surface in solid["semantics"]["surfaces"]]
    closure = kinds.index("ClosureSurface")
    (closed,) = [k for k, value in enumerate(solid["semantics"]["values"][0]) if value == closure]
    points = np.asarray(feature["vertices"]) * 0.001
    under = points[solid["boundaries"][0][closed][0]]
    facades = _mesh(folder, tower, "render")
    assert np.ptp(under[:, 2]) < 1e-9  # level, at the podium's eaves: the tower's base
    assert under[:, 2].max() == pytest.approx(facades.bounds[0][1] + 0.01, abs=2e-3)
    tower_plan = shapely.Polygon(under[:, :2])
    assert tower_plan.area == pytest.approx(tower_area, rel=1e-2)  # (UTM scale, degrees)
    within = tower_plan.buffer(-0.2)

    def inside(mesh: trimesh.Trimesh) -> np.ndarray:  # glTF frame: x east, y up, z south
        middles = mesh.triangles_center
        return shapely.contains_xy(within, middles[:, 0], -middles[:, 2])

    roof = lod_meshes(feature, 2)[ROOF_NAME]
    assert not inside(roof).any()
    glb = _mesh(folder, podium, cover)
    top = glb.area_faces[glb.face_normals[:, 1] > 0.1].sum()  # a flat roof is a slab
    assert roof.area == pytest.approx(top, rel=1e-3)
    walls = lod_meshes(feature, 2)["wall"]
    assert not (inside(walls) & (walls.triangles_center[:, 1] > 0.1)).any()  # no closure


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
    # building=carport too, its gable ends open; one storey (3 m) and its roof high
    entry = _entry(report, 210)
    assert entry["facades"] == 0 and entry["plain_walls"] == 0 and entry["height"] == 4.0
    gabled = _mesh(folder, 210, "render")  # posts only: no gable ends
    assert all(np.ptp(p.vertices[:, [0, 2]], axis=0).max() < 0.3 for p in _pieces(gabled))
    # in CityJSON each is one closed solid, the roof on a slab whose underside is a
    # ceiling, at the top of the posts: no walls down to the ground
    document = json.loads((folder / "out" / "d.city.json").read_text())
    scale = document["transform"]["scale"][2]
    for oid, eaves in ((200, 2.5), (210, 3.0)):
        (geometry,) = document["CityObjects"][f"way/{oid}"]["geometry"]
        assert geometry["type"] == "Solid"
        kinds = {s["type"] for s in geometry["semantics"]["surfaces"]}
        assert kinds == {"OuterCeilingSurface", "WallSurface", "RoofSurface"}
        used = {i for surface in geometry["boundaries"][0] for ring in surface for i in ring}
        low = min(document["vertices"][i][2] for i in used) * scale
        assert low == pytest.approx(eaves - 0.2, abs=1e-3)
        # its posts: a BuildingInstallation child, each post a closed box from the
        # ground to the eaves, as many as the glb's
        assert document["CityObjects"][f"way/{oid}"]["children"] == [f"way/{oid}-posts"]
        posts = document["CityObjects"][f"way/{oid}-posts"]
        assert posts["type"] == "BuildingInstallation" and posts["parents"] == [f"way/{oid}"]
        (solids,) = posts["geometry"]
        assert solids["type"] == "MultiSolid"
        assert len(solids["boundaries"]) == len(_pieces(_mesh(folder, oid, "render"))) >= 4
        for (shell,) in solids["boundaries"]:
            edges = [
                e
                for surface in shell
                for ring in surface
                for e in zip(ring, ring[1:] + ring[:1], strict=True)
            ]
            assert len(shell) == 6 and len(set(edges)) == 24
            assert all((b, a) in edges for a, b in edges)  # closed, each edge both ways
            heights = [document["vertices"][i][2] * scale for s in shell for r in s for i in r]
            assert min(heights) == 0 and max(heights) == pytest.approx(eaves, abs=1e-3)


def test_parts_take_the_tags_of_their_outline(district: tuple[Path, dict[str, Any]]) -> None:
    folder, report = district
    assert _entry(report, 501)["height"] == 12.0  # the outline's height, roof and colours
    assert _entry(report, 502)["height"] == 10.0  # its own
    glb = folder / "out" / building_file("way/501")  # its pictures are in the run's textures/
    scene = trimesh.load(glb, resolver=trimesh.resolvers.FilePathResolver(glb, allow_anywhere=True))
    roof = scene.geometry["way/501/roof"].visual.material  # tiles drawn in papayawhip
    assert list(roof.baseColorFactor[:3]) == [255, 255, 255]  # the colour is in the picture
    drawn = np.asarray(roof.baseColorTexture.convert("RGB"), dtype=float).reshape(-1, 3)
    assert drawn.mean(axis=0) == pytest.approx([255, 239, 213], abs=16)  # #ffefd5, a CSS name
    ridge = scene.geometry["way/501/roof"].vertices[:, 1]
    assert ridge.max() - ridge.min() == pytest.approx(2.0, abs=1e-3)  # roof:height 2


def test_the_cityjson_keeps_the_buildings_structure(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, _ = district
    document = json.loads((folder / "out" / "d.city.json").read_text())
    _check_valid(document, apart=False)  # the 2.0.2 schemas, parents and children, vertices
    objects = document["CityObjects"]
    # the outline is the Building, with its tags; its parts are its BuildingParts
    outline = objects["way/500"]
    assert outline["type"] == "Building" and "geometry" not in outline
    assert outline["children"] == ["way/501", "way/502", "way/503"]
    assert outline["attributes"]["building:colour"] == "rebeccapurple"
    assert outline["attributes"]["measuredHeight"] == 30.0  # its tallest part
    for key in outline["children"]:
        assert objects[key]["type"] == "BuildingPart" and objects[key]["parents"] == ["way/500"]
    assert [k for k, o in objects.items() if o["type"] == "Building" and "parents" in o] == []
    # numbers as numbers: heights in metres (feet read), levels as counts
    assert (
        outline["attributes"]["height"] == 12.0
        and objects["way/501"]["attributes"]["height"] == 12.0
    )
    assert objects["way/400"]["attributes"]["height"] == pytest.approx(12.192)
    assert objects["way/100"]["attributes"]["building:levels"] == 2
    assert objects["way/100"]["attributes"]["roof:height"] == 3.0
    # every volume a closed solid (a roof's posts: closed solids too); the tower part
    # starts on the podium's eaves
    scale = document["transform"]["scale"][2]
    for key, item in objects.items():
        for geometry in item.get("geometry", []):
            posts = item["type"] == "BuildingInstallation"
            assert geometry["type"] == ("MultiSolid" if posts else "Solid"), key
    (tower,) = objects["way/503"]["geometry"]
    used = {i for surface in tower["boundaries"][0] for ring in surface for i in ring}
    assert min(document["vertices"][i][2] for i in used) * scale == pytest.approx(8.0)


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
    # gabled_height_moved: a gable (12 x 8 m) whose ridge runs along it a third of the
    # depth in, not over the middle; both eaves at one height
    roof = _mesh(folder, 700 + ROOF_SHAPES.index("gabled_height_moved"), "roof")
    flat, up = roof.vertices[:, [0, 2]], roof.vertices[:, 1]
    across = np.array([0.0, 1.0])  # glTF z: north-south, across the ridge (the grid turns)
    depth = flat @ across
    ridge = flat[up > up.max() - 0.01] @ across
    assert np.ptp(ridge) < 0.5  # one ridge along the house
    share = (ridge.mean() - depth.min()) / np.ptp(depth)
    assert min(share, 1 - share) == pytest.approx(1 / 3, abs=0.03)
    eaves = up[np.isclose(depth, depth.min(), atol=0.3) | np.isclose(depth, depth.max(), atol=0.3)]
    assert np.ptp(eaves) < 0.3  # both long sides' eaves at one height (the ends: gables)


def test_a_butterfly_roof_is_a_valley_between_two_high_walls(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, _ = district
    oid = 700 + ROOF_SHAPES.index("butterfly")
    roof = _mesh(folder, oid, "roof")
    up, flat = roof.vertices[:, 1], roof.vertices[:, [0, 2]]
    assert up.max() - up.min() == pytest.approx(3.0, abs=1e-3)  # roof:height
    # 12 x 8 m: the valley at the eaves, along the middle; high along the two long
    # walls, 4 m either side of it
    valley = flat[up < up.min() + 1e-3]
    (a, b) = valley[np.argsort(valley[:, 0])[[0, -1]]]
    assert np.linalg.norm(b - a) == pytest.approx(12.0, abs=0.05)
    along = (b - a) / np.linalg.norm(b - a)
    off = (flat[up > up.max() - 1e-3] - a) @ np.array([-along[1], along[0]])
    assert np.abs(off) == pytest.approx(4.0, abs=0.01) and off.min() < 0 < off.max()
    ends = _above(_mesh(folder, oid, "render"), up.min())  # the walls over the eaves
    assert np.abs(ends.face_normals[ends.area_faces > 1e-9, 1]).max() < 1e-4


def test_a_zakomar_roof_is_arches_along_the_walls(
    district: tuple[Path, dict[str, Any]],
) -> None:
    folder, _ = district
    oid = 700 + ROOF_SHAPES.index("zakomar")
    roof = _mesh(folder, oid, "roof")
    up = roof.vertices[:, 1]
    # 12 x 8 m: two arches on each long wall, one on each short one; their crests and
    # the point the roof runs in to are the top, 3 m (roof:height) above the eaves
    crests = np.unique(np.round(roof.vertices[up > up.max() - 1e-3], 4), axis=0)
    assert len(crests) == 6 + 1
    assert up.max() - up.min() == pytest.approx(3.0, abs=1e-3)
    # under each arch a vertical gable, a half circle of ARCH_SEGMENTS pieces
    gables = _above(_mesh(folder, oid, "render"), up.min())  # the façades' wall material
    assert np.abs(gables.face_normals[gables.area_faces > 1e-9, 1]).max() < 1e-4  # float32
    pieces = _pieces(gables)
    assert len(pieces) == 6
    widths = sorted(float(np.ptp(p.vertices[:, [0, 2]], axis=0).max()) for p in pieces)
    assert widths == pytest.approx([6, 6, 6, 6, 8, 8], abs=0.05)  # 12 m walls: 2 arches each
    for piece in pieces:  # half circles 6 m wide, 3 m high; over 8 m, half ellipses
        width = float(np.ptp(piece.vertices[:, [0, 2]], axis=0).max())
        assert piece.area == pytest.approx(math.pi * width / 2 * 3.0 / 2, rel=0.03)


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
    counts = report["summary"]["warnings_by_tag"]
    assert counts == {"building:colour": 1, "roof:shape": 1}
    assert report["summary"]["warnings"] == len(report["warnings"]) == sum(counts.values())
    # every shape S3DB lists is understood: no warning
    for shape in ROOF_SHAPES:
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

    def steady(out: Path) -> str:  # the report on disk, but its times
        found = json.loads((out / "d.report.json").read_text())
        found["summary"].pop("seconds")
        for entry in found["buildings"]:
            entry.pop("time_ms")
        return json.dumps(found, sort_keys=True)

    assert steady(tmp_path / "out") == steady(folder / "out")
    assert again["summary"]["ok"] == report["summary"]["ok"]


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
