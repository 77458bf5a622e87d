"""A run's texture pictures stored once (facadecli.export.texture_store): each picture
one file named by its bytes, written once whoever asks for it; a glb that names its
pictures by relative URI, which the merged models rename for where they are, and
``facade view`` inlines again. The city's own checks are in test_city_assets.py,
test_city_resume.py and test_tileset.py."""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
from PIL import Image

from facadecli.city.demo import write_demo
from facadecli.city.manifest import load_city
from facadecli.city.run import run_city
from facadecli.export.glb_merge import merge_glb, read_glb
from facadecli.export.texture_store import (
    PICTURE,
    TextureStore,
    embedded,
    externalised,
    image_uris,
    picture_name,
    pictures_missing,
    prune,
    unpadded,
)
from facadecli.viewer.gallery import read_models, write_gallery
from tests.khronos import VALIDATOR, reports

ROOT = Path(__file__).resolve().parent.parent


def _png(colour: tuple[int, int, int], size: int = 8) -> bytes:
    with io.BytesIO() as buffer:
        Image.new("RGB", (size, size), colour).save(buffer, format="png")
        return buffer.getvalue()


def _textured_glb(colours: list[tuple[int, int, int]]) -> bytes:
    """A glb of one box a colour, each textured with a picture of that colour."""
    scene = trimesh.Scene()
    for index, colour in enumerate(colours):
        box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
        box.apply_translation((2.0 * index, 0.0, 0.0))
        picture = Image.open(io.BytesIO(_png(colour)))
        material = trimesh.visual.material.PBRMaterial(name=f"m{index}", baseColorTexture=picture)
        uv = box.vertices[:, :2] + 0.5
        box.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
        scene.add_geometry(box, geom_name=f"box{index}")
    data: bytes = scene.export(file_type="glb")
    return data


def test_a_picture_is_written_once_and_named_by_its_bytes(tmp_path: Path) -> None:
    store = TextureStore(tmp_path / "textures")
    red, blue = _png((200, 0, 0)), _png((0, 0, 200))
    first = store.put(red)
    stamp = first.stat()
    assert store.put(red) == first and TextureStore(store.folder).put(red) == first
    again = first.stat()
    assert (again.st_ino, again.st_mtime_ns) == (stamp.st_ino, stamp.st_mtime_ns)
    assert store.written == 1
    assert first.name == hashlib.sha256(red).hexdigest()[:32] + ".png"
    assert PICTURE.fullmatch(first.name) and first.read_bytes() == red
    assert store.put(blue) != first and store.written == 2
    assert picture_name(b"\xff\xd8\xff\xe0 a jpeg").endswith(".jpg")
    assert sorted(p.name for p in store.folder.iterdir()) == sorted(
        [picture_name(red), picture_name(blue)]
    )


def test_a_glb_names_its_pictures_and_gets_them_back(tmp_path: Path) -> None:
    colours = [(200, 0, 0), (0, 200, 0), (200, 0, 0)]  # a picture two materials share
    data = _textured_glb(colours)
    glb = tmp_path / "buildings" / "ab" / "house.glb"
    glb.parent.mkdir(parents=True)
    store = TextureStore(tmp_path / "textures")
    shared = externalised(data, store, glb)
    glb.write_bytes(shared)
    document, _ = read_glb(shared)
    assert all("bufferView" not in image for image in document["images"])
    uris = image_uris(glb)
    assert {Path(uri).parent.as_posix() for uri in uris} == {"../../textures"}
    assert len(set(uris)) == 2 and len(list(store.folder.iterdir())) == 2
    assert not pictures_missing(glb) and len(shared) < len(data)
    # the same pictures, its geometry untouched: the glb embedding them again
    whole = embedded(shared, lambda uri: (glb.parent / uri).read_bytes())
    inlined, binary = read_glb(whole)
    pictures = []
    for image in inlined["images"]:
        view = inlined["bufferViews"][image["bufferView"]]
        start = view["byteOffset"]
        pictures.append(binary[start : start + view["byteLength"]])
    assert set(pictures) == {(glb.parent / uri).read_bytes() for uri in uris}
    assert all(picture == unpadded(picture) for picture in pictures)  # no padding kept
    # a loader finds them where the glb says (trimesh 5 reads files above a glb's folder
    # only when allowed: they may be any file)
    resolver = trimesh.resolvers.FilePathResolver(glb, allow_anywhere=True)
    loaded = trimesh.load(glb, force="scene", resolver=resolver)
    seen = {
        tuple(np.asarray(g.visual.material.baseColorTexture)[0, 0][:3])
        for g in loaded.geometry.values()
    }
    assert seen == {(200, 0, 0), (0, 200, 0)}
    (store.folder / Path(uris[0]).name).unlink()
    assert pictures_missing(glb) == [glb.parent / uris[0]]


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_the_validator_reads_the_pictures_a_glb_names(tmp_path: Path) -> None:
    assert (VALIDATOR / "gltf-validator").exists(), "run 'make test' to install the validator"
    glb = tmp_path / "buildings" / "ab" / "house.glb"
    glb.parent.mkdir(parents=True)
    store = TextureStore(tmp_path / "textures")
    glb.write_bytes(externalised(_textured_glb([(10, 20, 30)]), store, glb))

    (found,) = reports(glb)
    assert (found["errors"], found["warnings"]) == (0, 0), found
    for picture in store.folder.iterdir():
        picture.unlink()
    (found,) = reports(glb)  # a missing picture is an error: the validator read them before
    assert found["errors"] == 1 and "IO_ERROR" in json.dumps(found["messages"])


