"""What stands on a flat roof (city/rooftop.py): a coping on its walls, plant inside its
parapet and clear of its party walls, the same for the same seed. Measured over a
generated family of footprints (rectangles and Ls of many sizes, party walls on some
sides), then on a small city built whole."""

from __future__ import annotations

import json
import random
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
from shapely.geometry import LineString, Polygon
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from facadecli.city.building import MAP_TO_WORLD
from facadecli.city.manifest import load_city
from facadecli.city.rooftop import (
    CLEAR,
    COPING_HEIGHT,
    COPING_IN,
    COPING_OVER,
    EDGE_CLEAR,
    GRID,
    HOUSING_AREA,
    KINDS,
    METAL_NAME,
    PARTY_CLEAR,
    UNITS,
    coping,
    plant,
)
from facadecli.city.run import run_city
from facadecli.export.glb_merge import read_glb
from facadecli.export.instancing import EXTENSION

ROOT = Path(__file__).resolve().parent.parent
TOLERANCE = 1e-6


def _family(count: int = 60, seed: int = 7) -> list[tuple[Polygon, list]]:
    """Footprints of flat-roofed buildings: rectangles and Ls, 8 to 40 m a side, turned
    any way, each with none, one or two of its sides a party wall."""
    rng = random.Random(seed)
    found = []
    for _ in range(count):
        width, depth = rng.uniform(8, 40), rng.uniform(8, 30)
        ring = [(0, 0), (width, 0), (width, depth), (0, depth)]
        if rng.random() < 0.4:  # an L
            ring = [(0, 0), (width, 0), (width, depth), (width / 2, depth)]
            ring += [(width / 2, depth / 2), (0, depth / 2)]
        turn = rng.uniform(0, np.pi)
        c, s = np.cos(turn), np.sin(turn)
        x0, y0 = rng.uniform(-500, 500), rng.uniform(-500, 500)
        points = [(x0 + x * c - y * s, y0 + x * s + y * c) for x, y in ring]
        part = orient(Polygon(points), sign=1.0)
        edges = list(zip(points, points[1:] + points[:1], strict=True))
        party = rng.sample(edges, rng.choice((0, 0, 1, 2)))
        found.append((part, party))
    return found


def _map_points(mesh: trimesh.Trimesh, matrix: np.ndarray) -> np.ndarray:
    """A unit's vertices where its placement puts them, in the map frame (x, y, z)."""
    world = trimesh.transform_points(mesh.vertices, matrix)
    return trimesh.transform_points(world, np.linalg.inv(MAP_TO_WORLD))


def test_plant_stays_inside_the_parapet_clear_of_party_walls_and_of_each_other() -> None:
    placed_anything = 0
    for number, (part, party) in enumerate(_family()):
        units = plant(part, 12.0, party, (number, 0, 0))
        placed_anything += bool(units)
        inside = part.buffer(-EDGE_CLEAR + TOLERANCE, join_style="mitre")
        for unit in units:
            # where its meshes are, not only the outline it was placed by
            points = np.vstack([_map_points(m, unit.matrix) for _, m in UNITS[unit.shape].meshes])
            plan = Polygon(points[:, :2]).convex_hull
            assert plan.difference(unit.outline.buffer(TOLERANCE)).area < 1e-9
            assert inside.contains(unit.outline), (number, unit.kind)
            assert points[:, 2].min() == pytest.approx(12.0)  # standing on the roof
            for a, b in party:
                assert LineString([a, b]).distance(unit.outline) >= PARTY_CLEAR - TOLERANCE
        for k, one in enumerate(units):
            for other in units[k + 1 :]:
                assert one.outline.distance(other.outline) >= CLEAR - TOLERANCE
    assert placed_anything >= 50  # nearly every roof of the family has some plant


def test_plant_grows_with_the_roof_and_only_large_roofs_get_a_housing() -> None:
    small = Polygon([(0, 0), (12, 0), (12, 10), (0, 10)])
    large = Polygon([(0, 0), (30, 0), (30, 20), (0, 20)])
    for seed in range(20):
        on_small = [u.kind for u in plant(small, 9.0, [], (seed, 0, 0))]
        on_large = [u.kind for u in plant(large, 9.0, [], (seed, 0, 0))]
        assert "housing" not in on_small and small.area < HOUSING_AREA
        assert on_large.count("housing") == 1
        assert len(on_large) > len(on_small) >= 1
    kinds = {u.kind for seed in range(20) for u in plant(large, 9.0, [], (seed, 0, 0))}
    assert kinds == set(KINDS)  # each kind turns up: rooflights on some roofs


