"""Binary glTF 2.0 (``.glb``) and JSON glTF (``.gltf`` + ``.bin``) of a layout."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import trimesh

from facadecli.export.atomic import write_atomic

#: material name -> {extension name: its object}, e.g. KHR_materials_transmission
Extensions = Mapping[str, Mapping[str, Mapping[str, float]]]


def glb_bytes(scene: trimesh.Scene, extensions: Extensions | None = None) -> bytes:
    """The scene as a .glb. Normals are left out: viewers derive flat ones (glTF 3.7.2.1),
    which suits a façade's flat faces and keeps the file small. ``extensions`` gives
    materials, by name, their glTF extensions (glass: transmission and IOR)."""
    data: bytes = scene.export(
        file_type="glb", include_normals=False, tree_postprocessor=_finish(extensions)
    )
    return data


def _finish(extensions: Extensions | None) -> Callable[[dict[str, Any]], None]:
    """A glTF tree post-processor: one image and one texture for each picture used, however
    many materials share it, and the named materials' extensions (viewers that know
    ``KHR_materials_transmission`` render glass that lets light through; the others fall
    back to the material's opacity)."""

    def finish(tree: dict[str, Any]) -> None:
        _share_images(tree)
        _tangent_space(tree)
        used: set[str] = set(_emissive_strength(tree))
        for material in tree.get("materials", []):
            for extension, value in (extensions or {}).get(material.get("name", ""), {}).items():
                material.setdefault("extensions", {})[extension] = dict(value)
                used.add(extension)
        if used:
            tree["extensionsUsed"] = sorted({*tree.get("extensionsUsed", []), *used})

    return finish


EMISSIVE_STRENGTH = "KHR_materials_emissive_strength"


def _emissive_strength(tree: dict[str, Any]) -> list[str]:
    """A material giving off more light than its colour (a lit room: ``emissive`` over 1)
    as glTF has it: ``emissiveFactor`` within 0..1 and the rest as
    ``KHR_materials_emissive_strength``. Returns the extension if any material uses it."""
    used = []
    for material in tree.get("materials", []):
        factor = material.get("emissiveFactor")
        strongest = max(factor) if factor else 0.0
        if strongest > 1.0:
            material["emissiveFactor"] = [value / strongest for value in factor]
            material.setdefault("extensions", {})[EMISSIVE_STRENGTH] = {
                "emissiveStrength": strongest
            }
            used = [EMISSIVE_STRENGTH]
    return used


def _share_images(tree: dict[str, Any]) -> None:
    """Fold images that hold the same bytes (trimesh adds one per material that uses a
    picture, all pointing at one buffer view) into one, and textures of the same image
    and sampler into one, renumbering the materials' references."""
    images, textures = tree.get("images", []), tree.get("textures", [])
    if not textures:
        return
    image_index: dict[tuple[Any, ...], int] = {}
    image_map: list[int] = []
    kept_images: list[dict[str, Any]] = []
    for image in images:
        key = (image.get("bufferView"), image.get("mimeType"), image.get("uri"))
        if key not in image_index:
            image_index[key] = len(kept_images)
            kept_images.append(image)
        image_map.append(image_index[key])
    texture_index: dict[tuple[Any, ...], int] = {}
    texture_map: list[int] = []
    kept_textures: list[dict[str, Any]] = []
    for texture in textures:
        texture = dict(texture)
        if "source" in texture:
            texture["source"] = image_map[texture["source"]]
        key = (texture.get("source"), texture.get("sampler"), repr(texture.get("extensions")))
        if key not in texture_index:
            texture_index[key] = len(kept_textures)
            kept_textures.append(texture)
        texture_map.append(texture_index[key])
    tree["images"], tree["textures"] = kept_images, kept_textures
    for material in tree.get("materials", []):
        _renumber(material, texture_map)


def _tangent_space(tree: dict[str, Any]) -> None:
    """trimesh writes a mesh's own vertex attributes with a leading underscore (custom
    attributes); the normals and tangents a normal-mapped mesh carries are glTF's
    ``NORMAL`` and ``TANGENT``."""
    for mesh in tree.get("meshes", []):
        for primitive in mesh.get("primitives", []):
            attributes = primitive.get("attributes", {})
            for name in ("NORMAL", "TANGENT"):
                if f"_{name}" in attributes:
                    attributes[name] = attributes.pop(f"_{name}")


def _renumber(value: Any, texture_map: list[int]) -> None:
    """Texture references sit in nested ``{"index": i}`` objects of a material."""
    if isinstance(value, dict):
        for key, item in value.items():
            if key.endswith("Texture") and isinstance(item, dict) and "index" in item:
                item["index"] = texture_map[item["index"]]
            else:
                _renumber(item, texture_map)
    elif isinstance(value, list):
        for item in value:
            _renumber(item, texture_map)


def write_glb(scene: trimesh.Scene, path: Path, extensions: Extensions | None = None) -> list[Path]:
    write_atomic(path, glb_bytes(scene, extensions))
    return [path]


def write_gltf(
    scene: trimesh.Scene, path: Path, extensions: Extensions | None = None
) -> list[Path]:
    """``name.gltf`` and its buffer, named after it."""
    files: dict[str, bytes] = scene.export(
        file_type="gltf",
        include_normals=False,
        merge_buffers=True,
        tree_postprocessor=_finish(extensions),
    )
    written = []
    renames = {
        name: f"{path.stem}{Path(name).suffix}" if name.endswith(".gltf") else f"{path.stem}_{name}"
        for name in files
    }
    for name, data in sorted(files.items()):
        if name.endswith(".gltf"):
            text = data.decode("utf-8")
            for old, new in renames.items():
                if not old.endswith(".gltf"):
                    text = text.replace(f'"{old}"', f'"{new}"')
            data = text.encode("utf-8")
        target = path.parent / renames[name]
        write_atomic(target, data)
        written.append(target)
    return written
