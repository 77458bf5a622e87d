"""The ground in a city's exported models (facadecli.city.ground, ``facade city --ground``,
issue 35): a base plane and the land cover, in one plane with no piece over another, in
the merged glb (a root node ``ground``) and as a tile of the 3D Tiles, each material with
its pictures, validator-clean, the same bytes for the same input; none without the flag.
The district is tests/landcover_town.py's (nine houses, a park with a pond, a wood, a car
park, a river), seeds 1-3 for the pieces, seed 1 built once for the module."""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
import trimesh
from shapely.geometry import box

from facadecli.city.footprints import read_footprints
from facadecli.city.ground import GROUND_LEVEL, PAVING, ground_box, ground_pieces
from facadecli.city.landcover import KINDS
from facadecli.export.glb_merge import read_glb
from facadecli.viewer.gallery import find_models
from tests.khronos import VALIDATOR, validates
from tests.landcover_town import town, write_osm
from tests.rays import directions, missing
from tests.running import facade

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_pieces_tile_the_district_once_with_later_kinds_over_earlier(
    tmp_path: Path, seed: int
) -> None:
    """Every point of the district's box is in exactly one piece (their areas add up to
    the box's, and their union is the box), and each kind holds what the input maps of it
    in the box, less what later kinds cover (a pond in a park is water)."""
    found = read_footprints(write_osm(tmp_path / "t.osm", town(seed)))
    extent = ground_box(part for footprint in found.footprints for part in footprint.parts)
    pieces = ground_pieces(extent, found.ground)
    plane = box(*extent)
    assert next(iter(pieces)) == PAVING and set(pieces) <= {PAVING, *KINDS}
    shapes = {kind: shapely.union_all(parts) for kind, parts in pieces.items()}
    assert sum(shape.area for shape in shapes.values()) == pytest.approx(plane.area, rel=1e-9)
    assert shapely.union_all(list(shapes.values())).symmetric_difference(plane).area < 1e-6
    for one, other in itertools.combinations(shapes.values(), 2):
        assert one.intersection(other).area < 1e-6
    order = list(KINDS)
    for kind in (kind for kind in pieces if kind != PAVING):
        mapped = shapely.union_all([p for a in found.ground if a.kind == kind for p in a.parts])
        later = [
            p for a in found.ground if order.index(a.kind) > order.index(kind) for p in a.parts
        ]
        expected = mapped.intersection(plane).difference(shapely.union_all(later))
        assert shapes[kind].symmetric_difference(expected).area < 1e-3, kind


def _city(capsys: pytest.CaptureFixture[str], source: Path, out: Path, *more: str) -> Any:
    code, said, err = facade(capsys, "city", source, "-o", out, "-j", "1", "--3dtiles", *more)
    assert code == 0, err
    report = json.loads((out / "t.report.json").read_text())
    return report, said


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Seed 1's district built with ``--ground --3dtiles``: its output folder."""
    folder = tmp_path_factory.mktemp("ground")
    source = write_osm(folder / "t.osm", town(1))
    command = [sys.executable, "-m", "facadecli", "city", str(source), "-o", str(folder / "a")]
    run = subprocess.run(
        [*command, "-j", "1", "--3dtiles", "--ground"], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.rstrip().endswith("t.ground.glb"), run.stdout  # named in the last line
    return folder / "a"


def test_the_merged_model_stands_the_buildings_on_the_ground(built: Path) -> None:
    """The merged glb holds the ground after the buildings, under a root node ``ground``:
    a mesh a kind, each in its ``ground-<kind>`` material with a base colour and a normal
    picture (the run's textures/), flat at GROUND_LEVEL, facing up; rays at 35° from eight
    directions over the whole district all meet something (no building floats over
    nothing), the ground's own front faces where no building stands."""
    report = json.loads((built / "t.report.json").read_text())
    triangles = report["models"]["ground_model"]["triangles"]
    assert report["models"]["ground_model"]["file"] == "t.ground.glb"
    assert set(triangles) == {PAVING, "wood", "park", "parking", "water"}
    document, _ = read_glb((built / "t.glb").read_bytes())
    roots = [document["nodes"][index]["name"] for index in document["scenes"][0]["nodes"]]
    assert roots[-1] == "ground" and roots.count("ground") == 1
    names = {f"ground-{kind}" for kind in triangles}
    materials = [m for m in document["materials"] if m["name"] in names]
    assert {m["name"] for m in materials} == names
    for material in materials:
        assert "baseColorTexture" in material["pbrMetallicRoughness"], material["name"]
        assert "normalTexture" in material, material["name"]
    uris = [image["uri"] for image in document["images"]]
    assert all(uri.startswith("textures/") for uri in uris)
    scene = trimesh.load(built / "t.ground.glb", force="scene")
    laid = scene.to_geometry()
    assert np.allclose(laid.vertices[:, 1], GROUND_LEVEL)
    assert (laid.face_normals[:, 1] > 0.999).all()  # up: glTF's y
    city = trimesh.load(built / "t.glb", force="scene").to_geometry()
    upright = city.triangles[:, :, [0, 2, 1]] * np.array([1.0, -1.0, 1.0])  # z up
    (x0, _, z0), (x1, _, z1) = laid.bounds
    xs, ys = np.meshgrid(np.linspace(x0 + 0.5, x1 - 0.5, 40), np.linspace(-z1 + 0.5, -z0 - 0.5, 40))
    targets = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, GROUND_LEVEL)])
    for direction in directions(8, math.radians(55)):  # 35° above the horizon
        through = targets[missing(upright, targets, direction, tile=10.0, culled=True)]
        assert len(through) == 0, f"{len(through)} rays along {direction}: {through[:3]}"