def test_each_kind_comes_in_several_shapes_over_a_family_of_roofs() -> None:
    """Over the generated family, every shape of every kind turns up (so a kind is not one
    shape everywhere), each on a roof it is meant for and where its outline says."""
    seen: dict[str, set[str]] = {kind: set() for kind in KINDS}
    for number, (part, party) in enumerate(_family(count=120, seed=11)):
        for unit in plant(part, 12.0, party, (number, 0, 0)):
            shape = UNITS[unit.shape]
            assert shape.kind == unit.kind
            assert part.area >= shape.from_area  # the largest housings on the largest roofs
            length, width = shape.size
            assert unit.outline.area == pytest.approx(length * width)
            seen[unit.kind].add(unit.shape)
    for kind in KINDS:
        assert seen[kind] == {n for n, u in UNITS.items() if u.kind == kind}, kind
        assert len(seen[kind]) >= 3, kind
    sizes = {u.kind: set() for u in UNITS.values()}
    for unit in UNITS.values():
        sizes[unit.kind].add(tuple(round(v, 3) for v in unit.size))
    assert all(len(found) == 3 for found in sizes.values())  # each shape its own plan


def test_the_same_seed_places_the_same_plant_and_another_seed_other_plant() -> None:
    part = Polygon([(0, 0), (22, 0), (22, 14), (0, 14)])
    first = plant(part, 15.0, [((0, 0), (0, 14))], (5, 0, 0))
    again = plant(part, 15.0, [((0, 0), (0, 14))], (5, 0, 0))
    assert [u.outline.wkb for u in first] == [u.outline.wkb for u in again]
    assert all(np.array_equal(a.matrix, b.matrix) for a, b in zip(first, again, strict=True))
    others = {tuple(u.outline.wkb for u in plant(part, 15.0, [], (s, 0, 0))) for s in range(8)}
    assert len(others) == 8


@pytest.mark.parametrize("number", range(0, 60, 6))
def test_the_coping_caps_every_wall_and_overhangs_only_the_free_ones(number: int) -> None:
    part, party = _family()[number]
    cap = coping(part, 12.6, party)
    assert cap.is_watertight
    assert cap.bounds[0][2] == pytest.approx(12.6)
    assert cap.bounds[1][2] == pytest.approx(12.6 + COPING_HEIGHT)
    plan = unary_union([Polygon(t[:, :2]) for t in cap.triangles if Polygon(t[:, :2]).area > 0])
    walls = part.difference(part.buffer(-(COPING_IN - 0.05), join_style="mitre"))
    snapped = GRID * part.length  # the outline is snapped to GRID
    assert walls.difference(plan).area < snapped  # every wall's top is under it
    outside = plan.difference(part)
    free = part.boundary.length - sum(LineString([a, b]).length for a, b in party)
    assert outside.area == pytest.approx(COPING_OVER * free, rel=0.05)  # a drip all round
    for a, b in party:  # none over a party wall: the neighbour's roof
        assert outside.intersection(LineString([a, b]).buffer(COPING_OVER / 2)).area < snapped


MANIFEST = """\
version: 1
name: roofs
seed: 3
footprints: footprints.geojson
defaults:
  facade: {specs}/terraced-house.yaml
  height: 15.0
  roof: {{type: flat, parapet: 0.6}}
rules:
  - when: {{building: house}}
    facade: {specs}/townhouse.yaml
    roof: {{type: gable, pitch: 35}}
"""


CRS = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::28992"}}  # metres


def _rectangle(fid: str, x: float, y: float, width: float, depth: float, kind: str) -> dict:
    ring = [[x, y], [x + width, y], [x + width, y + depth], [x, y + depth], [x, y]]
    ring = [[155000 + u, 463000 + v] for u, v in ring]  # in the Netherlands
    return {
        "type": "Feature",
        "id": fid,
        "properties": {"building": kind},
        "geometry": {"type": "Polygon", "coordinates": [ring]},
    }


