"""A city's merged model as an engine loads it: one material of each kind, each picture
once, vertices stored once, and no building a ray can pass through. One generated city
of 50 buildings (the demo district's first 50), built once for the module."""

from __future__ import annotations

import json
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import trimesh
from shapely.geometry import Polygon

from facadecli.city.building import FLAT_ROOFS, MAP_TO_WORLD, flat_roof
from facadecli.city.default import default_city, tones
from facadecli.city.demo import write_demo
from facadecli.city.manifest import Roof, load_city
from facadecli.city.roofs import roof_meshes
from facadecli.city.run import _pick, run_city
from facadecli.export.glb_merge import merge_glb, read_glb
from facadecli.export.texture_store import PICTURE, image_uris, picture_name, pictures_missing
from facadecli.geometry.facade import plane_uv, weld
from tests.khronos import VALIDATOR, validates
from tests.rays import city_leaks

ROOT = Path(__file__).resolve().parent.parent
BUILDINGS = 50


@pytest.fixture(scope="module")
def city(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of a 50-building city (the merged glb and ``buildings/``)."""
    folder = tmp_path_factory.mktemp("city")
    manifest = write_demo(folder / "demo", ROOT / "specs", 4)
    report = run_city(load_city(manifest), folder / "out", jobs=1, limit=BUILDINGS)
    assert report["summary"]["ok"] == BUILDINGS
    return folder / "out"


def test_buildings_share_one_material_of_each_kind_and_each_picture(city: Path) -> None:
    document, _ = read_glb((city / "demo-district.glb").read_bytes())
    materials = document["materials"]
    names = [m["name"] for m in materials]
    # one material of each kind for the whole city, but the walls' four tones (the demo's
    # three palettes: the houses' brick, the shop fronts' render in the houses' tones, the
    # flats' render) and a name two specs give different looks (stone: the church's, the
    # shop's; render: the shop front's, the flats') and the flat roofs' coverings (four at
    # most: FLAT_ROOFS)
    assert max(Counter(names).values()) <= 2 * 4, Counter(names)
    assert len(names) <= len(set(names)) + 3 * 3 + 2 + len(FLAT_ROOFS) - 1
    canonical = [json.dumps(m, sort_keys=True) for m in materials]
    assert len(set(canonical)) == len(canonical)
    assert len({json.dumps(t, sort_keys=True) for t in document["textures"]}) == len(
        document["textures"]
    )
    # each picture named once, a file of the run's textures/ (stored once for the run)
    uris = [image["uri"] for image in document["images"]]
    assert len(set(uris)) == len(uris) and all(uri.startswith("textures/") for uri in uris)
    pictures = [(city / uri).read_bytes() for uri in uris]
    assert len(set(pictures)) == len(pictures)
    assert not any("bufferView" in image for image in document["images"])
    # every building still has its own node, whose meshes name the shared materials
    assert len(document["scenes"][0]["nodes"]) == BUILDINGS
    used = {p["material"] for m in document["meshes"] for p in m["primitives"]}
    assert used == set(range(len(materials)))


def test_each_picture_is_stored_once_for_the_run_and_named_by_every_building(
    city: Path,
) -> None:
    """No building's glb embeds a picture: each names the run's ``textures/``, where
    every picture is one file (named by its bytes) and every file is named by some
    building; the pictures are a small part of the run."""
    named: set[Path] = set()
    glbs = sorted((city / "buildings").glob("*/*.glb"))
    for glb in glbs:
        document, _ = read_glb(glb.read_bytes())
        assert all("bufferView" not in image for image in document.get("images", []))
        uris = image_uris(glb)
        assert uris and all(uri.startswith("../../textures/") for uri in uris)
        assert not pictures_missing(glb)
        named |= {(glb.parent / uri).resolve() for uri in uris}
    stored = sorted((city / "textures").iterdir())
    assert set(stored) == named and all(PICTURE.fullmatch(p.name) for p in stored)
    assert all(picture_name(p.read_bytes()) == p.name for p in stored)
    pictures = sum(p.stat().st_size for p in stored)
    models = sum(glb.stat().st_size for glb in glbs)
    assert pictures < models / 2  # stored once, not once a building


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_a_building_naming_the_runs_pictures_passes_the_khronos_validator(city: Path) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    glb = sorted((city / "buildings").glob("*/*.glb"))[0]
    validates(glb)


def test_merging_the_same_buildings_twice_gives_the_same_bytes(city: Path, tmp_path: Path) -> None:
    parts = sorted((city / "buildings").glob("*/*.glb"))
    merge_glb(((p.stem, p) for p in parts), tmp_path / "a.glb")
    merge_glb(((p.stem, p) for p in parts), tmp_path / "b.glb")
    assert (tmp_path / "a.glb").read_bytes() == (tmp_path / "b.glb").read_bytes()
    document, _ = read_glb((tmp_path / "a.glb").read_bytes())
    alone, _ = read_glb(parts[0].read_bytes())  # a building alone has its own materials
    assert len(document["materials"]) < len(alone["materials"]) * len(parts)


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_the_merged_city_passes_the_khronos_validator(city: Path) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    glb = city / "demo-district.glb"
    validates(glb)


def test_a_welded_mesh_keeps_its_triangles_and_stores_each_vertex_once() -> None:
    box = trimesh.creation.box(extents=(2.0, 3.0, 0.5))
    box.unmerge_vertices()  # every face its own corners, as metric_uv leaves them
    uv = box.vertices[:, :2] / 2.0
    box.visual = trimesh.visual.TextureVisuals(uv=uv)
    box.vertex_attributes["NORMAL"] = np.repeat(box.face_normals, 3, axis=0)[
        np.argsort(box.faces.reshape(-1))
    ]
    welded = weld(box)
    assert len(welded.vertices) == 24  # four corners a side: each side has its own normal
    assert np.allclose(welded.triangles, box.triangles)
    assert np.allclose(np.asarray(welded.visual.uv)[welded.faces], uv[box.faces])
    normals = np.asarray(welded.vertex_attributes["NORMAL"])[welded.faces]
    assert np.allclose(normals, np.asarray(box.vertex_attributes["NORMAL"])[box.faces])


def test_rays_at_35_degrees_from_eight_directions_meet_every_building(city: Path) -> None:
    """No building of the city lets a view through (a missing wall, a window with
    nothing behind it): :func:`tests.rays.city_leaks`."""
    count, leaks = city_leaks(city / "demo-district.glb")
    assert count == BUILDINGS
    assert not leaks, leaks[:5]


@pytest.mark.parametrize("kind", ["gable", "hip", "shed", "dome"])
def test_roof_textures_lie_in_their_slopes_in_metres(kind: str) -> None:
    """Each roof face's texture coordinates are its own plane's, in metres: an edge is as
    long in the texture as on the roof (no stretch on a steep slope or a dome's facets),
    and u runs level, along the eaves (tile courses stay horizontal)."""
    part = Polygon([(0, 0), (12, 0), (12, 8), (7, 8), (7, 5), (0, 5)])  # an L: hips, valleys
    cover, _ = roof_meshes(part, 6.0, Roof(type=kind, pitch=40))  # type: ignore[arg-type]
    cover.apply_transform(MAP_TO_WORLD)
    mapped = plane_uv(cover, 1.0)
    corners = mapped.vertices[mapped.faces]
    uv = np.asarray(mapped.visual.uv)[mapped.faces]
    for a, b in ((0, 1), (1, 2), (2, 0)):
        assert np.allclose(
            np.linalg.norm(corners[:, b] - corners[:, a], axis=1),
            np.linalg.norm(uv[:, b] - uv[:, a], axis=1),
            atol=1e-6,
        )
    # the 3D direction of increasing u in each face: level
    edge1, edge2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    du1, dv1 = uv[:, 1, 0] - uv[:, 0, 0], uv[:, 1, 1] - uv[:, 0, 1]
    du2, dv2 = uv[:, 2, 0] - uv[:, 0, 0], uv[:, 2, 1] - uv[:, 0, 1]
    det = du1 * dv2 - du2 * dv1
    usable = np.abs(det) > 1e-9
    along = (edge1 * dv2[:, None] - edge2 * dv1[:, None])[usable] / det[usable, None]
    assert np.abs(along[:, 1]).max() < 1e-6
    assert (det[usable] > 0).all()  # seen from outside the texture is not mirrored


def test_roofs_wear_a_library_material(city: Path) -> None:
    document, _ = read_glb((city / "demo-district.glb").read_bytes())
    roofs = [m for m in document["materials"] if m["name"] in ("roof", "flat_roof")]
    assert {m["name"] for m in roofs} == {"roof", "flat_roof"}  # pitched and flat, in the demo
    for material in roofs:
        assert "baseColorTexture" in material["pbrMetallicRoughness"]
        assert "normalTexture" in material


def _base_colours(glb: Path, names: tuple[str, ...]) -> dict[str, str]:
    """Each building's base colour picture (a file of the run's textures/) of its
    material named one of ``names``, by the building's name."""
    document, _ = read_glb(glb.read_bytes())
    found = {}
    for node in document["nodes"]:
        for child in node.get("children", []):
            mesh = document["nodes"][child].get("mesh")
            for primitive in [] if mesh is None else document["meshes"][mesh]["primitives"]:
                material = document["materials"][primitive["material"]]
                if material["name"] in names:
                    texture = material["pbrMetallicRoughness"]["baseColorTexture"]
                    source = document["textures"][texture["index"]]["source"]
                    found[node["name"]] = document["images"][source]["uri"]
    return found


def _flat_roofs(glb: Path) -> dict[str, str]:
    """Each building's flat roof material (its base colour picture's file), by its name."""
    return _base_colours(glb, ("flat_roof",))


def test_flat_roofs_vary_from_building_to_building_in_a_few_shared_materials(
    city: Path,
) -> None:
    """The demo's flats with flat roofs (seed 0) wear more than one covering, each the one
    the seed and the building's id pick, and the city stores each covering once."""
    document, _ = read_glb((city / "demo-district.glb").read_bytes())
    roofs = _flat_roofs(city / "demo-district.glb")
    assert len(roofs) >= 4, roofs  # the block's flats with flat roofs
    assert len(set(roofs.values())) >= 2  # more than one covering (it was one grey deck)
    flat = [m for m in document["materials"] if m["name"] == "flat_roof"]
    assert len(flat) == len(set(roofs.values())) <= len(FLAT_ROOFS)  # shared, not per building
    # buildings given the same covering by their pick share one material, and buildings
    # given different ones do not
    by_covering: dict[str, set[str]] = {}
    for building, picture in roofs.items():
        by_covering.setdefault(flat_roof(_pick(0, building)).model_dump_json(), set()).add(picture)
    assert all(len(pictures) == 1 for pictures in by_covering.values())
    assert len(by_covering) == len(set(roofs.values()))


def test_a_flat_roofs_covering_is_independent_of_its_walls_tone() -> None:
    """The covering comes from other bits of a building's number than the palette's tone
    (``pick % 4``): each tone goes with every covering across a city's buildings."""
    picks = [_pick(0, f"way/{k}") for k in range(400)]
    for tone in range(4):
        coverings = {flat_roof(p).model_dump_json() for p in picks if p % 4 == tone}
        assert len(coverings) == len(FLAT_ROOFS)


def test_the_default_city_dresses_buildings_by_their_tags() -> None:
    city = default_city(ROOT / "samples" / "town.osm")
    name = lambda path: Path(path).stem  # noqa: E731
    for kind in ("church", "cathedral", "chapel", "tower"):
        assert name(city.choose({"building": kind}).facade) == "church"
    assert name(city.choose({"building": "yes", "man_made": "tower"}).facade) == "church"
    shop = city.choose({"building": "yes", "shop": "bakery"})  # a house with a shop
    assert name(shop.facade) == "townhouse"
    assert [(w.side, name(w.facade)) for w in shop.walls] == [("front", "shop-front")]
    flats = city.choose({"building": "apartments", "shop": "books"})
    assert name(flats.facade) == "terraced-house" and name(flats.walls[0].facade) == "shop-front"
    assert city.choose({"building": "yes", "shop": "no"}).walls == ()
    assert city.choose({"building": "yes"}).walls == ()
    # every style varies its own wall colour: four tones, the spec's own first
    brick = city.choose({"building": "yes"}).palette
    assert len(set(brick)) == 4 and brick[0] == "#9c4a32"  # the townhouse's brick
    assert city.choose({"building": "church"}).palette != brick


def test_tones_keep_the_hue_and_stay_within_white() -> None:
    for colour in ("#9c4a32", "#e8e4dc", "#ffffff", "#000000", "#abc"):
        found = tones(colour)
        assert len(found) == 4
        for tone in found:
            rgb = np.array([int(tone[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
            first = np.array([int(found[0][i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
            if first.max() > 0:  # the same proportions: the hue kept
                assert rgb / max(rgb.max(), 1) == pytest.approx(first / first.max(), abs=0.02)


def _wall_pictures(glb: Path) -> dict[str, bytes]:
    """Each building's wall picture (its brick's or render's base colour: a file of the
    run's textures/), by its name."""
    pictures = _base_colours(glb, ("brick", "render"))
    return {name: (glb.parent / uri).read_bytes() for name, uri in pictures.items()}


def test_the_seed_varies_the_walls_and_the_same_seed_gives_the_same_bytes(
    tmp_path: Path,
) -> None:
    manifest = write_demo(tmp_path / "demo", ROOT / "specs", 2)
    text = manifest.read_text()
    merged, walls = [], []
    for run, seed in enumerate((0, 0, 1, 2)):
        manifest.write_text(f"{text}seed: {seed}\n")
        out = tmp_path / f"out{run}"
        run_city(load_city(manifest), out, jobs=1, limit=6)
        merged.append((out / "demo-district.glb").read_bytes())
        walls.append(_wall_pictures(out / "demo-district.glb"))
    assert merged[0] == merged[1]  # the same city and seed: the same bytes
    assert len(walls[0]) >= 4  # the houses and flats with brick or render walls
    assert walls[2] != walls[0] or walls[3] != walls[0]  # another seed: other tones somewhere


def _rooms_shown(glb: Path) -> tuple[int, set[tuple[int, int]]]:
    """The merged city's materials named ``interior`` (how many) and the rooms of the
    atlas their back plates show (each triangle's texture coordinates' centre, as a room
    of the 4 x 4 atlas)."""
    document, binary = read_glb(glb.read_bytes())
    interiors = {k for k, m in enumerate(document["materials"]) if m["name"] == "interior"}
    rooms: set[tuple[int, int]] = set()
    for mesh in document["meshes"]:
        for primitive in mesh["primitives"]:
            if primitive["material"] not in interiors:
                continue
            material = document["materials"][primitive["material"]]
            assert "baseColorTexture" in material["pbrMetallicRoughness"]
            accessor = document["accessors"][primitive["attributes"]["TEXCOORD_0"]]
            view = document["bufferViews"][accessor["bufferView"]]
            start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
            uv = np.frombuffer(binary, np.float32, 2 * accessor["count"], start).reshape(-1, 2)
            rooms |= {(int(u * 4), int(v * 4)) for u, v in uv}
    return len(interiors), rooms


def test_the_windows_of_a_city_show_many_rooms_from_one_material(city: Path) -> None:
    """Behind the windows of the 50 buildings: one ``interior`` material for the city
    (one picture, the atlas of rooms), and its back plates show every room of it."""
    materials, rooms = _rooms_shown(city / "demo-district.glb")
    assert materials == 1
    assert len(rooms) == 16, rooms
