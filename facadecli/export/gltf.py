"""Binary glTF 2.0 (``.glb``) and JSON glTF (``.gltf`` + ``.bin``) of a layout."""

from __future__ import annotations

from pathlib import Path

import trimesh

from facadecli.export.atomic import write_atomic


def glb_bytes(scene: trimesh.Scene) -> bytes:
    """The scene as a .glb. Normals are left out: viewers derive flat ones (glTF 3.7.2.1),
    which suits a façade's flat faces and keeps the file small."""
    data: bytes = scene.export(file_type="glb", include_normals=False)
    return data


def write_glb(scene: trimesh.Scene, path: Path) -> list[Path]:
    write_atomic(path, glb_bytes(scene))
    return [path]


def write_gltf(scene: trimesh.Scene, path: Path) -> list[Path]:
    """``name.gltf`` and its buffer, named after it."""
    files: dict[str, bytes] = scene.export(
        file_type="gltf", include_normals=False, merge_buffers=True
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
