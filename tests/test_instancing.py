"""Repeated parts as GPU instances (``facade city --instance``, issue 35 item 5): the
same triangles where they were, each repeated mesh stored once and drawn by one node
for the whole city, a valid glb, the same bytes for the same buildings."""

from __future__ import annotations

import json
import math
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from facadecli.city.demo import write_demo
from facadecli.city.manifest import load_city
from facadecli.city.run import run_city
from facadecli.export.glb_merge import instance_nodes, merge_glb, read_glb
from facadecli.export.gltf import glb_bytes
from facadecli.export.instancing import (
    EXTENSION,
    MIN_TRIANGLES,
    mesh_digest,
    node_matrix,
    trs,
)
from tests.instances import placed_triangles
from tests.khronos import VALIDATOR, validates
from tests.test_city_assets import ROOT

BUILDINGS = 8


@pytest.fixture(scope="module")
def towns(tmp_path_factory: pytest.TempPathFactory) -> dict[bool, Path]:
    """The same 8 buildings of the demo district built plainly and with instances."""
    folder = tmp_path_factory.mktemp("instanced")
    manifest = write_demo(folder / "demo", ROOT / "specs", 2)
    found = {}
    for instanced in (False, True):
        out = folder / f"out-{instanced}"
        report = run_city(load_city(manifest), out, jobs=1, limit=BUILDINGS, instanced=instanced)
        assert report["summary"]["ok"] == BUILDINGS
        found[instanced] = out
    return found