@pytest.fixture(scope="module")
def small_city(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """Two flats in a terrace (a party wall between them) and a gabled house, built; the
    manifest and the output folder."""
    folder = tmp_path_factory.mktemp("roofs")
    features = [
        _rectangle("a", 0, 0, 20, 16, "apartments"),
        _rectangle("b", 20, 0, 18, 16, "apartments"),
        _rectangle("c", 60, 0, 12, 10, "house"),
    ]
    (folder / "footprints.geojson").write_text(
        json.dumps({"type": "FeatureCollection", "crs": CRS, "features": features})
    )
    manifest = folder / "roofs.yaml"
    manifest.write_text(MANIFEST.format(specs=ROOT / "specs"))
    report = run_city(load_city(manifest), folder / "out", jobs=1, usd=True)
    assert report["summary"]["ok"] == 3
    return manifest, folder / "out"


def _usd_triangles(stage: str, material: str) -> int:
    """Triangles of a building's USD mesh of ``material`` (its faceVertexCounts)."""
    found = re.search(
        rf'def Xform "m_[^"]*_{material}"\s*{{\s*def Mesh[^{{]*{{[^}}]*?'
        r"int\[\] faceVertexCounts = \[([^\]]*)\]",
        stage,
    )
    assert found is not None
    return len(found.group(1).split(","))


def _metal(glb: Path) -> trimesh.Trimesh | None:
    scene = trimesh.load(glb, force="scene")
    found = [
        g.copy().apply_transform(scene.graph[node][0])
        for node in scene.graph.nodes_geometry
        for g in [scene.geometry[scene.graph[node][1]]]
        if g.visual.material.name == METAL_NAME
    ]
    return trimesh.util.concatenate(found) if found else None


def test_every_flat_roof_of_a_city_has_a_coping_and_plant_and_a_pitched_one_none(
    small_city: tuple[Path, Path],
) -> None:
    _, out = small_city
    glbs = {p.stem: p for p in (out / "buildings").rglob("*.glb")}
    assert _metal(glbs["c"]) is None  # the gabled house
    for name in ("a", "b"):
        metal = _metal(glbs[name])
        assert metal is not None
        low, high = metal.bounds
        assert high[1] > 15.0 + 0.6 + COPING_HEIGHT + 0.5  # plant stands above the coping
        assert low[1] == pytest.approx(15.0, abs=1e-3)  # on the roof
        assert low[1] < 15.6 + 1e-3  # the coping on the parapet
        stage = glbs[name].with_suffix(".usda").read_text(encoding="utf-8")
        assert _usd_triangles(stage, METAL_NAME) == len(metal.faces)  # the USD has it too


def test_a_city_with_plant_gives_the_same_bytes_with_the_same_seed(
    small_city: tuple[Path, Path], tmp_path: Path
) -> None:
    manifest, out = small_city
    run_city(load_city(manifest), tmp_path / "again", jobs=1)
    for glb in sorted((out / "buildings").rglob("*.glb")):
        twin = tmp_path / "again" / glb.relative_to(out)
        assert glb.read_bytes() == twin.read_bytes(), glb.name


def test_with_instance_plant_placed_twice_or_more_is_instanced_and_the_rest_merged(
    small_city: tuple[Path, Path], tmp_path: Path
) -> None:
    """With ``--instance`` a unit placed twice or more on a building (its vents) is one
    mesh drawn at each place; one placed once (a building's one condenser, its housing) is
    merged with the building's metal, not a draw call of its own."""
    manifest, _ = small_city
    run_city(load_city(manifest), tmp_path / "out", jobs=1, instanced=True)
    for name in ("a", "b"):
        glb = next((tmp_path / "out" / "buildings").rglob(f"{name}.glb"))
        document, _ = read_glb(glb.read_bytes())
        metal = [k for k, m in enumerate(document["materials"]) if m["name"] == METAL_NAME]
        drawn = [
            node
            for node in document["nodes"]
            if "mesh" in node
            and any(
                p.get("material") in metal for p in document["meshes"][node["mesh"]]["primitives"]
            )
        ]
        plain = [node for node in drawn if EXTENSION not in node.get("extensions", {})]
        instanced = [node for node in drawn if EXTENSION in node.get("extensions", {})]
        assert len(plain) == 1  # the coping and every unit placed once, merged
        assert instanced  # the vents
        for node in instanced:
            accessor = next(iter(node["extensions"][EXTENSION]["attributes"].values()))
            assert document["accessors"][accessor]["count"] >= 2