def test_merged_models_name_the_pictures_from_where_they_are(tmp_path: Path) -> None:
    store = TextureStore(tmp_path / "textures")
    parts = []
    for shard, colours in (("aa", [(1, 2, 3), (4, 5, 6)]), ("bb", [(4, 5, 6), (7, 8, 9)])):
        glb = tmp_path / "buildings" / shard / "house.glb"
        glb.parent.mkdir(parents=True)
        glb.write_bytes(externalised(_textured_glb(colours), store, glb))
        parts.append((shard, glb))
    for target in (
        tmp_path / "city.glb",
        tmp_path / "tiles" / "city_0_0.glb",
        tmp_path / "3dtiles" / "0" / "0" / "0.lod3.glb",
    ):
        merge_glb(parts, target)
        uris = image_uris(target)
        assert len(uris) == len(set(uris)) == 3  # the picture both houses wear, once
        assert not pictures_missing(target)
        depth = len(target.relative_to(tmp_path).parts) - 1
        assert all(uri.startswith("../" * depth + "textures/") for uri in uris)


def test_a_page_inlines_the_pictures_of_a_city_folder(tmp_path: Path) -> None:
    out = tmp_path / "out"
    glb = out / "buildings" / "ab" / "house.glb"
    glb.parent.mkdir(parents=True)
    store = TextureStore(out / "textures")
    glb.write_bytes(externalised(_textured_glb([(9, 9, 9)]), store, glb))
    written = write_gallery(out)
    assert [model.glb for model in written.models] == [glb]
    loaded, skipped = read_models(written.models, out)
    document, _ = read_glb(loaded[0].glb)
    assert not skipped and all("uri" not in image for image in document["images"])
    for picture in store.folder.iterdir():
        os.unlink(picture)
    _, skipped = read_models(written.models, out)  # a picture gone: the model left out
    assert len(skipped) == 1 and "its texture picture ../../textures/" in skipped[0].reason


def test_a_citys_usd_stages_name_the_glbs_pictures_and_embed_textures_keeps_them_in(
    tmp_path: Path,
) -> None:
    """A building's USD stage names the very files its glb names (one PNG encoding for
    both); with ``shared_textures`` off (``--embed-textures``) each glb holds its own."""
    manifest = write_demo(tmp_path / "demo", ROOT / "specs", 1)
    shared = tmp_path / "shared"
    run_city(load_city(manifest), shared, jobs=1, limit=2, usd=True)
    glbs = sorted((shared / "buildings").glob("*/*.glb"))
    assert len(glbs) == 2
    for glb in glbs:
        stage = glb.with_suffix(".usda").read_text()
        assets = set(re.findall(r"asset inputs:file = @([^@]+)@", stage))
        assert assets and assets <= set(image_uris(glb))
    alone = tmp_path / "alone"
    run_city(load_city(manifest), alone, jobs=1, limit=2, shared_textures=False)
    assert not (alone / "textures").exists()
    for glb in sorted((alone / "buildings").glob("*/*.glb")):
        document, _ = read_glb(glb.read_bytes())
        assert document["images"] and all("bufferView" in i for i in document["images"])


def test_pictures_no_glb_names_are_removed_and_nothing_else(tmp_path: Path) -> None:
    store = TextureStore(tmp_path / "textures")
    glb = tmp_path / "buildings" / "ab" / "house.glb"
    glb.parent.mkdir(parents=True)
    glb.write_bytes(externalised(_textured_glb([(1, 1, 1)]), store, glb))
    kept = store.folder / Path(image_uris(glb)[0]).name
    orphan = store.put(_png((2, 2, 2)))
    mine = store.folder / "notes.png"  # not named as the store names pictures: kept
    mine.write_bytes(b"mine")
    assert prune(store.folder, [glb, tmp_path / "gone.glb"]) == [orphan]
    assert kept.is_file() and mine.is_file() and not orphan.exists()