def test_the_ground_is_a_tile_of_its_own_beside_the_buildings(built: Path) -> None:
    """The tileset's root draws both (``refine: ADD``): the ground's tile, its content
    ``ground.glb`` (error 0: nothing replaces it), its box holding its content, and the
    buildings' root as it was, the globe's transform on the new root alone."""
    tileset = json.loads((built / "3dtiles" / "tileset.json").read_text())
    root = tileset["root"]
    assert root["refine"] == "ADD" and "transform" in root and "content" not in root
    laid, buildings = root["children"]
    assert laid["content"] == {"uri": "ground.glb"} and laid["geometricError"] == 0.0
    assert "transform" not in buildings and buildings["refine"] == "REPLACE"
    centre, half = np.array(laid["boundingVolume"]["box"][:3]), laid["boundingVolume"]["box"][3:]
    mesh = trimesh.load(built / "3dtiles" / "ground.glb", force="scene").to_geometry()
    low, high = mesh.bounds  # glTF y-up -> the tile's z-up: (x, -z, y)
    corners = np.array([[x, -z, y] for x, y, z in (low, high)])
    extent = np.array([half[0], half[4], half[8]])
    assert (np.abs(corners - centre) <= extent + 1e-3).all()
    assert tileset["geometricError"] == root["geometricError"] >= buildings["geometricError"]


@pytest.mark.skipif(
    not (VALIDATOR / "gltf-validator").exists(), reason="run 'make test' to install the validator"
)
def test_the_ground_passes_the_khronos_validator(built: Path) -> None:
    files = [built / "t.ground.glb", built / "t.glb", built / "3dtiles" / "ground.glb"]
    validates(*files)


def test_the_same_district_lays_the_same_ground_and_none_without_the_flag(
    capsys: pytest.CaptureFixture[str], built: Path, tmp_path: Path
) -> None:
    """Built again, the ground's files are the same bytes; built without ``--ground`` in
    the same folder, the ground files are gone, the report names none and the merged
    model holds no ``ground`` node; the gallery lists the merged model, never the ground
    beside it as a model of its own."""
    assert [model.name for model in find_models(built)] == ["t"]
    source = built.parent / "t.osm"
    again = tmp_path / "b"
    _city(capsys, source, again, "--ground")
    for name in ("t.ground.glb", "t.glb", "3dtiles/ground.glb", "3dtiles/tileset.json"):
        assert (again / name).read_bytes() == (built / name).read_bytes(), name
    report, said = _city(capsys, source, again)
    assert "ground_model" not in report["models"] and "ground.glb" not in said
    assert not (again / "t.ground.glb").exists()
    assert not (again / "3dtiles" / "ground.glb").exists()
    document, _ = read_glb((again / "t.glb").read_bytes())
    assert "ground" not in [node.get("name") for node in document["nodes"]]
    assert "ground.glb" not in (again / "3dtiles/tileset.json").read_text()


def test_a_killed_runs_half_written_ground_is_found_as_leftovers(tmp_path: Path) -> None:
    """The temporary files of the ground's glb (atomic: ``.t.ground.glb.<8>.tmp``) and of
    its tile (merge_glb's spool, ``3dtiles/.ground.glb.<8>.bin``) are the run's
    leftovers, removed by the next; a user's files of other names are not."""
    from facadecli.city.run import leftovers

    (tmp_path / "3dtiles").mkdir()
    ours = [tmp_path / ".t.ground.glb.ab12cd34.tmp", tmp_path / "3dtiles/.ground.glb.x1y2z3w4.bin"]
    theirs = [tmp_path / ".t.ground.glb.old", tmp_path / "3dtiles/.ground.glb.tmp"]
    for path in (*ours, *theirs):
        path.write_bytes(b"")
    assert leftovers(tmp_path, "t") == sorted(ours)
