"""Binary glTF 2.0 (``.glb``) and JSON glTF (``.gltf`` + ``.bin``) of a layout."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import trimesh

from facadecli.export.atomic import write_atomic

TRANSMISSION = "KHR_materials_transmission"


def glb_bytes(scene: trimesh.Scene, transmission: Mapping[str, float] | None = None) -> bytes:
    """The scene as a .glb. Normals are left out: viewers derive flat ones (glTF 3.7.2.1),
    which suits a façade's flat faces and keeps the file small. ``transmission`` maps
    material names to how much light passes through them (glass)."""
    data: bytes = scene.export(
        file_type="glb", include_normals=False, tree_postprocessor=_extensions(transmission)
    )
    return data


def _extensions(transmission: Mapping[str, float] | None) -> Callable[[dict[str, Any]], None]:
    """A glTF tree post-processor that gives the named materials their transmission
    (``KHR_materials_transmission``: viewers that know it render glass that lets light
    through; the others fall back to the material's opacity)."""

    def finish(tree: dict[str, Any]) -> None:
        used = False
        for material in tree.get("materials", []):
            factor = (transmission or {}).get(material.get("name", ""), 0.0)
            if factor > 0:
                material.setdefault("extensions", {})[TRANSMISSION] = {"transmissionFactor": factor}
                used = True
        if used:
            tree["extensionsUsed"] = sorted({*tree.get("extensionsUsed", []), TRANSMISSION})

    return finish


def write_glb(
    scene: trimesh.Scene, path: Path, transmission: Mapping[str, float] | None = None
) -> list[Path]:
    write_atomic(path, glb_bytes(scene, transmission))
    return [path]


def write_gltf(
    scene: trimesh.Scene, path: Path, transmission: Mapping[str, float] | None = None
) -> list[Path]:
    """``name.gltf`` and its buffer, named after it."""
    files: dict[str, bytes] = scene.export(
        file_type="gltf",
        include_normals=False,
        merge_buffers=True,
        tree_postprocessor=_extensions(transmission),
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