def _same_triangles(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two sets of triangles are the same (corners within 1 mm: float32 places)."""
    if a.shape != b.shape:
        return False
    keys = lambda t: np.hstack([t.mean(axis=1), np.sort(t.reshape(len(t), -1), axis=1)])  # noqa: E731
    distance, _ = cKDTree(keys(b)).query(keys(a))
    return bool(distance.max() < 1e-3)


def test_an_instanced_city_draws_the_same_triangles_where_they_were(
    towns: dict[bool, Path],
) -> None:
    plain = placed_triangles((towns[False] / "demo-district.glb").read_bytes())
    instanced = placed_triangles((towns[True] / "demo-district.glb").read_bytes())
    assert sorted(plain) == sorted(instanced)
    for name in plain:
        assert _same_triangles(plain[name], instanced[name]), name


def test_each_repeated_part_is_stored_once_and_drawn_by_one_node(towns: dict[bool, Path]) -> None:
    document, chunk = read_glb((towns[True] / "demo-district.glb").read_bytes())
    plain, _ = read_glb((towns[False] / "demo-district.glb").read_bytes())
    roots = [document["nodes"][n] for n in document["scenes"][0]["nodes"]]
    assert [r["name"] for r in roots][-1] == "instanced"
    assert len(roots) == BUILDINGS + 1  # every building keeps its node
    instanced = [document["nodes"][n] for n in roots[-1]["children"]]
    assert instanced and all(EXTENSION in n["extensions"] for n in instanced)
    meshes = [n["mesh"] for n in instanced]
    assert len(set(meshes)) == len(meshes)  # one node a mesh
    identities = [json.dumps(m, sort_keys=True) for m in document["materials"]]
    digests = {mesh_digest(document, chunk, mesh, identities) for mesh in meshes}
    assert len(digests) == len(meshes)  # no mesh stored twice
    counts = [
        document["accessors"][n["extensions"][EXTENSION]["attributes"]["TRANSLATION"]]["count"]
        for n in instanced
    ]
    assert min(counts) >= 2 and sum(counts) > 4 * len(counts)  # windows repeat
    stored = sum(document["accessors"][a]["count"] for a in _positions(document))
    assert stored < 0.8 * sum(plain["accessors"][a]["count"] for a in _positions(plain))
    units = 0
    for mesh in meshes:  # a small part is a pane or a recess: a unit mesh for every size
        primitives = document["meshes"][mesh]["primitives"]
        found = sum(document["accessors"][p["indices"]]["count"] // 3 for p in primitives)
        if found >= MIN_TRIANGLES:
            continue
        units += 1
        for primitive in primitives:
            material = document["materials"][primitive["material"]]
            glass = "KHR_materials_transmission" in material.get("extensions", {})
            assert glass or material.get("alphaMode") == "BLEND" or material["name"] == "interior"
            position = document["accessors"][primitive["attributes"]["POSITION"]]
            assert min(position["min"]) >= 0 and max(position["max"]) <= 1
    assert units  # the panes and recesses of every size, each kind one mesh


def test_a_part_built_on_walls_of_other_lengths_is_one_mesh(towns: dict[bool, Path]) -> None:
    """The same frame or door on two walls is one instanced mesh: no two instanced meshes
    hold the same triangles and texture coordinates to within 0.1 mm (built at other
    wall lengths, they came out a float32 step apart and were stored and drawn twice)."""
    document, chunk = read_glb((towns[True] / "demo-district.glb").read_bytes())
    roots = [document["nodes"][n] for n in document["scenes"][0]["nodes"]]
    meshes = [document["nodes"][n]["mesh"] for n in roots[-1]["children"]]

    def values(index: int) -> np.ndarray:
        accessor = document["accessors"][index]
        view = document["bufferViews"][accessor["bufferView"]]
        width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[accessor["type"]]
        kind = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "u1"}[accessor["componentType"]]
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        found = np.frombuffer(chunk, kind, accessor["count"] * width, start)
        return found.astype(float)

    shapes = Counter()
    for mesh in meshes:
        key = []
        for primitive in document["meshes"][mesh]["primitives"]:
            key.append(primitive["material"])
            key.append(values(primitive["indices"]).tobytes())
            for name in ("POSITION", "TEXCOORD_0"):
                key.append(np.round(values(primitive["attributes"][name]), 4).tobytes())
        shapes[tuple(key)] += 1
    assert len(meshes) > 10
    twins = sum(count - 1 for count in shapes.values())
    assert twins == 0, f"{twins} of {len(meshes)} instanced meshes are another's twin"


def _positions(document: dict[str, object]) -> list[int]:
    return [p["attributes"]["POSITION"] for m in document["meshes"] for p in m["primitives"]]  # type: ignore[attr-defined, index]


def test_merging_instanced_buildings_twice_gives_the_same_bytes(
    towns: dict[bool, Path], tmp_path: Path
) -> None:
    parts = sorted((towns[True] / "buildings").glob("*.glb"))
    merge_glb(((p.stem, p) for p in parts), tmp_path / "a.glb", instanced=True)
    merge_glb(((p.stem, p) for p in parts), tmp_path / "b.glb", instanced=True)
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_instanced_glb_files_pass_the_khronos_validator(towns: dict[bool, Path]) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    files = [towns[True] / "demo-district.glb", *sorted((towns[True] / "buildings").glob("*.glb"))]
    validates(*files)


@pytest.mark.parametrize("seed", range(5))
def test_a_placement_is_a_translation_rotation_and_scale(seed: int) -> None:
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0, 2 * math.pi)
    matrix = trimesh.transformations.rotation_matrix(angle, (0, 1, 0))
    matrix = matrix @ np.diag([*rng.uniform(0.5, 2.0, 3), 1.0])
    matrix[:3, 3] = rng.uniform(-100, 100, 3)
    found = trs(matrix)
    assert found is not None
    node = {"translation": found[:3], "rotation": found[3:7], "scale": found[7:]}
    assert np.allclose(node_matrix(node), matrix)
    assert trs(matrix @ np.diag([-1.0, 1.0, 1.0, 1.0])) is None  # a mirror is no instance


def test_a_mesh_placed_again_and_again_becomes_one_instanced_node() -> None:
    scene = trimesh.Scene()
    box = trimesh.creation.box(extents=(1.0, 2.0, 0.1))
    scene.add_geometry(box, geom_name="pane", node_name="pane/0")
    for k in range(1, 4):
        move = trimesh.transformations.translation_matrix((2.0 * k, 0.0, 0.0))
        scene.graph.update(frame_to=f"pane/{k}", matrix=move, geometry="pane")
    scene.add_geometry(trimesh.creation.box(), geom_name="door", node_name="door")
    data = glb_bytes(scene)
    instanced = instance_nodes(data)
    document, _ = read_glb(instanced)
    nodes = [n for n in document["nodes"] if "mesh" in n]
    assert len(nodes) == 2 and len(document["meshes"]) == 2
    (one,) = [n for n in nodes if "extensions" in n]
    assert document["accessors"][one["extensions"][EXTENSION]["attributes"]["SCALE"]]["count"] == 4
    before, after = placed_triangles(data), placed_triangles(instanced)
    for name in before:
        assert _same_triangles(before[name], after[name])
    assert instance_nodes(instanced) == instanced  # nothing left to instance


def test_3d_tiles_see_instanced_buildings_where_they_are(towns: dict[bool, Path]) -> None:
    """The tiles' boxes and triangle counts of a building are the same with instances:
    its parts' boxes placed at each instance, their triangles counted at each."""
    from facadecli.city.tileset import _glb_boxes, _glb_triangles

    plain = sorted((towns[False] / "buildings").glob("*.glb"))
    instanced = sorted((towns[True] / "buildings").glob("*.glb"))
    assert [p.name for p in plain] == [p.name for p in instanced]
    assert np.allclose(_glb_boxes(plain), _glb_boxes(instanced), atol=1e-3)
    assert [_glb_triangles(p) for p in plain] == [_glb_triangles(p) for p in instanced]


def test_a_part_a_building_places_once_is_merged_with_its_material(
    towns: dict[bool, Path],
) -> None:
    """The rule the rooftop units follow holds for a façade's parts too: a part placed
    once on a building (a room shown in a single window) is merged with the building's
    mesh of its material, not a node and a draw call of its own; so each material of a
    building is drawn by one plain node at most, and each instanced node places its
    mesh twice or more (32 buildings of the 50-building block drew a lone room apart)."""
    for glb in sorted((towns[True] / "buildings").rglob("*.glb")):
        document, _ = read_glb(glb.read_bytes())
        plain: Counter[int] = Counter()
        for node in document["nodes"]:
            if "mesh" not in node:
                continue
            if EXTENSION in node.get("extensions", {}):
                accessor = next(iter(node["extensions"][EXTENSION]["attributes"].values()))
                assert document["accessors"][accessor]["count"] >= 2, glb.name
                continue
            for primitive in document["meshes"][node["mesh"]]["primitives"]:
                plain[primitive["material"]] += 1
        twice = {document["materials"][k]["name"]: n for k, n in plain.items() if n > 1}
        assert not twice, (glb.name, twice)
